// Polygon clipping, point-in-polygon and point-segment distance for the voronoi module.
#include "geods/voronoi/polygon_clip.hpp"

#include <algorithm>

#include "geods/core/segment.hpp"

namespace geods::voronoi {

std::vector<Vec2d> clip_polygon_to_box(const std::vector<Vec2d>& polygon, const AABB2d& box) {
  std::vector<Vec2d> current = polygon, clipped;
  // Keep the side where sign * (p[axis] - bound) <= 0, for the four sides of the box.
  for (int side = 0; side < 4 && !current.empty(); ++side) {
    const int axis = side % 2;
    const double bound = side < 2 ? box.hi[axis] : box.lo[axis];
    const double sign = side < 2 ? 1.0 : -1.0;
    const auto inside = [&](const Vec2d& p) { return sign * (p[axis] - bound) <= 0; };
    clipped.clear();
    for (std::size_t i = 0; i < current.size(); ++i) {
      const Vec2d& a = current[i];
      const Vec2d& b = current[(i + 1) % current.size()];
      const bool in_a = inside(a), in_b = inside(b);
      if (in_a) clipped.push_back(a);
      if (in_a != in_b) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        Vec2d x = a + t * (b - a);
        x[axis] = bound;  // exactly on the side despite rounding
        clipped.push_back(x);
      }
    }
    std::swap(current, clipped);
  }
  // Drop repeated points (a vertex on a side of the box is found twice).
  std::vector<Vec2d> out;
  for (const Vec2d& p : current)
    if (out.empty() || p != out.back()) out.push_back(p);
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  if (out.size() < 3) out.clear();
  return out;
}

std::optional<std::pair<Vec2d, Vec2d>> clip_segment_to_box(const Vec2d& a, const Vec2d& b, const AABB2d& box) {
  double t0 = 0, t1 = 1;
  const Vec2d d = b - a;
  for (int axis = 0; axis < 2; ++axis) {
    if (d[axis] == 0) {
      if (a[axis] < box.lo[axis] || a[axis] > box.hi[axis]) return std::nullopt;
      continue;
    }
    double lo = (box.lo[axis] - a[axis]) / d[axis], hi = (box.hi[axis] - a[axis]) / d[axis];
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  if (t0 > t1) return std::nullopt;
  return std::pair<Vec2d, Vec2d>(t0 == 0 ? a : Vec2d(a + t0 * d), t1 == 1 ? b : Vec2d(a + t1 * d));
}

bool point_in_polygon(const Vec2d& p, const std::vector<Vec2d>& polygon) {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Vec2d& a = polygon[i];
    const Vec2d& b = polygon[j];
    if ((a[1] > p[1]) != (b[1] > p[1]) && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0])
      inside = !inside;
  }
  return inside;
}

double point_segment_distance(const Vec2d& x, const Vec2d& a, const Vec2d& b) {
  return (x - closest_point_on_segment(x, a, b)).norm();
}

double polygon_area(const std::vector<Vec2d>& polygon) {
  // A fan about the first corner: far from the origin, the products of absolute
  // coordinates cancel the area away (a cell of side 1 at 1e15 lost it and its sign).
  double twice = 0;
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    const Vec2d a = polygon[i] - polygon[0], b = polygon[i + 1] - polygon[0];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return twice / 2;
}

}  // namespace geods::voronoi
