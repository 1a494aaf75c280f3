// Smallest enclosing circle (Welzl) and largest empty circle (Voronoi vertices and hull crossings).
#include "geods/voronoi/circles.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "exact_compare.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"

namespace geods::voronoi {
namespace {

// A circle of Welzl's algorithm, held by the 1 to 3 points on its boundary that define it.
struct Support {
  std::array<Vec2d, 3> p;
  int size = 0;

  explicit Support(const Vec2d& a) : p{a, a, a}, size(1) {}
  Support(const Vec2d& a, const Vec2d& b) : p{a, b, b}, size(2) {}
  Support(const Vec2d& a, const Vec2d& b, const Vec2d& c) : p{a, b, c}, size(3) {}

  // Exact: is q in the closed disc?
  bool contains(const Vec2d& q) const {
    switch (size) {
      case 1: return q == p[0];
      case 2: return detail::diametral_sign(q, p[0], p[1]) <= 0;
      default: {
        const double o = orient2d(p[0], p[1], p[2]);
        if (o == 0) return diameter_contains(q);
        const double in = incircle(p[0], p[1], p[2], q);
        return o > 0 ? in >= 0 : in <= 0;
      }
    }
  }
  // Three collinear support points (only reachable through rounding of the
  // input, never in exact arithmetic): the circle on their farthest pair.
  bool diameter_contains(const Vec2d& q) const {
    const auto [a, b] = farthest_pair();
    return detail::diametral_sign(q, a, b) <= 0;
  }
  std::pair<Vec2d, Vec2d> farthest_pair() const {
    std::pair<Vec2d, Vec2d> best{p[0], p[1]};
    double d = (p[0] - p[1]).squaredNorm();
    if (const double e = (p[0] - p[2]).squaredNorm(); e > d) d = e, best = {p[0], p[2]};
    if ((p[1] - p[2]).squaredNorm() > d) best = {p[1], p[2]};
    return best;
  }
  Vec2d center() const {
    switch (size) {
      case 1: return p[0];
      case 2: return (p[0] + p[1]) / 2;
      default: {
        if (orient2d(p[0], p[1], p[2]) != 0) return detail::circumcentre(p[0], p[1], p[2]);
        const auto [a, b] = farthest_pair();
        return (a + b) / 2;
      }
    }
  }
};

void check_points(std::span<const Vec2d> points, const char* what) {
  if (points.empty()) throw Error(std::string(what) + ": no points");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]))
      throw Error(std::string(what) + ": non-finite coordinates at point " + std::to_string(i));
  check_coordinate_range(points.front().data(), points.size(), 2, 2, 3, what);
}

// The convex hull of the sites, counter-clockwise: the next hull site after a
// is across the ray that comes into a's cell from infinity.
std::vector<std::uint32_t> hull_sites(const Voronoi2& diagram) {
  std::vector<std::uint32_t> hull;
  std::uint32_t first = Voronoi2::kInfinity;
  for (std::uint32_t i = 0; i < diagram.size() && first == Voronoi2::kInfinity; ++i)
    if (diagram.representative(i) == i && !diagram.bounded(i)) first = i;
  std::uint32_t s = first;
  do {
    hull.push_back(s);
    s = diagram.opposite_site(diagram.cell_edge(s));
  } while (s != first && hull.size() <= diagram.size());
  return hull;
}

// Inside or on the convex polygon `hull` (counter-clockwise, >= 3 sites), exactly for the given double point.
bool in_hull(const Voronoi2& diagram, const std::vector<std::uint32_t>& hull, const Vec2d& p) {
  const auto at = [&](std::size_t k) -> const Vec2d& { return diagram.points()[hull[k]]; };
  const std::size_t h = hull.size();
  if (orient2d(at(0), at(1), p) < 0 || orient2d(at(0), at(h - 1), p) > 0) return false;
  std::size_t lo = 1, hi = h - 1;  // the wedge at(0), at(lo), at(lo + 1) holds p
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (orient2d(at(0), at(mid), p) >= 0 ? lo : hi) = mid;
  }
  return orient2d(at(lo), at(lo + 1), p) >= 0;
}

// Follows the segment from site a to site b through the cells it crosses and
// offers each crossing point (on a Voronoi edge) as a centre.
template <typename Offer>
void follow_segment(const Voronoi2& diagram, std::uint32_t a, std::uint32_t b, const Offer& offer) {
  const std::span<const Vec2d> points = diagram.points();
  const Vec2d from = points[a], along = points[b] - points[a];
  std::uint32_t cell = a;
  double t = 0;
  for (std::size_t steps = 0; cell != b && steps <= diagram.size(); ++steps) {
    // Leave the cell through the first bisector with a neighbour we move towards.
    double exit = std::numeric_limits<double>::infinity();
    std::uint32_t into = Voronoi2::kInfinity;
    const Vec2d& c = points[cell];
    for (std::uint32_t nb : diagram.neighbors(cell)) {
      const Vec2d& d = points[nb];
      const double towards = along.dot(d - c);
      if (towards <= 0) continue;
      const double crossing = (d.squaredNorm() - c.squaredNorm() - 2 * from.dot(d - c)) / (2 * towards);
      if (crossing < exit || (crossing == exit && nb < into)) exit = crossing, into = nb;
    }
    if (into == Voronoi2::kInfinity || exit >= 1) break;
    t = std::max(t, exit);
    const Vec2d x = from + t * along;
    offer(x, (x - c).norm());
    cell = into;
  }
}

}  // namespace

Circle smallest_enclosing_circle(std::span<const Vec2d> points, std::uint64_t seed) {
  check_points(points, "smallest_enclosing_circle");
  std::vector<std::uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  Rng rng(seed);
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);

  Support s(points[order[0]]);
  for (std::size_t i = 1; i < order.size(); ++i) {
    const Vec2d& p = points[order[i]];
    if (s.contains(p)) continue;
    s = Support(p);  // p is on the boundary of the circle of the first i + 1 points
    for (std::size_t j = 0; j < i; ++j) {
      const Vec2d& q = points[order[j]];
      if (s.contains(q)) continue;
      s = Support(p, q);  // and so is q
      for (std::size_t k = 0; k < j; ++k) {
        const Vec2d& r = points[order[k]];
        if (!s.contains(r)) s = Support(p, q, r);
      }
    }
  }
  Circle circle{s.center(), 0};
  for (const Vec2d& p : points) circle.radius = std::max(circle.radius, (p - circle.center).norm());
  return circle;
}

Circle largest_empty_circle(const Voronoi2& diagram) {
  Circle best{diagram.points()[0], 0};
  const auto offer = [&](const Vec2d& center, double radius) {
    if (radius > best.radius) best = {center, radius};
  };
  if (diagram.edges().empty()) return best;  // one distinct site
  if (diagram.vertices().empty()) {
    // Collinear sites: the hull is the segment between the two extreme sites.
    std::uint32_t lo = Voronoi2::kInfinity, hi = Voronoi2::kInfinity;
    for (std::uint32_t i = 0; i < diagram.size(); ++i) {
      if (diagram.representative(i) != i) continue;
      const auto key = [&](std::uint32_t s) { return std::pair(diagram.points()[s][0], diagram.points()[s][1]); };
      if (lo == Voronoi2::kInfinity || key(i) < key(lo)) lo = i;
      if (hi == Voronoi2::kInfinity || key(hi) < key(i)) hi = i;
    }
    follow_segment(diagram, lo, hi, offer);
    return best;
  }
  const std::vector<std::uint32_t> hull = hull_sites(diagram);
  const auto& edges = diagram.edges();
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    const std::uint32_t v = edges[e].origin;
    if (v == Voronoi2::kInfinity) continue;
    const Vec2d& center = diagram.vertices()[v];
    const double radius = (center - diagram.points()[edges[e].site]).norm();
    if (radius > best.radius && in_hull(diagram, hull, center)) best = {center, radius};
  }
  for (std::size_t k = 0; k < hull.size(); ++k) follow_segment(diagram, hull[k], hull[(k + 1) % hull.size()], offer);
  return best;
}

Circle largest_empty_circle(std::span<const Vec2d> points) { return largest_empty_circle(Voronoi2(points)); }

}  // namespace geods::voronoi
