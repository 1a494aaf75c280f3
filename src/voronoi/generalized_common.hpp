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

/// Counter-clockwise convex hull of floating-point points (monotone chain), without collinear points.
inline std::vector<Vec2d> convex_polygon_of(std::vector<Vec2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const Vec2d& a, const Vec2d& b) { return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return {};
  std::vector<Vec2d> hull(2 * pts.size());
  std::size_t k = 0;
  const auto cross = [](const Vec2d& o, const Vec2d& a, const Vec2d& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  // Corners found twice (rounded apart by the clipping of neighbouring pieces) count once.
  double extent = 0;
  for (const Vec2d& p : pts) extent = std::max(extent, (p - pts.front()).cwiseAbs().maxCoeff());
  std::vector<Vec2d> out;
  for (const Vec2d& p : hull)
    if (out.empty() || (p - out.back()).cwiseAbs().maxCoeff() > 1e-12 * extent) out.push_back(p);
  while (out.size() > 1 && (out.front() - out.back()).cwiseAbs().maxCoeff() <= 1e-12 * extent) out.pop_back();
  if (out.size() < 3) out.clear();
  return out;
}

/// Whether a polygon is no more than the rounding of its corners (u |corner|
/// each, across its perimeter): a sliver that cutting by lines left, not a
/// region. (Relative to the polygon, not the box: regions of sites 1e-7 of the
/// box apart are 1e-14 of its area.)
inline bool negligible_area(const std::vector<Vec2d>& polygon) {
  double perimeter = 0, far = 0;
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    perimeter += (polygon[(k + 1) % polygon.size()] - polygon[k]).norm();
    far = std::max(far, polygon[k].cwiseAbs().maxCoeff());
  }
  return polygon_area(polygon) <= 8 * std::numeric_limits<double>::epsilon() * far * perimeter;
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
