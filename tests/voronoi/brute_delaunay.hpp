#pragma once
// Test oracles for the voronoi tests: a brute-force Delaunay triangulation of
// points in general position (every triangle with an empty circumcircle, by the
// exact incircle predicate), a diagonal triangulation of an integer grid (a
// Delaunay triangulation with four co-circular points per square), and
// brute-force nearest sites.
#include <cstdint>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi::testing {

struct Triangulation {
  std::vector<Vec2d> points;
  std::vector<std::uint32_t> triangles, halfedges, representative;

  Voronoi2 voronoi() const { return Voronoi2(points, triangles, halfedges, representative); }
};

inline std::vector<Vec2d> uniform_points(std::size_t n, std::uint64_t seed, double lo = 0, double hi = 1) {
  Rng rng(seed);
  std::vector<Vec2d> p(n);
  for (Vec2d& v : p) v = {rng.uniform(lo, hi), rng.uniform(lo, hi)};
  return p;
}

// 4 to 15 sites of the 6 x 6 integer lattice (duplicates likely); with
// moved_rows, each raised by 0, 0.01 or 0.02 (nearly co-circular quadruples).
inline std::vector<Vec2d> lattice_subset(std::uint64_t seed, bool moved_rows) {
  Rng rng(seed);
  std::vector<Vec2d> sites(4 + rng.below(12));
  for (Vec2d& s : sites)
    s = Vec2d(double(rng.below(6)), double(rng.below(6)) + (moved_rows ? 0.01 * double(rng.below(3)) : 0.0));
  return sites;
}

inline void link_halfedges(Triangulation& t) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> directed;
  for (std::uint32_t e = 0; e < t.triangles.size(); ++e)
    directed[{t.triangles[e], t.triangles[e % 3 == 2 ? e - 2 : e + 1]}] = e;
  t.halfedges.assign(t.triangles.size(), Voronoi2::kNoEdge);
  for (const auto& [edge, e] : directed)
    if (const auto it = directed.find({edge.second, edge.first}); it != directed.end()) t.halfedges[e] = it->second;
}

inline std::vector<std::uint32_t> first_occurrences(const std::vector<Vec2d>& points) {
  std::vector<std::uint32_t> rep(points.size());
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    rep[i] = i;
    for (std::uint32_t j = 0; j < i; ++j)
      if (points[j] == points[i]) {
        rep[i] = j;
        break;
      }
  }
  return rep;
}

/// O(n^4): for points whose distinct ones are in general position (no four co-circular).
inline Triangulation brute_delaunay(const std::vector<Vec2d>& points) {
  Triangulation t;
  t.points = points;
  t.representative = first_occurrences(points);
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < points.size(); ++i)
    if (t.representative[i] == i) sites.push_back(i);
  for (std::size_t a = 0; a < sites.size(); ++a)
    for (std::size_t b = a + 1; b < sites.size(); ++b)
      for (std::size_t c = b + 1; c < sites.size(); ++c) {
        std::uint32_t i = sites[a], j = sites[b], k = sites[c];
        const double o = orient2d(points[i], points[j], points[k]);
        if (o == 0) continue;
        if (o < 0) std::swap(j, k);
        bool empty = true;
        for (std::uint32_t s : sites)
          if (s != i && s != j && s != k && incircle(points[i], points[j], points[k], points[s]) > 0) {
            empty = false;
            break;
          }
        if (empty) t.triangles.insert(t.triangles.end(), {i, j, k});
      }
  link_halfedges(t);
  return t;
}

/// The k x k integer grid, each square cut by its diagonal from lower left to upper right.
inline Triangulation grid_delaunay(std::uint32_t k) {
  Triangulation t;
  for (std::uint32_t y = 0; y < k; ++y)
    for (std::uint32_t x = 0; x < k; ++x) t.points.push_back(Vec2d(x, y));
  t.representative = first_occurrences(t.points);
  for (std::uint32_t y = 0; y + 1 < k; ++y)
    for (std::uint32_t x = 0; x + 1 < k; ++x) {
      const std::uint32_t a = y * k + x, b = a + 1, c = a + k + 1, d = a + k;
      t.triangles.insert(t.triangles.end(), {a, b, c, a, c, d});
    }
  link_halfedges(t);
  return t;
}

/// The smallest squared distance from q to any point.
inline double nearest_squared_distance(const std::vector<Vec2d>& points, const Vec2d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec2d& p : points) best = std::min(best, (p - q).squaredNorm());
  return best;
}

/// Length of a minimum spanning tree of the complete graph (Prim, O(n^2)).
inline double prim_mst_length(const std::vector<Vec2d>& p) {
  std::vector<double> key(p.size(), std::numeric_limits<double>::infinity());
  std::vector<char> in(p.size(), 0);
  if (!p.empty()) key[0] = 0;
  double length = 0;
  for (std::size_t step = 0; step < p.size(); ++step) {
    std::size_t u = p.size();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!in[i] && (u == p.size() || key[i] < key[u])) u = i;
    in[u] = 1;
    length += key[u];
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!in[i]) key[i] = std::min(key[i], (p[u] - p[i]).norm());
  }
  return length;
}

}  // namespace geods::voronoi::testing
