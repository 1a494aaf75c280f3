// Triangulated irregular networks by greedy insertion (Garland & Heckbert) into
// a Delaunay triangulation, tiled without cracks. The triangulation is a small
// half-edge structure of its own (as delatin's) rather than voronoi::Delaunay2,
// whose insert() renumbers its public arrays (O(n) per point, O(n^2) for a TIN):
// here the point's triangle is known (it is that triangle's candidate), so an
// insertion is a split and Lawson flips with the exact incircle test, O(1)
// expected, and only the triangles it changed get new candidates.
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <span>
#include <string>
#include <unordered_map>

#include "geods/core/error.hpp"
#include "geods/terrain/terrain.hpp"
#include "geods/core/predicates.hpp"
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

// A Delaunay triangulation of grid samples with the sample of largest vertical
// error per triangle, refined by greedy insertion.
class GreedyTin {
 public:
  GreedyTin(const float* z, std::uint64_t w, double limit, std::int64_t extent)
      : z_(z), w_(w), limit_(limit), small_(extent <= (std::int64_t(1) << 14)) {}

  // The rectangle [a, c] (corners ccw from a) as two triangles, then the border
  // samples `border` inserted on its sides.
  void start(P2 c00, P2 c10, P2 c11, P2 c01, const std::vector<P2>& border) {
    const std::uint32_t a = add_point(c00), b = add_point(c10), c = add_point(c11), d = add_point(c01);
    const std::uint32_t t0 = new_triangle(), t1 = new_triangle();
    set(t0, a, b, c, kNone, kNone, 3 * t1 + 2);
    set(t1, c, d, a, kNone, kNone, 3 * t0 + 2);
    legalize(3 * t0 + 2);
    for (const P2& p : border) {
      // Its hull edge: the one it lies on.
      for (std::uint32_t e = 0; e < tri_.size(); ++e) {
        if (twin_[e] != kNone) continue;
        const P2 u = pts_[tri_[e]], v = pts_[tri_[next(e)]];
        if ((u.x == v.x && p.x == u.x && (p.y - u.y) * (p.y - v.y) < 0) ||
            (u.y == v.y && p.y == u.y && (p.x - u.x) * (p.x - v.x) < 0)) {
          insert_on_edge(add_point(p), e);
          break;
        }
      }
    }
    for (std::uint32_t t = 0; t < tri_.size() / 3; ++t) touched_.push_back(t);
    update_candidates();
  }

  // Inserts the worst sample while it is farther than the limit.
  void refine() {
    while (!queue_.empty()) {
      const Entry top = queue_.top();
      queue_.pop();
      if (top.version != version_[top.triangle]) continue;  // the triangle changed since
      const std::uint32_t t = top.triangle;
      const P2 p = candidate_[t];
      const std::uint32_t p_index = add_point(p);
      std::uint32_t on_edge = kNone;
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t e = 3 * t + k;
        if (orient(pts_[tri_[e]], pts_[tri_[next(e)]], p) == 0) on_edge = e;
      }
      if (on_edge == kNone)
        insert_inside(p_index, t);
      else
        insert_on_edge(p_index, on_edge);
      update_candidates();
    }
  }

  std::vector<P2> pts_;
  std::vector<std::uint32_t> tri_;  // per half-edge its start vertex; triangle t is half-edges 3t..3t+2 (ccw)

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  struct Entry {  // 16 bytes; the sample is the triangle's candidate_ while the version matches
    double error;
    std::uint32_t triangle, version;
    bool operator<(const Entry& o) const { return error < o.error; }
  };
  static std::uint32_t next(std::uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }
  static std::uint32_t prev(std::uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }
  static std::int64_t orient(P2 a, P2 b, P2 c) {  // exact in integers (|coordinates| < 2^31)
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  }
  // Whether d is strictly inside the circle through a, b, c (counter-clockwise):
  // exact in 64-bit integers when the coordinates span at most 2^14 (every term
  // below 2^62), else core's exact incircle.
  bool in_circle(P2 a, P2 b, P2 c, P2 d) const {
    if (!small_) {
      auto v = [](P2 p) { return Vec2d(double(p.x), double(p.y)); };
      return incircle(v(a), v(b), v(c), v(d)) > 0;
    }
    const std::int64_t adx = a.x - d.x, ady = a.y - d.y, bdx = b.x - d.x, bdy = b.y - d.y, cdx = c.x - d.x,
                       cdy = c.y - d.y;
    const std::int64_t al = adx * adx + ady * ady, bl = bdx * bdx + bdy * bdy, cl = cdx * cdx + cdy * cdy;
    return al * (bdx * cdy - cdx * bdy) + bl * (cdx * ady - adx * cdy) + cl * (adx * bdy - bdx * ady) > 0;
  }
  std::uint32_t add_point(P2 p) {
    pts_.push_back(p);
    return std::uint32_t(pts_.size() - 1);
  }
  std::uint32_t new_triangle() {
    tri_.resize(tri_.size() + 3, 0);
    twin_.resize(twin_.size() + 3, kNone);
    version_.push_back(0);
    candidate_.emplace_back();
    return std::uint32_t(version_.size() - 1);
  }
  void link(std::uint32_t a, std::uint32_t b) {
    twin_[a] = b;
    if (b != kNone) twin_[b] = a;
  }
  // Triangle t := (i0, i1, i2) with the twins of its half-edges.
  void set(std::uint32_t t, std::uint32_t i0, std::uint32_t i1, std::uint32_t i2, std::uint32_t a, std::uint32_t b,
           std::uint32_t c) {
    tri_[3 * t] = i0, tri_[3 * t + 1] = i1, tri_[3 * t + 2] = i2;
    link(3 * t, a), link(3 * t + 1, b), link(3 * t + 2, c);
    ++version_[t];
    touched_.push_back(t);
  }

  // p strictly inside triangle t = (a, b, c): (a, b, p), (b, c, p), (c, a, p).
  void insert_inside(std::uint32_t p, std::uint32_t t) {
    const std::uint32_t a = tri_[3 * t], b = tri_[3 * t + 1], c = tri_[3 * t + 2];
    const std::uint32_t ha = twin_[3 * t], hb = twin_[3 * t + 1], hc = twin_[3 * t + 2];
    const std::uint32_t t1 = new_triangle(), t2 = new_triangle();
    set(t, a, b, p, ha, 3 * t1 + 2, 3 * t2 + 1);
    set(t1, b, c, p, hb, 3 * t2 + 2, 3 * t + 1);
    set(t2, c, a, p, hc, 3 * t + 2, 3 * t1 + 1);
    legalize(3 * t), legalize(3 * t1), legalize(3 * t2);
  }

  // p on half-edge e = (a -> b) of triangle t = (a, b, c), twin in (b, a, d) if any.
  void insert_on_edge(std::uint32_t p, std::uint32_t e) {
    const std::uint32_t t = e / 3, a = tri_[e], b = tri_[next(e)], c = tri_[prev(e)];
    const std::uint32_t hbc = twin_[next(e)], hca = twin_[prev(e)], f = twin_[e];
    if (f == kNone) {
      const std::uint32_t t1 = new_triangle();
      set(t, b, c, p, hbc, 3 * t1 + 2, kNone);      // (b, c, p)
      set(t1, c, a, p, hca, kNone, 3 * t + 1);      // (c, a, p)
      legalize(3 * t), legalize(3 * t1);
      return;
    }
    const std::uint32_t u = f / 3, d = tri_[prev(f)];
    const std::uint32_t had = twin_[next(f)], hdb = twin_[prev(f)];
    const std::uint32_t t1 = new_triangle(), u1 = new_triangle();
    set(t, b, c, p, hbc, 3 * t1 + 2, 3 * u1 + 1);   // (b, c, p)
    set(t1, c, a, p, hca, 3 * u + 2, 3 * t + 1);    // (c, a, p)
    set(u, a, d, p, had, 3 * u1 + 2, 3 * t1 + 1);   // (a, d, p)
    set(u1, d, b, p, hdb, 3 * t + 2, 3 * u + 1);    // (d, b, p)
    legalize(3 * t), legalize(3 * t1), legalize(3 * u), legalize(3 * u1);
  }

  // Half-edge a has the new point opposite; flip it while the point across is
  // inside the circle (exact incircle), then the two far edges (Lawson).
  void legalize(std::uint32_t a) {
    const std::uint32_t b = twin_[a];
    if (b == kNone) return;
    const std::uint32_t a0 = a - a % 3, b0 = b - b % 3;
    const std::uint32_t al = a0 + (a + 1) % 3, ar = a0 + (a + 2) % 3, bl = b0 + (b + 2) % 3, br = b0 + (b + 1) % 3;
    const std::uint32_t p0 = tri_[ar], pr = tri_[a], pl = tri_[al], p1 = tri_[bl];
    if (!in_circle(pts_[pr], pts_[pl], pts_[p0], pts_[p1])) return;
    const std::uint32_t hal = twin_[al], har = twin_[ar], hbl = twin_[bl], hbr = twin_[br];
    const std::uint32_t t0 = a0 / 3, t1 = b0 / 3;
    set(t0, p0, p1, pl, kNone, hbl, hal);
    set(t1, p1, p0, pr, 3 * t0, har, hbr);
    legalize(3 * t0 + 1);
    legalize(3 * t1 + 2);
  }

  void update_candidates() {
    std::sort(touched_.begin(), touched_.end());
    touched_.erase(std::unique(touched_.begin(), touched_.end()), touched_.end());
    for (const std::uint32_t t : touched_) {
      const P2 a = pts_[tri_[3 * t]], b = pts_[tri_[3 * t + 1]], c = pts_[tri_[3 * t + 2]];
      const detail::Worst w = detail::triangle_worst(z_, w_, a, b, c);
      const bool corner = (w.at.x == a.x && w.at.y == a.y) || (w.at.x == b.x && w.at.y == b.y) ||
                          (w.at.x == c.x && w.at.y == c.y);
      candidate_[t] = w.at;
      if (w.error > limit_ && !corner) queue_.push({w.error, t, version_[t]});
    }
    touched_.clear();
  }

  const float* z_;
  std::uint64_t w_;
  double limit_;
  bool small_;  // coordinates within 2^14 of each other: integer incircle
  std::vector<std::uint32_t> twin_, version_, touched_;
  std::vector<P2> candidate_;  // per triangle: its worst sample
  std::priority_queue<Entry> queue_;
};

}  // namespace

namespace {

// The greedy TIN of the tile [c00, c11] of the row-major samples z (row length w):
// its four sides simplified on their own to border_limit (the neighbour does the
// same), then the inside to limit. Only differences of coordinates enter the
// arithmetic, so a block holding the tile gives the same triangles, shifted.
GreedyTin tile_tin(const float* z, std::uint64_t w, P2 c00, P2 c11, double limit, double border_limit) {
  const P2 c10{c11.x, c00.y}, c01{c00.x, c11.y};
  std::vector<P2> start{c00, c10, c11, c01};
  simplify_segment(z, w, c00, c10, border_limit, start);
  simplify_segment(z, w, c10, c11, border_limit, start);
  simplify_segment(z, w, c01, c11, border_limit, start);
  simplify_segment(z, w, c00, c01, border_limit, start);
  GreedyTin g(z, w, limit, std::max(c11.x - c00.x, c11.y - c00.y));
  g.start(c00, c10, c11, c01, std::vector<P2>(start.begin() + 4, start.end()));
  g.refine();
  return g;
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
  const GreedyTin g = tile_tin(z.data(), width, P2{0, 0}, P2{std::int64_t(width) - 1, std::int64_t(height) - 1},
                               max_error, border_limit);
  TerrainMesh mesh;
  for (const P2& p : g.pts_) {
    mesh.samples.push_back({std::uint32_t(p.x), std::uint32_t(p.y)});
    mesh.vertices.push_back(Vec3f(float(p.x), float(p.y), z[std::size_t(p.y) * width + std::size_t(p.x)]));
  }
  for (std::size_t k = 0; k + 2 < g.tri_.size(); k += 3) mesh.triangles.push_back({g.tri_[k], g.tri_[k + 1], g.tri_[k + 2]});
  return mesh;
}

TerrainMesh Terrain::tin(double max_error, std::uint32_t tiles) const {
  check_max_error(max_error, "terrain tin");
  if (tiles < 1 || tiles > std::min(width_, height_) - 1)
    throw Error("terrain tin: tiles must be in 1.." + std::to_string(std::min(width_, height_) - 1) + ", got " +
                std::to_string(tiles));
  const std::vector<float> z = heights_matrix();
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
      const GreedyTin g = tile_tin(z.data(), width_, P2{xs[tx], ys[ty]}, P2{xs[tx + 1], ys[ty + 1]}, limit, border_limit);
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
      for (std::size_t k = 0; k + 2 < g.tri_.size(); k += 3)
        mesh.triangles.push_back({vertex_of[g.tri_[k]], vertex_of[g.tri_[k + 1]], vertex_of[g.tri_[k + 2]]});
    }
  return mesh;
}

}  // namespace geods::terrain
