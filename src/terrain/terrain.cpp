// The 4-8 hierarchy of Lindstrom & Pascucci: exact nested errors, nested
// bounding spheres, the interleaved quadtree layout, refinement into one
// triangle strip and a triangle list, tiles, and the mapped terrain file.
#include "geods/terrain/terrain.hpp"

#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/parallel.hpp"
#include "triangle_raster.hpp"

namespace geods::terrain {
namespace {

using detail::P2;
using detail::triangle_error;

constexpr float kInf = std::numeric_limits<float>::infinity();

// The smallest float >= v, for v >= 0 (or +inf).
float round_up(double v) {
  float f = float(v);
  if (double(f) < v) f = std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) + 1);
  return f;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

// ---------------------------------------------------------------- layout

LayoutIndex::LayoutIndex(Layout layout, std::uint32_t levels) : layout_(layout), levels_(levels) {
  if (levels < 1 || levels > 30) throw Error("terrain layout: levels must be in 1..30, got " + std::to_string(levels));
  if (layout == Layout::matrix) {
    slots_ = n() * n();
    return;
  }
  std::uint64_t next = 5;  // slot 0 the centre, 1..4 the corners
  for (std::int64_t t = std::int64_t(levels) - 1; t >= 0; --t) {
    const std::uint64_t m = std::uint64_t(1) << (levels - std::uint32_t(t));
    base_[std::size_t(t)] = next;
    next += m * m;
  }
  slots_ = next;
}

std::uint64_t LayoutIndex::interleaved_slot(std::uint32_t x, std::uint32_t y) const {
  const std::int64_t c = std::int64_t(1) << (levels_ - 1), N = 2 * c;
  if (x == c && y == c) return 0;
  if ((x == 0 || x == N) && (y == 0 || y == N)) return 1 + (x == N) + 2 * (y == N);
  const int t = std::countr_zero(x | y);
  const std::int64_t s = std::int64_t(1) << t;
  std::int64_t X = x, Y = y;
  if (((x >> t) & 1) && ((y >> t) & 1)) {
    // A red vertex (square centre, s < c): into a ghost slot of the blue level
    // of the same spacing. Rotate it into the bottom quarter Q0 (below both
    // diagonals; of the diagonal points the lower-left ones), map (x, y) ->
    // (x + s, -y), rotate back: the image is a blue-lattice point outside the
    // grid but inside the blue quadtree's root diamond, and distinct per vertex.
    std::int64_t dx = X - c, dy = Y - c;
    int q = 0;
    while (!(dy < 0 && (-dy > std::abs(dx) || (-dy == std::abs(dx) && dx < 0)))) {
      const std::int64_t t0 = dx;
      dx = dy, dy = -t0, ++q;  // R^-1
    }
    std::int64_t ex = dx + s, ey = -2 * c - dy;
    for (int k = 0; k < q; ++k) {
      const std::int64_t t0 = ex;
      ex = -ey, ey = t0;  // R
    }
    X = c + ex, Y = c + ey;
  }
  const std::int64_t m = N >> t;
  const std::int64_t u = (X + Y) >> t, v = (X - Y) / s;  // odd, u in (0, 2m), v in (-m, m)
  const std::uint64_t i = std::uint64_t((u - 1) / 2), j = std::uint64_t((v + m - 1) / 2);
  return base_[std::size_t(t)] + morton2d_encode64(std::uint32_t(i), std::uint32_t(j));
}

// ---------------------------------------------------------------- build

Terrain::Terrain(HeightField field, TerrainOptions options) {
  const auto t0 = std::chrono::steady_clock::now();
  check_height_field(field);
  if (!std::isfinite(options.z_scale) || options.z_scale == 0)
    throw Error("terrain: z_scale " + format_number(options.z_scale) + " is not finite and nonzero");
  filled_ = fill_missing(field);
  width_ = field.width;
  height_ = field.height;
  spacing_ = field.spacing;
  origin_ = field.origin;
  z_scale_ = options.z_scale;
  std::uint32_t K = 1;
  while ((std::uint64_t(1) << K) + 1 < std::max(width_, height_)) ++K;
  const std::uint64_t n = (std::uint64_t(1) << K) + 1;
  const std::int64_t W = std::int64_t(width_), H = std::int64_t(height_);
  index_ = LayoutIndex(options.layout, K);

  // Heights of the padded grid (the padding repeats the last row and column).
  std::vector<float> z(n * n);
  parallel_for(0, n, 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t y = b; y < e; ++y)
      for (std::size_t x = 0; x < n; ++x) {
        const double v = double(field.heights[std::min<std::size_t>(y, height_ - 1) * width_ +
                                              std::min<std::size_t>(x, width_ - 1)]) * z_scale_;
        if (!std::isfinite(float(v))) throw Error("terrain: a height times z_scale overflows a float");
        z[y * n + x] = float(v);
      }
  });
  field.heights = {};

  const std::int64_t N = std::int64_t(n) - 1, c = N / 2;
  auto inside = [&](P2 p) { return p.x <= W - 1 && p.y <= H - 1; };
  // Own error of each vertex: the largest vertical distance between the grid and
  // the triangles it splits (its diamond); +inf where the diamond leaves the
  // field (the padding), so that those vertices are always refined and no
  // final triangle straddles the field's border.
  std::vector<float> err(n * n, 0.0f);
  parallel_for(0, n, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t yy = b; yy < e; ++yy)
      for (std::size_t xx = 0; xx < n; ++xx) {
        const std::int64_t x = std::int64_t(xx), y = std::int64_t(yy);
        if ((x == 0 || x == N) && (y == 0 || y == N)) continue;
        if (x == c && y == c) continue;  // the centre is always in the mesh
        const int t = std::countr_zero(std::uint64_t(x | y));
        const std::int64_t s = std::int64_t(1) << t;
        P2 h0, h1, apex[2];
        int apexes = 0;
        if (((x >> t) & 1) && ((y >> t) & 1)) {  // red: square centre
          const bool main_parents = ((((x - s) >> (t + 1)) + ((y - s) >> (t + 1))) & 1) != 0;
          if (main_parents) {  // parents (x-s, y-s), (x+s, y+s); hypotenuse the other diagonal
            apex[0] = {x - s, y - s}, apex[1] = {x + s, y + s}, h0 = {x - s, y + s}, h1 = {x + s, y - s};
          } else {
            apex[0] = {x - s, y + s}, apex[1] = {x + s, y - s}, h0 = {x - s, y - s}, h1 = {x + s, y + s};
          }
          apexes = 2;
        } else if ((x >> t) & 1) {  // blue on a horizontal edge
          h0 = {x - s, y}, h1 = {x + s, y};
          if (y - s >= 0) apex[apexes++] = {x, y - s};
          if (y + s <= N) apex[apexes++] = {x, y + s};
        } else {  // blue on a vertical edge
          h0 = {x, y - s}, h1 = {x, y + s};
          if (x - s >= 0) apex[apexes++] = {x - s, y};
          if (x + s <= N) apex[apexes++] = {x + s, y};
        }
        double worst = 0;
        for (int k = 0; k < apexes; ++k) {
          if (!inside(h0) || !inside(h1) || !inside(apex[k])) {
            worst = kInf;
            break;
          }
          worst = std::max(worst, triangle_error(z.data(), n, h0, h1, apex[k]));
        }
        err[yy * n + xx] = round_up(worst);
      }
  });

  // Nesting, finest level first: error = max(own, children's); radius = max over
  // children of (distance + child's radius), rounded up, so that a child's
  // sphere lies in its parent's.
  std::vector<float> rad(n * n, 0.0f);
  const double sx = std::abs(spacing_[0]), sy = std::abs(spacing_[1]);
  auto nest = [&](std::int64_t x, std::int64_t y, P2 child) {
    if (child.x < 0 || child.y < 0 || child.x > N || child.y > N) return;
    const std::size_t v = std::size_t(y * std::int64_t(n) + x), w = std::size_t(child.y * std::int64_t(n) + child.x);
    err[v] = std::max(err[v], err[w]);
    const double dx = double(child.x - x) * sx, dy = double(child.y - y) * sy, dz = double(z[w]) - double(z[v]);
    rad[v] = std::max(rad[v], round_up(std::sqrt(dx * dx + dy * dy + dz * dz) + double(rad[w])));
  };
  for (std::uint32_t t = 0; t < K; ++t) {
    const std::int64_t s = std::int64_t(1) << t;
    // Blue vertices of spacing s: children are the red ones of spacing s / 2.
    parallel_for(0, std::size_t(N / s + 1), 4, [&](std::size_t b, std::size_t e) {
      for (std::size_t r = b; r < e; ++r) {
        const std::int64_t y = std::int64_t(r) * s;
        for (std::int64_t x = ((r & 1) ? 0 : s); x <= N; x += 2 * s) {
          if (s < 2) continue;
          const std::int64_t h = s / 2;
          for (const P2 ch : {P2{x - h, y - h}, P2{x + h, y - h}, P2{x - h, y + h}, P2{x + h, y + h}}) nest(x, y, ch);
        }
      }
    });
    // Red vertices of spacing s (square centres): children the blue ones of spacing s.
    parallel_for(0, std::size_t(N / (2 * s)), 4, [&](std::size_t b, std::size_t e) {
      for (std::size_t r = b; r < e; ++r) {
        const std::int64_t y = std::int64_t(2 * r + 1) * s;
        for (std::int64_t x = s; x < N; x += 2 * s)
          for (const P2 ch : {P2{x - s, y}, P2{x + s, y}, P2{x, y - s}, P2{x, y + s}}) nest(x, y, ch);
      }
    });
  }

  std::vector<VertexRecord> records(index_.slots());
  parallel_for(0, n, 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t y = b; y < e; ++y)
      for (std::size_t x = 0; x < n; ++x)
        records[index_.slot(std::uint32_t(x), std::uint32_t(y))] = {z[y * n + x], err[y * n + x], rad[y * n + x]};
  });
  records_ = FlatArray<VertexRecord>(std::move(records));
  build_s_ = seconds_since(t0);
}

TerrainStats Terrain::stats() const {
  TerrainStats s;
  s.width = width_;
  s.height = height_;
  s.grid = index_.n();
  s.levels = index_.levels();
  s.slots = index_.slots();
  s.unused_slots = s.slots - s.grid * s.grid;
  s.unused_slots_pct = s.slots ? 100.0 * double(s.unused_slots) / double(s.slots) : 0;
  s.filled_samples = filled_;
  s.bytes = records_.size() * sizeof(VertexRecord);
  s.mapped = records_.mapped();
  s.build_s = build_s_;
  return s;
}

// ---------------------------------------------------------------- refinement

namespace {

// The refinement of one square of the grid: L&P's submesh recursion in doubled
// coordinates (a split vertex of the finest triangles lies between samples).
class Refiner {
 public:
  Refiner(const Terrain& t, const Refinement& r) : t_(t), r_(r) {
    if (!r.max_error && !r.view) throw Error("terrain refine: give a max_error or a view (camera)");
    if (r.max_error && !(*r.max_error >= 0)) throw Error("terrain refine: max_error must be >= 0");
    n_ = t.layout().n();
    if (r.view) {
      const TerrainView& v = *r.view;
      v.camera.check();
      if (v.width < 1 || v.height < 1) throw Error("terrain refine: the image size must be at least 1 x 1");
      if (!(r.pixel_error > 0) || !std::isfinite(r.pixel_error))
        throw Error("terrain refine: pixel_error must be > 0");
      eye_ = {v.camera.eye.x(), v.camera.eye.y(), v.camera.eye.z()};
      const Vec3d f = (v.camera.target - v.camera.eye).cast<double>().normalized();
      const Vec3d right = f.cross(v.camera.up.cast<double>()).normalized();
      const Vec3d up = right.cross(f);
      const double tv = std::tan(double(v.camera.vertical_fov_deg) * M_PI / 360.0);
      const double th = tv * double(v.width) / double(v.height);
      planes_[0] = (th * f + right).normalized();
      planes_[1] = (th * f - right).normalized();
      planes_[2] = (tv * f + up).normalized();
      planes_[3] = (tv * f - up).normalized();
      planes_[4] = f;
      lambda_ = double(v.height) / (2 * tv);
    }
  }

  static constexpr unsigned kAllPlanes = 31;

  // Whether the vertex at doubled coordinates (x2, y2) is in the mesh;
  // `planes` are the frustum planes its sphere still straddles (updated).
  bool active(std::int64_t x2, std::int64_t y2, unsigned& planes) const {
    const std::uint32_t x = std::uint32_t(x2 / 2), y = std::uint32_t(y2 / 2);
    const VertexRecord& v = t_.record(x, y);
    if (std::isinf(v.error)) return true;  // the padding
    if (r_.max_error && double(v.error) > *r_.max_error) return true;
    if (!r_.view || v.error <= 0) return false;
    const Vec3d p(t_.origin()[0] + double(x) * t_.spacing()[0], t_.origin()[1] + double(y) * t_.spacing()[1], double(v.z));
    const Vec3d d = p - eye_;
    for (unsigned k = 0; k < 5; ++k) {
      if (!(planes & (1u << k))) continue;
      const double dist = planes_[k].dot(d);
      if (dist < -double(v.radius)) return false;  // outside the frustum
      if (dist > double(v.radius)) planes &= ~(1u << k);  // completely inside this plane
    }
    const double dd = d.norm() - double(v.radius);
    if (dd <= 0) return true;
    return lambda_ * double(v.error) > r_.pixel_error * dd;
  }

  // The mesh of the square [x0, x0 + L] x [y0, y0 + L] (L a power of two >= 2)
  // as a strip of grid ids, appended to strip_; its non-degenerate triangles are the mesh.
  void square(std::int64_t x0, std::int64_t y0, std::int64_t L, std::uint32_t depth) {
    const std::int64_t X0 = 2 * x0, Y0 = 2 * y0, X1 = 2 * (x0 + L), Y1 = 2 * (y0 + L), C = X0 + L, CY = Y0 + L;
    const P2 corners[4] = {{X1, Y0}, {X1, Y1}, {X0, Y1}, {X0, Y0}};
    const P2 mids[4] = {{C, Y0}, {X1, CY}, {C, Y1}, {X0, CY}};
    const std::size_t first = strip_.size();
    strip_.push_back(id(X0, Y0));
    strip_.push_back(id(X0, Y0));
    parity_ = 0;
    for (int q = 0; q < 4; ++q) {
      submesh({C, CY}, mids[q], 2 * depth, kAllPlanes, true);
      append(corners[q], 1);
    }
    strip_begin_.push_back(first);
  }

  std::vector<std::uint64_t> strip_;
  std::vector<std::size_t> strip_begin_;  // where each square's strip starts

 private:
  std::uint64_t id(std::int64_t x2, std::int64_t y2) const { return std::uint64_t(y2 / 2) * n_ + std::uint64_t(x2 / 2); }

  // The children of split vertex j in the triangle of apex i: the split
  // vertices of its halves, in the order the strip walks them (L&P's c_l, c_r):
  // for an axis-aligned i - j the one counter-clockwise from i - j first, for a
  // diagonal one the clockwise one (the walk turns at every level).
  static P2 child_ccw(P2 i, P2 j) {
    const std::int64_t dx = i.x - j.x, dy = i.y - j.y;
    return {(j.x - dy + i.x) / 2, (j.y + dx + i.y) / 2};
  }
  static P2 child_cw(P2 i, P2 j) {
    const std::int64_t dx = i.x - j.x, dy = i.y - j.y;
    return {(j.x + dy + i.x) / 2, (j.y - dx + i.y) / 2};
  }
  static P2 child_left(P2 i, P2 j) { return (i.x == j.x || i.y == j.y) ? child_ccw(i, j) : child_cw(i, j); }
  static P2 child_right(P2 i, P2 j) { return (i.x == j.x || i.y == j.y) ? child_cw(i, j) : child_ccw(i, j); }

  // L&P's submesh-refine(i, j, l): the triangle of apex i and split vertex j
  // exists when i is active; its halves are the triangles of apex j.
  void submesh(P2 i, P2 j, std::uint32_t l, unsigned planes, bool forced = false) {
    if (l == 0) return;
    if (!forced && !active(i.x, i.y, planes)) return;
    submesh(j, child_left(i, j), l - 1, planes);
    append(i, l & 1);
    submesh(j, child_right(i, j), l - 1, planes);
  }

  void append(P2 v, unsigned p) {
    const std::uint64_t w = id(v.x, v.y);
    const std::size_t k = strip_.size();
    if (w == strip_[k - 1] || w == strip_[k - 2]) return;
    if (p != parity_)
      parity_ = p;
    else
      strip_.push_back(strip_[k - 2]);  // a turn
    strip_.push_back(w);
  }

  const Terrain& t_;
  const Refinement& r_;
  std::uint64_t n_ = 0;
  unsigned parity_ = 0;
  Vec3d eye_ = Vec3d::Zero();
  Vec3d planes_[5];
  double lambda_ = 1;
};

// The output mesh: the triangles and strip of `refiner` restricted to the field
// (the padding dropped: every leaf triangle lies wholly inside or outside it),
// vertices numbered in order of first use.
TerrainMesh assemble(const Terrain& t, const Refiner& refiner) {
  const std::uint64_t n = t.layout().n(), W = t.width(), H = t.height();
  const bool full = W == n && H == n;  // no padding: every triangle is inside
  auto inside = [&](std::uint64_t g) { return full || (g % n < W && g / n < H); };
  TerrainMesh mesh;
  std::vector<std::uint64_t> ids;  // the triangles: the strip's non-degenerate ones inside the field
  // Strip: keep the triangles inside (degenerate ones too, they turn the
  // strip); runs of kept triangles are joined by degenerate triangles that keep
  // each triangle's parity, so the winding is what the submesh recursion made.
  std::vector<std::uint64_t> strip;
  const std::vector<std::uint64_t>& s = refiner.strip_;
  std::vector<std::size_t> begins = refiner.strip_begin_;
  begins.push_back(s.size());
  for (std::size_t part = 0; part + 1 < begins.size(); ++part) {
    const std::size_t b = begins[part], e = begins[part + 1];
    std::size_t k = b;
    while (k + 2 < e) {
      if (!(inside(s[k]) && inside(s[k + 1]) && inside(s[k + 2]))) {
        ++k;
        continue;
      }
      std::size_t end = k;  // [k, end] kept triangles
      while (end + 3 < e && inside(s[end + 3])) ++end;
      // Join: ..., last, last, s[k], s[k] (degenerate triangles), one more
      // s[k] when needed so that the run's triangles keep their parity.
      if (strip.empty())  // no leading degenerate triangles
        while (k < end && (s[k] == s[k + 1] || s[k + 1] == s[k + 2] || s[k] == s[k + 2])) ++k;
      if (!strip.empty()) {
        strip.push_back(strip.back());
        strip.push_back(s[k]);
      }
      // The recursion's strip starts with its first corner twice: its
      // triangle k is counter-clockwise when k - b is odd.
      if (strip.size() % 2 != (k - b + 1) % 2) strip.push_back(s[k]);
      for (std::size_t q = k; q <= end + 2; ++q) strip.push_back(s[q]);
      k = end + 1;
    }
  }
  for (std::size_t part = 0; part + 1 < begins.size(); ++part)
    for (std::size_t k = begins[part]; k + 2 < begins[part + 1]; ++k) {
      const std::uint64_t a = s[k], b = s[k + 1], c = s[k + 2];
      if (a != b && b != c && a != c && inside(a) && inside(b) && inside(c)) ids.insert(ids.end(), {a, b, c});
    }
  // Vertices numbered in grid order: by a dense table up to 2^24 samples, else by sorting.
  std::vector<std::uint64_t> unique;
  std::vector<std::uint32_t> dense;
  constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
  if (n * n <= (std::uint64_t(1) << 24)) {
    dense.assign(n * n, kUnused);
    for (const std::uint64_t g : ids) dense[g] = 0;
    for (const std::uint64_t g : strip) dense[g] = 0;
    for (std::uint64_t g = 0; g < n * n; ++g)
      if (dense[g] == 0) {
        dense[g] = std::uint32_t(unique.size());
        unique.push_back(g);
      }
  } else {
    unique = ids;
    unique.insert(unique.end(), strip.begin(), strip.end());
    std::sort(unique.begin(), unique.end());
    unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  }
  auto number = [&](std::uint64_t g) {
    return dense.empty() ? std::uint32_t(std::lower_bound(unique.begin(), unique.end(), g) - unique.begin())
                         : dense[g];
  };
  mesh.vertices.resize(unique.size());
  mesh.samples.resize(unique.size());
  for (std::size_t v = 0; v < unique.size(); ++v) {
    const std::uint32_t x = std::uint32_t(unique[v] % n), y = std::uint32_t(unique[v] / n);
    mesh.samples[v] = {x, y};
    mesh.vertices[v] = Vec3f(float(t.origin()[0] + double(x) * t.spacing()[0]),
                             float(t.origin()[1] + double(y) * t.spacing()[1]), t.sample(x, y));
  }
  mesh.triangles.reserve(ids.size() / 3);
  for (std::size_t k = 0; k < ids.size(); k += 3) {
    std::array<std::uint32_t, 3> tri{number(ids[k]), number(ids[k + 1]), number(ids[k + 2])};
    // Counter-clockwise in grid coordinates.
    const auto& a = mesh.samples[tri[0]];
    const auto& b = mesh.samples[tri[1]];
    const auto& c = mesh.samples[tri[2]];
    const std::int64_t cross = (std::int64_t(b[0]) - a[0]) * (std::int64_t(c[1]) - a[1]) -
                               (std::int64_t(b[1]) - a[1]) * (std::int64_t(c[0]) - a[0]);
    if (cross < 0) std::swap(tri[1], tri[2]);
    mesh.triangles.push_back(tri);
  }
  mesh.strip.reserve(strip.size());
  for (const std::uint64_t g : strip) mesh.strip.push_back(number(g));
  return mesh;
}

}  // namespace

TerrainMesh Terrain::refine(const Refinement& refinement) const { return refine_tiles(refinement, 1); }

TerrainMesh Terrain::refine_tiles(const Refinement& refinement, std::uint32_t tiles) const {
  if (records_.empty()) throw Error("terrain refine: an empty terrain");
  const std::uint32_t K = index_.levels();
  if (tiles < 1 || !std::has_single_bit(tiles) || tiles > (1u << (K - 1)))
    throw Error("terrain refine: tiles must be a power of two from 1 to " + std::to_string(1u << (K - 1)) +
                " for this grid, got " + std::to_string(tiles));
  Refiner refiner(*this, refinement);
  const std::int64_t L = (std::int64_t(1) << K) / tiles;
  const std::uint32_t depth = std::uint32_t(std::countr_zero(std::uint64_t(L)));
  for (std::uint32_t ty = 0; ty < tiles; ++ty)
    for (std::uint32_t tx = 0; tx < tiles; ++tx) {
      const std::int64_t x0 = std::int64_t(tx) * L, y0 = std::int64_t(ty) * L;
      if (std::uint64_t(x0) >= width_ - 1 || std::uint64_t(y0) >= height_ - 1) continue;  // all padding
      refiner.square(x0, y0, L, depth);
    }
  return assemble(*this, refiner);
}

std::vector<float> Terrain::heights_matrix() const {
  std::vector<float> z(width_ * height_);
  parallel_for(0, height_, 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t y = b; y < e; ++y)
      for (std::size_t x = 0; x < width_; ++x) z[y * width_ + x] = sample(std::uint32_t(x), std::uint32_t(y));
  });
  return z;
}

double Terrain::measure_error(const TerrainMesh& mesh) const {
  for (const auto& tri : mesh.triangles)
    for (const std::uint32_t v : tri)
      if (mesh.samples.size() <= v || mesh.samples[v][0] >= width_ || mesh.samples[v][1] >= height_)
        throw Error("terrain measure_error: a vertex without a sample of the field");
  const std::vector<float> z = heights_matrix();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.triangles.size(), 256), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double worst) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          const auto& t = mesh.triangles[k];
          const auto p = [&](std::uint32_t v) { return P2{mesh.samples[v][0], mesh.samples[v][1]}; };
          const P2 a = p(t[0]), b = p(t[1]), c = p(t[2]);
          if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) == 0) continue;  // degenerate: no area
          worst = std::max(worst, triangle_error(z.data(), width_, a, b, c));
        }
        return worst;
      },
      [](double a, double b) { return std::max(a, b); });
}

// ---------------------------------------------------------------- file

void Terrain::save(const std::filesystem::path& path) const {
  ArchiveWriter w(std::string(kTerrainArchiveKind), kTerrainArchiveVersion);
  w.add_value("width", width_);
  w.add_value("height", height_);
  w.add_value("levels", std::uint64_t(index_.levels()));
  w.add_value("layout", std::uint32_t(index_.layout()));
  w.add_value("spacing", spacing_);
  w.add_value("origin", origin_);
  w.add_value("z_scale", z_scale_);
  w.add_value("filled", filled_);
  w.add("records", records_);
  w.write(path);
}

Terrain Terrain::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kTerrainArchiveKind, kTerrainArchiveVersion, verify);
  Terrain t;
  t.width_ = a.value<std::uint64_t>("width");
  t.height_ = a.value<std::uint64_t>("height");
  const std::uint64_t levels = a.value<std::uint64_t>("levels");
  const std::uint32_t layout = a.value<std::uint32_t>("layout");
  t.spacing_ = a.value<std::array<double, 2>>("spacing");
  t.origin_ = a.value<std::array<double, 2>>("origin");
  t.z_scale_ = a.value<double>("z_scale");
  t.filled_ = a.value<std::uint64_t>("filled");
  a.check([&] {
    if (layout > 1) throw Error("unknown layout " + std::to_string(layout));
    if (levels < 1 || levels > 30) throw Error("levels " + std::to_string(levels) + " outside 1..30");
    const std::uint64_t n = (std::uint64_t(1) << levels) + 1;
    std::uint64_t expected = 1;
    while ((std::uint64_t(1) << expected) + 1 < std::max(t.width_, t.height_)) ++expected;
    if (t.width_ < 2 || t.height_ < 2 || t.width_ > n || t.height_ > n || expected != levels)
      throw Error("a " + std::to_string(t.width_) + " x " + std::to_string(t.height_) + " field in a grid of " +
                  std::to_string(n));
    for (const double v : {t.spacing_[0], t.spacing_[1], t.origin_[0], t.origin_[1], t.z_scale_})
      if (!std::isfinite(v)) throw Error("a spacing, origin or z_scale that is not finite");
    if (t.spacing_[0] == 0 || t.spacing_[1] == 0 || t.z_scale_ == 0) throw Error("a zero spacing or z_scale");
    t.index_ = LayoutIndex(Layout(layout), std::uint32_t(levels));
  });
  t.records_ = a.array<VertexRecord>("records", t.index_.slots());
  return t;
}

}  // namespace geods::terrain
