#pragma once
// A ray o + t d restricted to the parameter interval [tmin, tmax].
#include <limits>
#include <utility>

#include "geods/core/aabb.hpp"

namespace geods {

template <typename T>
struct Ray {
  Vec<T, 3> origin = Vec<T, 3>::Zero();
  Vec<T, 3> direction = Vec<T, 3>::UnitZ();
  T tmin = T(0);
  T tmax = std::numeric_limits<T>::infinity();

  Vec<T, 3> at(T t) const { return origin + t * direction; }
};

using Ray3f = Ray<float>;
using Ray3d = Ray<double>;

/// Slab test. Returns the parameter interval where the ray is inside the box
/// (first > second when it misses). inv_dir = 1 / direction, with infinities for
/// zero components; NaNs from 0 * inf are filtered so axis-parallel rays on a
/// slab boundary count as inside.
template <typename T>
std::pair<T, T> ray_box_interval(const Ray<T>& ray, const Vec<T, 3>& inv_dir, const AABB<T, 3>& box) {
  T t0 = ray.tmin, t1 = ray.tmax;
  for (int a = 0; a < 3; ++a) {
    T near = (box.lo[a] - ray.origin[a]) * inv_dir[a];
    T far = (box.hi[a] - ray.origin[a]) * inv_dir[a];
    if (near > far) std::swap(near, far);
    // max/min written so that a NaN operand leaves the interval unchanged.
    t0 = near > t0 ? near : t0;
    t1 = far < t1 ? far : t1;
  }
  return {t0, t1};
}

}  // namespace geods
