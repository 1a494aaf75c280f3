#pragma once
// Small polygon helpers for the voronoi module: clipping to a box, point in polygon.
#include <optional>
#include <utility>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

/// Sutherland-Hodgman: the part of `polygon` inside `box`, counter-clockwise if
/// `polygon` is. Exact for convex polygons; a non-convex one whose clipped part
/// falls apart comes back as one polygon joined by zero-width bridges along the box.
std::vector<Vec2d> clip_polygon_to_box(const std::vector<Vec2d>& polygon, const AABB2d& box);

/// Liang-Barsky: the part of segment ab inside `box`, if any.
std::optional<std::pair<Vec2d, Vec2d>> clip_segment_to_box(const Vec2d& a, const Vec2d& b, const AABB2d& box);

/// Whether p lies inside the simple polygon (even-odd rule; points on the boundary may go either way).
bool point_in_polygon(const Vec2d& p, const std::vector<Vec2d>& polygon);

/// The z component of the cross product of a and b: twice the signed area of
/// the triangle (0, a, b).
inline double cross(const Vec2d& a, const Vec2d& b) { return a[0] * b[1] - a[1] * b[0]; }

/// The distance from x to the segment ab (to a if a == b).
double point_segment_distance(const Vec2d& x, const Vec2d& a, const Vec2d& b);

/// Signed area, positive for counter-clockwise polygons.
double polygon_area(const std::vector<Vec2d>& polygon);

}  // namespace geods::voronoi
