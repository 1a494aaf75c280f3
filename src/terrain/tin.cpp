// Triangulated irregular networks by greedy insertion (Garland & Heckbert)
// into the voronoi module's Delaunay triangulation, tiled without cracks.
#include <algorithm>
#include <cmath>
#include <queue>
#include <unordered_map>

#include "geods/core/error.hpp"
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
  double worst = 0;
  std::int64_t at = 0;
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

struct Candidate {
  double error;
  std::array<std::uint32_t, 3> triangle;  // Delaunay2 point indices, sorted
  P2 at;
  bool operator<(const Candidate& o) const { return error < o.error; }
};

}  // namespace

TerrainMesh Terrain::tin(double max_error, std::uint32_t tiles) const {
  if (!(max_error >= 0) || !std::isfinite(max_error)) throw Error("terrain tin: max_error must be finite and >= 0");
  if (tiles < 1 || tiles > std::min(width_, height_) - 1)
    throw Error("terrain tin: tiles must be in 1.." + std::to_string(std::min(width_, height_) - 1) + ", got " +
                std::to_string(tiles));
  const std::vector<float> z = heights_matrix();
  const std::int64_t W = std::int64_t(width_), H = std::int64_t(height_);
  float lo = z[0], hi = z[0];
  for (const float v : z) lo = std::min(lo, v), hi = std::max(hi, v);
  // Interior samples must exceed the bound by more than rounding: a border
  // sample (within max_error along its border, measured in 1D) is then never
  // picked in 2D, so neighbouring tiles keep the same border vertices.
  const double limit = max_error + 1e-9 * (1 + std::abs(max_error) + double(hi - lo));
  std::vector<std::int64_t> xs(tiles + 1), ys(tiles + 1);
  for (std::uint32_t k = 0; k <= tiles; ++k) xs[k] = std::int64_t(k) * (W - 1) / tiles, ys[k] = std::int64_t(k) * (H - 1) / tiles;

  TerrainMesh mesh;
  std::unordered_map<std::uint64_t, std::uint32_t> vertex_of;  // sample id -> vertex
  auto vertex = [&](P2 p) {
    const std::uint64_t id = std::uint64_t(p.y) * width_ + std::uint64_t(p.x);
    auto [it, added] = vertex_of.try_emplace(id, std::uint32_t(mesh.vertices.size()));
    if (added) {
      mesh.samples.push_back({std::uint32_t(p.x), std::uint32_t(p.y)});
      mesh.vertices.push_back(Vec3f(float(origin_[0] + double(p.x) * spacing_[0]),
                                    float(origin_[1] + double(p.y) * spacing_[1]), z[id]));
    }
    return it->second;
  };

  for (std::uint32_t ty = 0; ty < tiles; ++ty)
    for (std::uint32_t tx = 0; tx < tiles; ++tx) {
      const P2 c00{xs[tx], ys[ty]}, c10{xs[tx + 1], ys[ty]}, c11{xs[tx + 1], ys[ty + 1]}, c01{xs[tx], ys[ty + 1]};
      std::vector<P2> start{c00, c10, c11, c01};
      // The border: each side simplified on its own (the neighbour does the same).
      simplify_segment(z.data(), width_, c00, c10, max_error, start);
      simplify_segment(z.data(), width_, c10, c11, max_error, start);
      simplify_segment(z.data(), width_, c01, c11, max_error, start);
      simplify_segment(z.data(), width_, c00, c01, max_error, start);
      std::vector<Vec2d> points;
      for (const P2& p : start) points.emplace_back(double(p.x), double(p.y));
      voronoi::Delaunay2 d(points);
      std::priority_queue<Candidate> queue;
      auto consider = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        const auto pa = d.points()[a], pb = d.points()[b], pc = d.points()[c];
        const P2 A{std::int64_t(pa.x()), std::int64_t(pa.y())}, B{std::int64_t(pb.x()), std::int64_t(pb.y())},
            C{std::int64_t(pc.x()), std::int64_t(pc.y())};
        const detail::Worst w = detail::triangle_worst(z.data(), width_, A, B, C);
        if (w.error <= limit) return;
        std::array<std::uint32_t, 3> key{a, b, c};
        std::sort(key.begin(), key.end());
        queue.push({w.error, key, w.at});
      };
      const auto& tris = d.triangles();
      for (std::size_t k = 0; k + 2 < tris.size(); k += 3) consider(tris[k], tris[k + 1], tris[k + 2]);
      // Whether triangle t is still in the triangulation: t[1], t[2] consecutive
      // around t[0] (the start points are the hull: their neighbour lists do not wrap).
      auto alive = [&](const std::array<std::uint32_t, 3>& t) {
        const std::vector<std::uint32_t> nb = d.neighbors(t[0]);
        const std::size_t pairs = t[0] < start.size() ? nb.size() - 1 : nb.size();
        for (std::size_t i = 0; i < pairs && nb.size() > 1; ++i) {
          const std::uint32_t u = nb[i], v = nb[(i + 1) % nb.size()];
          if ((u == t[1] && v == t[2]) || (u == t[2] && v == t[1])) return true;
        }
        return false;
      };
      while (!queue.empty()) {
        const Candidate top = queue.top();
        queue.pop();
        if (!alive(top.triangle)) continue;
        const std::uint32_t v = d.insert(Vec2d(double(top.at.x), double(top.at.y)));
        const std::vector<std::uint32_t> nb = d.neighbors(v);
        for (std::size_t i = 0; i < nb.size(); ++i) consider(v, nb[i], nb[(i + 1) % nb.size()]);
      }
      const auto& final_tris = d.triangles();
      for (std::size_t k = 0; k + 2 < final_tris.size(); k += 3) {
        std::array<std::uint32_t, 3> t;
        for (int e = 0; e < 3; ++e) {
          const Vec2d p = d.points()[final_tris[k + std::size_t(e)]];
          t[std::size_t(e)] = vertex(P2{std::int64_t(p.x()), std::int64_t(p.y())});
        }
        mesh.triangles.push_back(t);
      }
    }
  return mesh;
}

}  // namespace geods::terrain
