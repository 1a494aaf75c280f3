// The smallest color-spanning circle: an upper bound from per-color k-d trees,
// then the circles through each point and one or two near points.
#include "geods/voronoi/color_spanning.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "exact_compare.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace geods::voronoi {

ColorSpanningCircle smallest_color_spanning_circle(std::span<const Vec2d> points, std::span<const std::uint32_t> colors) {
  const char* what = "smallest_color_spanning_circle";
  const std::size_t n = points.size();
  if (n == 0) throw Error(std::string(what) + ": no points");
  if (colors.size() != n)
    throw Error(std::string(what) + ": " + std::to_string(colors.size()) + " colors for " + std::to_string(n) + " points");
  if (n >= (std::size_t(1) << 31)) throw Error(std::string(what) + ": 2^31 points or more");
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]))
      throw Error(std::string(what) + ": non-finite coordinates at point " + std::to_string(i));
  check_coordinate_range(points.front().data(), n, 2, 2, 3, what);

  ColorSpanningCircle result;
  result.colors.assign(colors.begin(), colors.end());
  std::sort(result.colors.begin(), result.colors.end());
  result.colors.erase(std::unique(result.colors.begin(), result.colors.end()), result.colors.end());
  const std::size_t m = result.colors.size();
  std::vector<std::uint32_t> color_index(n);
  for (std::size_t i = 0; i < n; ++i)
    color_index[i] = std::uint32_t(std::lower_bound(result.colors.begin(), result.colors.end(), colors[i]) - result.colors.begin());

  // Per color, the points and a k-d tree of them.
  std::vector<std::vector<std::uint32_t>> members(m);
  for (std::uint32_t i = 0; i < n; ++i) members[color_index[i]].push_back(i);
  std::vector<std::vector<Vec2d>> member_points(m);
  std::vector<spatial::KdTree<double, 2>> trees;
  trees.reserve(m);
  for (std::size_t c = 0; c < m; ++c) {
    for (std::uint32_t i : members[c]) member_points[c].push_back(points[i]);
    trees.emplace_back(spatial::PointView<double>(std::span<const Vec2d>(member_points[c])));
  }
  // The chosen points of a circle: per color the point nearest to its centre.
  const auto choose = [&](const Vec2d& center) {
    std::vector<std::uint32_t> chosen(m);
    double radius = 0;
    for (std::size_t c = 0; c < m; ++c) {
      const auto nn = trees[c].query(center, 1);
      chosen[c] = members[c][nn[0].index];
      radius = std::max(radius, std::sqrt(nn[0].squared_distance));
    }
    return std::pair(radius, chosen);
  };

  // Upper bound: the best circle centred at an input point (at most 2 r*).
  double best = std::numeric_limits<double>::infinity();
  Vec2d best_center = points[0];
  result.support = {0};
  const std::size_t step = std::max<std::size_t>(1, n * m / 4000000);
  for (std::size_t i = 0; i < n; i += step) {
    const double r = choose(points[i]).first;
    if (r < best) best = r, best_center = points[i], result.support = {std::uint32_t(i)};
  }
  if (m == 1 || best == 0) {
    auto [radius, chosen] = choose(best_center);
    result.circle = {best_center, radius};
    result.chosen = std::move(chosen);
    return result;
  }

  // The circles through each point p and one or two points within 2 * best of it.
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return points[a][0] < points[b][0]; });
  std::vector<std::uint32_t> stamp(m, 0), near;
  std::uint32_t round = 0;
  // Whether the circle (given by its containment test) holds a point of every color, among `near`.
  const auto spans = [&](const auto& contains) {
    ++round;
    std::size_t seen = 0;
    for (std::uint32_t q : near) {
      const std::uint32_t c = color_index[q];
      if (stamp[c] == round || !contains(points[q])) continue;
      stamp[c] = round;
      if (++seen == m) return true;
    }
    return false;
  };
  for (std::size_t a = 0; a < n; ++a) {
    const std::uint32_t i = order[a];
    const Vec2d& p = points[i];
    near.clear();
    near.push_back(i);
    // Points within 2 * best in x on both sides (the circle may extend either way), then by distance.
    const auto lo = std::lower_bound(order.begin(), order.end(), p[0] - 2 * best,
                                     [&](std::uint32_t q, double x) { return points[q][0] < x; });
    for (auto it = lo; it != order.end() && points[*it][0] <= p[0] + 2 * best; ++it)
      if (*it != i && (points[*it] - p).squaredNorm() <= 4 * best * best) near.push_back(*it);
    // Pairs and triples with p as the first of them in `order` (each circle is tried once).
    const auto later = [&](std::uint32_t q) { return points[q][0] > p[0] || (points[q][0] == p[0] && q > i); };
    for (std::size_t x = 1; x < near.size(); ++x) {
      const std::uint32_t j = near[x];
      if (!later(j)) continue;
      const Vec2d& q = points[j];
      const double pair_radius = (q - p).norm() / 2;
      if (pair_radius < best &&
          spans([&](const Vec2d& s) { return detail::diametral_sign(s, p, q) <= 0; })) {
        best = pair_radius;
        best_center = (p + q) / 2;
        result.support = {i, j};
        if (p == q) result.support = {i};
      }
      for (std::size_t y = x + 1; y < near.size(); ++y) {
        const std::uint32_t k = near[y];
        if (!later(k)) continue;
        const Vec2d& r = points[k];
        if ((r - q).squaredNorm() >= 4 * best * best) continue;
        const double side = orient2d(p, q, r);
        if (side == 0) continue;
        const Vec2d center = detail::circumcentre(p, q, r);
        const double radius = std::max({(center - p).norm(), (center - q).norm(), (center - r).norm()});
        if (radius >= best) continue;
        const bool ccw = side > 0;
        if (spans([&](const Vec2d& s) { return (ccw ? incircle(p, q, r, s) : incircle(p, r, q, s)) >= 0; })) {
          best = radius;
          best_center = center;
          result.support = {i, j, k};
        }
      }
    }
  }
  auto [radius, chosen] = choose(best_center);
  // The nearest point per color is within the circle: the radius only grows by rounding.
  result.circle = {best_center, std::max(radius, 0.0)};
  result.chosen = std::move(chosen);
  return result;
}

}  // namespace geods::voronoi
