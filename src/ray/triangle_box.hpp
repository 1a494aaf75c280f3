#pragma once
// Triangle / box overlap by the separating axis theorem (Akenine-Möller): the
// box's three axes, the triangle's normal and the nine cross products of the
// edges with the box axes. In double; callers widen the box by a margin, so
// the test only has to be conservative, never exact.
#include <algorithm>
#include <cmath>

#include "geods/core/aabb.hpp"

namespace geods::ray::detail {

inline bool triangle_overlaps_box(const Vec3f& a, const Vec3f& b, const Vec3f& c, const AABB3f& box) {
  const Vec3d center = (box.lo.cast<double>() + box.hi.cast<double>()) * 0.5;
  const Vec3d half = (box.hi.cast<double>() - box.lo.cast<double>()) * 0.5;
  const Vec3d v[3] = {a.cast<double>() - center, b.cast<double>() - center, c.cast<double>() - center};
  auto separated = [&](const Vec3d& axis) {
    const double p0 = axis.dot(v[0]), p1 = axis.dot(v[1]), p2 = axis.dot(v[2]);
    const double r = half.dot(axis.cwiseAbs());
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  for (int i = 0; i < 3; ++i)
    if (separated(Vec3d::Unit(i))) return false;
  const Vec3d edges[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  if (separated(edges[0].cross(edges[1]))) return false;
  for (const Vec3d& e : edges)
    for (int i = 0; i < 3; ++i)
      if (separated(e.cross(Vec3d::Unit(i)))) return false;
  return true;
}

inline AABB3f triangle_bounds(const Vec3f* corners) {
  AABB3f box = AABB3f::of_point(corners[0]);
  box.extend(corners[1]).extend(corners[2]);
  return box;
}

/// The box widened by m on every side.
inline AABB3f widened(const AABB3f& box, float m) { return {box.lo.array() - m, box.hi.array() + m}; }

}  // namespace geods::ray::detail
