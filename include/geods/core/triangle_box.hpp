#pragma once
// Exact-enough triangle / axis-aligned box overlap: the separating axis test
// of Akenine-Möller (13 axes: 3 box normals, the triangle normal, 9 edge
// cross products), evaluated in double. Closed sets: touching counts.
#include <algorithm>

#include "geods/core/aabb.hpp"

namespace geods {

template <typename T>
bool triangle_box_overlap(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, const AABB<T, 3>& box) {
  if (box.empty()) return false;
  const Vec3d center = box.center().template cast<double>();
  const Vec3d half = ((box.hi - box.lo).template cast<double>()) / 2;
  const Vec3d v[3] = {a.template cast<double>() - center, b.template cast<double>() - center,
                      c.template cast<double>() - center};
  auto separated = [&](const Vec3d& axis) {
    const double p0 = axis.dot(v[0]), p1 = axis.dot(v[1]), p2 = axis.dot(v[2]);
    const double r = half.dot(axis.cwiseAbs());
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  for (int i = 0; i < 3; ++i)
    if (separated(Vec3d::Unit(i))) return false;
  const Vec3d e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  if (separated(e[0].cross(e[1]))) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (separated(Vec3d::Unit(i).cross(e[j]))) return false;
  return true;
}

}  // namespace geods
