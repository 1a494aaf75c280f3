// Closest pair, all nearest neighbours, EMST and k nearest sites from the Delaunay graph.
#include "geods/voronoi/proximity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>

#include "geods/core/error.hpp"

namespace geods::voronoi {
namespace {

void require_two(const Voronoi2& diagram, const char* what) {
  if (diagram.size() < 2) throw Error(std::string(what) + ": needs at least 2 points, got " + std::to_string(diagram.size()));
}

double squared(const Voronoi2& d, std::uint32_t a, std::uint32_t b) {
  return (d.points()[a] - d.points()[b]).squaredNorm();
}

// Every candidate edge of the spanning tree and of the closest pair: the Delaunay
// edges between representatives (i < j) and each duplicate with its first occurrence.
std::vector<std::pair<std::uint32_t, std::uint32_t>> candidate_edges(const Voronoi2& diagram) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (std::uint32_t i = 0; i < diagram.size(); ++i) {
    const std::uint32_t r = diagram.representative(i);
    if (r != i) {
      out.push_back({r, i});
      continue;
    }
    for (std::uint32_t nb : diagram.neighbors(i))
      if (i < nb) out.push_back({i, nb});
  }
  return out;
}

}  // namespace

ClosestPair closest_pair(const Voronoi2& diagram) {
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

std::vector<std::uint32_t> all_nearest_neighbors(const Voronoi2& diagram) {
  require_two(diagram, "all_nearest_neighbors");
  const std::size_t n = diagram.size();
  // The two smallest indices of each group of copies (kInfinity when a site has no copy).
  std::vector<std::uint32_t> second(n, Voronoi2::kInfinity);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = diagram.representative(i);
    if (r != i && second[r] == Voronoi2::kInfinity) second[r] = i;
  }
  std::vector<std::uint32_t> nearest(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = diagram.representative(i);
    if (r != i) {
      nearest[i] = r;
    } else if (second[i] != Voronoi2::kInfinity) {
      nearest[i] = second[i];
    } else {
      double best = std::numeric_limits<double>::infinity();
      for (std::uint32_t nb : diagram.neighbors(i))
        if (const double d = squared(diagram, i, nb); d < best || (d == best && nb < nearest[i])) best = d, nearest[i] = nb;
    }
  }
  return nearest;
}

SpanningTree emst(const Voronoi2& diagram) {
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
  SpanningTree tree;
  tree.edges.reserve(diagram.size() - 1);
  for (std::uint32_t k : order) {
    const std::uint32_t a = root(candidates[k].first), b = root(candidates[k].second);
    if (a == b) continue;
    parent[std::max(a, b)] = std::min(a, b);
    tree.edges.push_back(candidates[k]);
    tree.length += std::sqrt(length[k]);
    if (tree.edges.size() + 1 == diagram.size()) break;
  }
  return tree;
}

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
