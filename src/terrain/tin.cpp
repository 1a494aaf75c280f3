// Triangulated irregular networks by greedy insertion (Garland & Heckbert) into
// a Delaunay triangulation (voronoi::Delaunay2, grown through its Inserter:
// O(1) expected per point, exact predicates), tiled without cracks.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <unordered_map>

#include "../core/prefault.hpp"
#include "geods/core/error.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/terrain/terrain.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "triangle_raster.hpp"

namespace geods::terrain {
namespace {

using detail::P2;

// The samples of the segment p -> q (axis-aligned) kept so that linear
// interpolation between consecutive kept ones is within `limit` of every
// sample: split at the worst one until none exceeds it (in 1D the greedy
// insertion and this recursion keep the same samples).
void simplify_segment(const float* z, std::uint64_t w, P2 p, P2 q, double limit, std::vector<P2>& out) {
  const std::int64_t len = std::max(std::abs(q.x - p.x), std::abs(q.y - p.y));
  if (len < 2) return;
  const std::int64_t sx = (q.x - p.x) / len, sy = (q.y - p.y) / len;
  const double zp = z[p.y * std::int64_t(w) + p.x], zq = z[q.y * std::int64_t(w) + q.x];
  double worst = -1;
  std::int64_t at = 1;
  for (std::int64_t k = 1; k < len; ++k) {
    const double t = double(k) / double(len);
    const double d = std::abs(double(z[(p.y + sy * k) * std::int64_t(w) + p.x + sx * k]) - (zp + t * (zq - zp)));
    if (d > worst) worst = d, at = k;
  }
  if (worst <= limit) return;
  const P2 m{p.x + sx * at, p.y + sy * at};
  simplify_segment(z, w, p, m, limit, out);
  out.push_back(m);
  simplify_segment(z, w, m, q, limit, out);
}

// Greedy insertion into a voronoi::Delaunay2 through its Inserter: each
// triangle keeps its worst sample (its candidate), the queue holds the
// triangles farther than the limit, and an insertion rescans only the
// triangles it changed. The point's triangle is known (it is that triangle's
// candidate), so the insertion walks no steps.
// A queue entry: a triangle and its error. 16 bytes.
struct Entry {
  double error;
  std::uint32_t triangle;
};

// A 4-ary max-heap of entries by error: the four children of a node share a
// cache line, so a pop misses half as often as in a binary heap (the queue of
// a fine TIN holds millions of entries). Node i is stored at i + 3, so that the
// children 4 i + 1 .. 4 i + 4 sit at 4 (i + 1) .. 4 (i + 1) + 3: one aligned
// 64-byte line (the allocation is page-aligned), not two.
class MaxHeap4 {
 public:
  MaxHeap4() : heap_(kPad) {}
  bool empty() const { return heap_.size() == kPad; }
  const Entry& top() const { return heap_[kPad]; }
  void reserve(std::size_t n) { heap_.reserve(n + kPad); }
  void push(const Entry& e) {
    std::size_t i = heap_.size() - kPad;
    heap_.push_back(e);
    Entry* h = heap_.data() + kPad;
    while (i > 0) {
      const std::size_t parent = (i - 1) / 4;
      if (!(h[parent].error < e.error)) break;
      h[i] = h[parent];
      i = parent;
    }
    h[i] = e;
  }
  // The triangle of the entry the pops will likely stop at: the top if it is
  // current, else (a stale top) its largest child, which the pop raises, unchecked.
  template <class Current>
  std::uint32_t likely_next(Current current) const {
    const std::size_t n = heap_.size() - kPad;
    const Entry* h = heap_.data() + kPad;
    if (n == 0) return voronoi::Delaunay2::no_edge;
    if (current(h[0]) || n == 1) return h[0].triangle;
    std::size_t best = 1;
    for (std::size_t c = 2; c < std::min<std::size_t>(5, n); ++c)
      if (h[best].error < h[c].error) best = c;
    return h[best].triangle;
  }
  void pop() {
    const Entry last = heap_.back();
    heap_.pop_back();
    const std::size_t n = heap_.size() - kPad;
    if (n == 0) return;
    Entry* h = heap_.data() + kPad;
    std::size_t i = 0;
    for (;;) {
      const std::size_t first = 4 * i + 1;
      if (first >= n) break;
      // The grandchildren: four lines, one of which the next level reads;
      // asked for now, they arrive while this level compares (deep levels miss).
      if (4 * first + 1 < n)
        for (std::size_t c = 0; c < 4; ++c) __builtin_prefetch(h + 4 * (first + c) + 1);
      std::size_t best = first;
      const std::size_t end = std::min(first + 4, n);
      for (std::size_t c = first + 1; c < end; ++c)
        if (h[best].error < h[c].error) best = c;
      if (!(last.error < h[best].error)) break;
      h[i] = h[best];
      i = best;
    }
    h[i] = last;
  }

 private:
  static constexpr std::size_t kPad = 3;
  std::vector<Entry, HugePageAllocator<Entry>> heap_;
};

class GreedyTin {
 public:
  using Inserter = voronoi::Delaunay2::Inserter;
  GreedyTin(const float* z, std::uint64_t w, double limit, Inserter& ins, std::vector<P2>& pts)
      : z_(z), w_(w), limit_(limit), ins_(ins), pts_(pts) {}

  // Room for the states and queue entries of the triangles of `points` points
  // (address space: the pages are touched as they fill, once, not at every doubling).
  void reserve(std::size_t points) {
    state_.reserve(2 * points + 16);
    queue_.reserve(2 * points + 16);
  }
  // Inserts a sample, then rescans the triangles it changed (if `scan`).
  void insert(P2 p, std::uint32_t near = voronoi::Delaunay2::no_edge, bool scan = true) {
    const std::uint32_t i = ins_.insert(Vec2d(double(p.x), double(p.y)), near);
    if (i != pts_.size()) throw Error("terrain tin: a sample was inserted twice");
    pts_.push_back(p);
    if (!scan) return;
    // Fetch the next insertion's triangle while this one is rescanned. It is the first current entry the
    // queue pops: its top, unless the top is stale (most pops are) or this insertion changed its triangle.
    const std::span<const Inserter::Triangle> changed = ins_.changed();
    const std::uint32_t next = queue_.likely_next([&](const Entry& e) {
      for (const Inserter::Triangle& t : changed)
        if (t.handle == e.triangle) return false;
      return state_[e.triangle].error == e.error;
    });
    if (next != voronoi::Delaunay2::no_edge) ins_.prefetch(next);
    rescan(changed);
    // Then its corners and neighbours (the rescan's pushes rarely change the guess).
    if (next != voronoi::Delaunay2::no_edge) ins_.prefetch_neighbors(next);
  }
  // Scans every triangle.
  void scan_all() {
    std::vector<Inserter::Triangle> all;
    for (std::uint32_t h = 0; h < ins_.handle_count(); ++h) {
      if (!ins_.is_triangle(h)) continue;
      const auto corners = ins_.triangle(h);
      all.push_back({h, {ins_.points()[corners[0]], ins_.points()[corners[1]], ins_.points()[corners[2]]}});
    }
    rescan(all);
  }
  // Inserts the worst sample while it is farther than the limit.
  void refine() {
    while (!queue_.empty()) {
      const Entry top = queue_.top();
      queue_.pop();
      if (!queue_.empty()) __builtin_prefetch(&state_[queue_.top().triangle]);  // read next, after this insertion
      const State& s = state_[top.triangle];
      // An entry is stale once its triangle changed: unless the triangle has
      // the same error again (then the entry is as good as the new one).
      if (top.error != s.error) continue;
      insert(P2{s.x, s.y}, top.triangle);
    }
  }

 private:
  struct State {  // per triangle handle: its worst sample and its error in the queue (-1: none)
    std::int32_t x = 0, y = 0;
    double error = -1;
  };

  void rescan(std::span<const Inserter::Triangle> triangles) {
    const std::size_t handles = ins_.handle_count();
    if (state_.size() < handles) state_.resize(std::max(handles, 2 * state_.size()));
    const auto p2 = [](const Vec2d& v) { return P2{std::int64_t(v[0]), std::int64_t(v[1])}; };
    // The triangles lie anywhere in the field: ask for their first samples and states ahead.
    for (const Inserter::Triangle& t : triangles) {
      __builtin_prefetch(&state_[t.handle]);
      for (const Vec2d& c : t.corners) __builtin_prefetch(z_ + std::uint64_t(c[1]) * w_ + std::uint64_t(c[0]));
    }
    for (const Inserter::Triangle& t : triangles) {
      const P2 a = p2(t.corners[0]), b = p2(t.corners[1]), c = p2(t.corners[2]);
      State& s = state_[t.handle];
      s.error = -1;
      // Twice the area 1: by Pick's theorem no sample but the corners, whose
      // error never counts (most triangles of a fine TIN are such).
      if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) == 1) continue;
#if defined(__x86_64__) && defined(__GNUC__)
      const detail::Worst w = simd_ == SimdLevel::avx512 ? detail::triangle_worst_avx512(z_, w_, a, b, c)
                              : simd_ == SimdLevel::avx2  ? detail::triangle_worst_avx2(z_, w_, a, b, c)
                                                          : detail::triangle_worst(z_, w_, a, b, c);
#else
      const detail::Worst w = detail::triangle_worst(z_, w_, a, b, c);
#endif
      const bool corner = (w.at.x == a.x && w.at.y == a.y) || (w.at.x == b.x && w.at.y == b.y) ||
                          (w.at.x == c.x && w.at.y == c.y);
      s.x = std::int32_t(w.at.x), s.y = std::int32_t(w.at.y);
      if (w.error > limit_ && !corner) {
        s.error = w.error;
        queue_.push({s.error, t.handle});
      }
    }
  }

  const float* z_;
  std::uint64_t w_;
  double limit_;
  SimdLevel simd_ = simd_level();  // the scan's kernel (the same errors and samples at every level)
  Inserter& ins_;
  std::vector<P2>& pts_;  // per point of the triangulation
  std::vector<State, HugePageAllocator<State>> state_;
  MaxHeap4 queue_;
};

// A tile's TIN: its samples and their triangulation (dt.triangles(): indices
// into pts_, counter-clockwise; read in place, not copied).
struct TileTin {
  std::vector<P2> pts_;
  voronoi::Delaunay2 dt;
};

// The greedy TIN of the tile [c00, c11] of the row-major samples z (row length w):
// its four sides simplified on their own to border_limit (the neighbour does the
// same), then the inside to limit. The Delaunay decisions are exact and the
// errors use only differences of coordinates, so a block holding the tile gives
// the same triangles, shifted.
TileTin tile_tin(const float* z, std::uint64_t w, P2 c00, P2 c11, double limit, double border_limit) {
  const P2 c10{c11.x, c00.y}, c01{c00.x, c11.y};
  std::vector<P2> border;
  simplify_segment(z, w, c00, c10, border_limit, border);
  simplify_segment(z, w, c10, c11, border_limit, border);
  simplify_segment(z, w, c01, c11, border_limit, border);
  simplify_segment(z, w, c00, c01, border_limit, border);
  TileTin tin;
  tin.pts_ = {c00, c10, c11, c01};
  std::vector<Vec2d> corners;
  for (const P2& p : tin.pts_) corners.emplace_back(double(p.x), double(p.y));
  tin.dt = voronoi::Delaunay2(corners);
  {
    voronoi::Delaunay2::Inserter ins(tin.dt);
    // Room for every sample, up to 2^22 (a few hundred MB of address space; larger tiles grow as needed).
    const std::size_t room = std::min(std::size_t(c11.x - c00.x + 1) * std::size_t(c11.y - c00.y + 1), std::size_t(1) << 22);
    ins.reserve(room);
    geods::detail::reserve_growing(tin.pts_, room);
    GreedyTin g(z, w, limit, ins, tin.pts_);
    g.reserve(room);
    for (const P2& p : border) g.insert(p, voronoi::Delaunay2::no_edge, false);
    g.scan_all();
    g.refine();
  }
  return tin;
}

// Room for a mesh of known size, mapped up front: no copies as the arrays grow,
// no page fault per 4 KiB page as they fill.
void reserve_mesh(TerrainMesh& mesh, std::size_t vertices, std::size_t triangles) {
  geods::detail::reserve_prefaulted(mesh.samples, vertices);
  geods::detail::reserve_prefaulted(mesh.vertices, vertices);
  geods::detail::reserve_prefaulted(mesh.triangles, triangles);
}

void check_max_error(double max_error, const char* what) {
  if (!(max_error >= 0) || !std::isfinite(max_error))
    throw Error(std::string(what) + ": max_error must be finite and >= 0");
}

}  // namespace

double tin_border_limit(double max_error, double lo, double hi) {
  // The borders are simplified to a little less than the bound, so that a
  // border sample (measured in 1D) is never picked in 2D, where rounding
  // differs: neighbouring tiles keep the same border vertices.
  return max_error - 1e-9 * (1 + std::abs(max_error) + (hi - lo));
}

TerrainMesh tin_tile(std::span<const float> z, std::size_t width, std::size_t height, double max_error,
                     double border_limit) {
  check_max_error(max_error, "terrain tin_tile");
  if (width < 2 || height < 2 || z.size() != width * height)
    throw Error("terrain tin_tile: a tile needs at least 2 x 2 samples, with width x height of them (got " +
                std::to_string(z.size()) + " for " + std::to_string(width) + " x " + std::to_string(height) + ")");
  if (!std::isfinite(border_limit) || border_limit > max_error)
    throw Error("terrain tin_tile: border_limit must be finite and <= max_error");
  for (const float v : z)
    if (!std::isfinite(v)) throw Error("terrain tin_tile: the heights hold a NaN or infinite sample");
  const TileTin g = tile_tin(z.data(), width, P2{0, 0}, P2{std::int64_t(width) - 1, std::int64_t(height) - 1},
                               max_error, border_limit);
  TerrainMesh mesh;
  const auto& tri = g.dt.triangles();
  reserve_mesh(mesh, g.pts_.size(), tri.size() / 3);
  for (const P2& p : g.pts_) {
    mesh.samples.push_back({std::uint32_t(p.x), std::uint32_t(p.y)});
    mesh.vertices.push_back(Vec3f(float(p.x), float(p.y), z[std::size_t(p.y) * width + std::size_t(p.x)]));
  }
  for (std::size_t k = 0; k + 2 < tri.size(); k += 3) mesh.triangles.push_back({tri[k], tri[k + 1], tri[k + 2]});
  return mesh;
}

TerrainMesh Terrain::tin(double max_error, std::uint32_t tiles) const {
  check_max_error(max_error, "terrain tin");
  if (tiles < 1 || tiles > std::min(width_, height_) - 1)
    throw Error("terrain tin: tiles must be in 1.." + std::to_string(std::min(width_, height_) - 1) + ", got " +
                std::to_string(tiles));
  const auto z = heights_matrix();  // huge pages: the scans jump from row to row
  const std::int64_t W = std::int64_t(width_), H = std::int64_t(height_);
  float lo = z[0], hi = z[0];
  for (const float v : z) lo = std::min(lo, v), hi = std::max(hi, v);
  const double limit = max_error, border_limit = tin_border_limit(max_error, lo, hi);
  std::vector<std::int64_t> xs(tiles + 1), ys(tiles + 1);
  for (std::uint32_t k = 0; k <= tiles; ++k) xs[k] = std::int64_t(k) * (W - 1) / tiles, ys[k] = std::int64_t(k) * (H - 1) / tiles;

  TerrainMesh mesh;
  // A tile's points are distinct; only those on its border are shared with its
  // neighbours, and only those go through the map.
  std::unordered_map<std::uint64_t, std::uint32_t> border_vertex;  // sample id -> vertex
  auto add_vertex = [&](P2 p) {
    mesh.samples.push_back({std::uint32_t(p.x), std::uint32_t(p.y)});
    mesh.vertices.push_back(Vec3f(float(origin_[0] + double(p.x) * spacing_[0]),
                                  float(origin_[1] + double(p.y) * spacing_[1]),
                                  z[std::uint64_t(p.y) * width_ + std::uint64_t(p.x)]));
    return std::uint32_t(mesh.vertices.size() - 1);
  };

  std::vector<std::uint32_t> vertex_of;  // of the tile's points
  for (std::uint32_t ty = 0; ty < tiles; ++ty)
    for (std::uint32_t tx = 0; tx < tiles; ++tx) {
      const TileTin g = tile_tin(z.data(), width_, P2{xs[tx], ys[ty]}, P2{xs[tx + 1], ys[ty + 1]}, limit, border_limit);
      const auto& tri = g.dt.triangles();
      if (tiles == 1) reserve_mesh(mesh, g.pts_.size(), tri.size() / 3);
      geods::detail::reserve_prefaulted(vertex_of, g.pts_.size());
      vertex_of.resize(g.pts_.size());
      for (std::size_t i = 0; i < g.pts_.size(); ++i) {
        const P2 p = g.pts_[i];
        if (p.x != xs[tx] && p.x != xs[tx + 1] && p.y != ys[ty] && p.y != ys[ty + 1]) {
          vertex_of[i] = add_vertex(p);
          continue;
        }
        const std::uint64_t id = std::uint64_t(p.y) * width_ + std::uint64_t(p.x);
        const auto it = border_vertex.find(id);
        vertex_of[i] = it != border_vertex.end() ? it->second : (border_vertex[id] = add_vertex(p));
      }
      for (std::size_t k = 0; k + 2 < tri.size(); k += 3)
        mesh.triangles.push_back({vertex_of[tri[k]], vertex_of[tri[k + 1]], vertex_of[tri[k + 2]]});
    }
  return mesh;
}

}  // namespace geods::terrain
