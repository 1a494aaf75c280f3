// Closest pair, all nearest neighbours, EMST and k nearest sites from the Delaunay graph.
#include "geods/voronoi/proximity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>

#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = std::uint32_t(-1);

// The Delaunay graph of 3D points as the 2D functions read it: size(),
// representative(i) (kNone for a removed point), neighbors(i), points().
// Without tetrahedra (fewer than four non-coplanar points) every other site is
// a neighbour: O(n^2), which the graph of the lower-dimensional set would
// avoid, but such sets are small in practice.
struct Delaunay3Graph {
  const Delaunay3& dt;
  std::vector<std::uint32_t> sites;  // only for dimension() < 3
  // The Delaunay graph takes any finite coordinates; the distances along it
  // are squared in double, so `what` refuses what they cannot hold.
  Delaunay3Graph(const Delaunay3& d, const char* what) : dt(d) {
    if (!dt.points().empty())
      check_coordinate_range(dt.points().front().data(), dt.points().size(), 3, 3, 2, what);
    if (dt.dimension() < 3)
      for (std::uint32_t i = 0; i < dt.points().size(); ++i)
        if (dt.representative(i) == i) sites.push_back(i);
  }
  std::size_t size() const { return dt.points().size(); }
  std::uint32_t representative(std::uint32_t i) const { return dt.representative(i); }
  std::span<const Vec3d> points() const { return dt.points(); }
  std::vector<std::uint32_t> neighbors(std::uint32_t i) const {
    if (dt.dimension() == 3) return dt.vertex_neighbors(i);
    std::vector<std::uint32_t> out;
    for (std::uint32_t s : sites)
      if (s != i) out.push_back(s);
    return out;
  }
};

template <class Graph>
void require_two(const Graph& graph, const char* what) {
  std::size_t present = 0;
  for (std::uint32_t i = 0; i < graph.size() && present < 2; ++i) present += graph.representative(i) != kNone;
  if (present < 2) throw Error(std::string(what) + ": needs at least 2 points, got " + std::to_string(present));
}

template <class Graph>
double squared(const Graph& d, std::uint32_t a, std::uint32_t b) {
  return (d.points()[a] - d.points()[b]).squaredNorm();
}

// Every candidate edge of the spanning tree and of the closest pair: the Delaunay
// edges between representatives (i < j) and each duplicate with its first occurrence.
template <class Graph>
std::vector<std::pair<std::uint32_t, std::uint32_t>> candidate_edges(const Graph& diagram) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (std::uint32_t i = 0; i < diagram.size(); ++i) {
    const std::uint32_t r = diagram.representative(i);
    if (r == kNone) continue;  // removed
    if (r != i) {
      out.push_back({r, i});
      continue;
    }
    for (std::uint32_t nb : diagram.neighbors(i))
      if (i < nb) out.push_back({i, nb});
  }
  return out;
}

template <class Graph>
ClosestPair closest_pair_of(const Graph& diagram) {
  require_two(diagram, "closest_pair");
  ClosestPair best;
  double best_d = std::numeric_limits<double>::infinity();
  for (const auto& [i, j] : candidate_edges(diagram)) {
    const double d = squared(diagram, i, j);
    if (d < best_d || (d == best_d && std::pair(i, j) < std::pair(best.i, best.j))) {
      best_d = d;
      best = {i, j, std::sqrt(d)};
    }
  }
  return best;
}

template <class Graph>
std::vector<std::uint32_t> all_nearest_neighbors_of(const Graph& diagram) {
  require_two(diagram, "all_nearest_neighbors");
  const std::size_t n = diagram.size();
  // The two smallest indices of each group of copies (kNone when a site has no copy).
  std::vector<std::uint32_t> second(n, kNone);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = diagram.representative(i);
    if (r != kNone && r != i && second[r] == kNone) second[r] = i;
  }
  std::vector<std::uint32_t> nearest(n, kNone);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = diagram.representative(i);
    if (r == kNone) continue;
    if (r != i) {
      nearest[i] = r;
    } else if (second[i] != kNone) {
      nearest[i] = second[i];
    } else {
      double best = std::numeric_limits<double>::infinity();
      for (std::uint32_t nb : diagram.neighbors(i))
        if (const double d = squared(diagram, i, nb); d < best || (d == best && nb < nearest[i])) best = d, nearest[i] = nb;
    }
  }
  return nearest;
}

template <class Graph>
SpanningTree emst_of(const Graph& diagram) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> candidates = candidate_edges(diagram);
  std::vector<double> length(candidates.size());
  for (std::size_t k = 0; k < candidates.size(); ++k) length[k] = squared(diagram, candidates[k].first, candidates[k].second);
  std::vector<std::uint32_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return std::tie(length[a], candidates[a]) < std::tie(length[b], candidates[b]);
  });
  std::vector<std::uint32_t> parent(diagram.size());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto root = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::size_t present = 0;
  for (std::uint32_t i = 0; i < diagram.size(); ++i) present += diagram.representative(i) != kNone;
  SpanningTree tree;
  if (present == 0) return tree;
  tree.edges.reserve(present - 1);
  for (std::uint32_t k : order) {
    const std::uint32_t a = root(candidates[k].first), b = root(candidates[k].second);
    if (a == b) continue;
    parent[std::max(a, b)] = std::min(a, b);
    tree.edges.push_back(candidates[k]);
    tree.length += std::sqrt(length[k]);
    if (tree.edges.size() + 1 == present) break;
  }
  return tree;
}

}  // namespace

ClosestPair closest_pair(const Voronoi2& diagram) { return closest_pair_of(diagram); }
std::vector<std::uint32_t> all_nearest_neighbors(const Voronoi2& diagram) { return all_nearest_neighbors_of(diagram); }
SpanningTree emst(const Voronoi2& diagram) { return emst_of(diagram); }
ClosestPair closest_pair(const Delaunay3& dt) { return closest_pair_of(Delaunay3Graph(dt, "closest_pair")); }
std::vector<std::uint32_t> all_nearest_neighbors(const Delaunay3& dt) {
  return all_nearest_neighbors_of(Delaunay3Graph(dt, "all_nearest_neighbors"));
}
SpanningTree emst(const Delaunay3& dt) { return emst_of(Delaunay3Graph(dt, "emst")); }
ClosestPair closest_pair(std::span<const Vec3d> points) { return closest_pair(Delaunay3(points)); }
std::vector<std::uint32_t> all_nearest_neighbors(std::span<const Vec3d> points) {
  return all_nearest_neighbors(Delaunay3(points));
}
SpanningTree emst(std::span<const Vec3d> points) { return emst(Delaunay3(points)); }

ClosestPair closest_pair(std::span<const Vec2d> points) { return closest_pair(Voronoi2(points)); }
std::vector<std::uint32_t> all_nearest_neighbors(std::span<const Vec2d> points) {
  return all_nearest_neighbors(Voronoi2(points));
}
SpanningTree emst(std::span<const Vec2d> points) { return emst(Voronoi2(points)); }

std::vector<std::uint32_t> k_nearest_sites(const WalkLocator& locator, const Vec2d& q, std::size_t k) {
  const Voronoi2& diagram = locator.diagram();
  std::vector<std::uint32_t> out;
  if (k == 0) return out;
  using Entry = std::pair<double, std::uint32_t>;  // squared distance, site
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> frontier;
  std::vector<std::uint32_t> seen;  // sorted
  const auto push = [&](std::uint32_t s) {
    const auto at = std::lower_bound(seen.begin(), seen.end(), s);
    if (at != seen.end() && *at == s) return;
    seen.insert(at, s);
    frontier.push({(diagram.points()[s] - q).squaredNorm(), s});
  };
  push(locator.nearest(q));
  while (!frontier.empty() && out.size() < k) {
    const std::uint32_t s = frontier.top().second;
    frontier.pop();
    out.push_back(s);
    for (std::uint32_t nb : diagram.neighbors(s)) push(nb);
  }
  return out;
}

}  // namespace geods::voronoi
