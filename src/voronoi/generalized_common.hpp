#pragma once
// Checks and small geometry shared by the generalized diagrams (farthest-point,
// k-th order, constrained, other metrics).
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"

namespace geods::voronoi::detail {

inline void check_sites_and_box(std::span<const Vec2d> points, const AABB2d& box, const std::string& what) {
  if (points.empty()) throw Error(what + ": no points");
  if (points.size() >= (std::size_t(1) << 30)) throw Error(what + ": 2^30 points or more");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]))
      throw Error(what + ": non-finite coordinates at point " + std::to_string(i));
  check_coordinate_range(points.front().data(), points.size(), 2, 2, 3, what);
  if (box.empty() || !box.lo.allFinite() || !box.hi.allFinite() || !(box.lo[0] < box.hi[0] && box.lo[1] < box.hi[1]))
    throw Error(what + ": empty or non-finite box");
}

/// Fills `representative` (per point, its first equal point) from the
/// triangulation and returns the representatives (the distinct sites), ascending.
inline std::vector<std::uint32_t> distinct_sites(const Delaunay2& dt, std::vector<std::uint32_t>& representative) {
  const std::size_t n = dt.points().size();
  representative.resize(n);
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < n; ++i) {
    representative[i] = dt.representative(i);
    if (representative[i] == i) sites.push_back(i);
  }
  return sites;
}

/// The counter-clockwise convex hull of points (monotone chain, exact
/// orientations), as indices into them; without collinear or repeated points.
inline std::vector<std::uint32_t> convex_hull_of(const std::vector<Vec2d>& pts) {
  std::vector<std::uint32_t> order(pts.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto less = [&](std::uint32_t i, std::uint32_t j) {
    return pts[i][0] < pts[j][0] || (pts[i][0] == pts[j][0] && pts[i][1] < pts[j][1]);
  };
  std::sort(order.begin(), order.end(), less);
  order.erase(std::unique(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) { return pts[i] == pts[j]; }),
              order.end());
  if (order.size() < 3) return {};
  const auto cross = [&](std::uint32_t o, std::uint32_t a, std::uint32_t b) { return orient2d(pts[o], pts[a], pts[b]); };
  std::vector<std::uint32_t> hull(2 * order.size());
  std::size_t k = 0;
  for (std::uint32_t i : order) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], i) <= 0) --k;
    hull[k++] = i;
  }
  for (std::size_t r = order.size() - 1, lower = k + 1; r-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], order[r]) <= 0) --k;
    hull[k++] = order[r];
  }
  hull.resize(k - 1);
  return hull;
}

/// Whether a polygon is no more than the rounding of its corners (u |corner|
/// on each axis, across the edges along the other): a sliver that cutting by
/// lines left, not a region. (Relative to the polygon, not the box: regions of
/// sites 1e-7 of the box apart are 1e-14 of its area; and per axis: a strip
/// 1e-12 high at x = 1e6 is a region, its y still exact to 1e-16.)
inline bool negligible_area(const std::vector<Vec2d>& polygon) {
  Vec2d travel(0, 0), far(0, 0);
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    travel += (polygon[(k + 1) % polygon.size()] - polygon[k]).cwiseAbs();
    far = far.cwiseMax(polygon[k].cwiseAbs());
  }
  return polygon_area(polygon) <=
         8 * std::numeric_limits<double>::epsilon() * (far[0] * travel[1] + far[1] * travel[0]);
}

/// Checks a counter-clockwise polygon inside the box (to 1e-9 of its side).
inline void check_cell(const std::vector<Vec2d>& cell, const AABB2d& box, const std::string& what) {
  if (cell.empty()) return;
  const double side = std::max(box.hi[0] - box.lo[0], box.hi[1] - box.lo[1]);
  for (const Vec2d& a : cell)
    if (((a - box.lo).array() < -1e-9 * side).any() || ((a - box.hi).array() > 1e-9 * side).any())
      throw Error(what + " leaves the box");
  if (polygon_area(cell) < 0) throw Error(what + " is clockwise");
}

}  // namespace geods::voronoi::detail
