#pragma once
// An oriented plane n·x = offset; the positive side is where n points.
#include "geods/core/vec.hpp"

namespace geods {

template <typename T>
struct Plane {
  Vec<T, 3> normal = Vec<T, 3>::UnitZ();
  T offset = T(0);

  static Plane from_point_normal(const Vec<T, 3>& p, const Vec<T, 3>& n) {
    const Vec<T, 3> unit = n.normalized();
    return {unit, unit.dot(p)};
  }
  /// Plane through a, b, c; counter-clockwise a, b, c seen from the positive side.
  static Plane from_points(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
    return from_point_normal(a, (b - a).cross(c - a));
  }

  /// Signed distance (the normal is unit length).
  T signed_distance(const Vec<T, 3>& p) const { return normal.dot(p) - offset; }
  Vec<T, 3> project(const Vec<T, 3>& p) const { return p - signed_distance(p) * normal; }
  Plane flipped() const { return {-normal, -offset}; }
};

using Plane3f = Plane<float>;
using Plane3d = Plane<double>;

}  // namespace geods
