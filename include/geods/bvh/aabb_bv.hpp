#pragma once
// The axis-aligned box as a bounding volume: core's AABB<T, 3> plus the
// operations every bounding volume of geods::bvh offers (see sphere.hpp,
// kdop.hpp, obb.hpp for the same set): fit, overlap, containment, merge,
// volume, surface area, ray interval, distance lower bound, plane side.
#include <span>
#include <utility>

#include "geods/core/aabb.hpp"
#include "geods/core/plane.hpp"
#include "geods/core/ray.hpp"

namespace geods::bvh {

/// Smallest box around the points (empty box for none).
template <typename T>
AABB<T, 3> fit_aabb(std::span<const Vec<T, 3>> points) {
  AABB<T, 3> box;
  for (const auto& p : points) box.extend(p);
  return box;
}

template <typename T>
bool overlaps(const AABB<T, 3>& a, const AABB<T, 3>& b) {
  return a.overlaps(b);
}
template <typename T>
bool contains(const AABB<T, 3>& a, const Vec<T, 3>& p) {
  return a.contains(p);
}
template <typename T>
bool contains(const AABB<T, 3>& a, const AABB<T, 3>& b) {
  return a.contains(b);
}
template <typename T>
AABB<T, 3> merge(const AABB<T, 3>& a, const AABB<T, 3>& b) {
  AABB<T, 3> m = a;
  return m.extend(b);
}
template <typename T>
T volume(const AABB<T, 3>& a) {
  return a.volume();
}
template <typename T>
T surface_area(const AABB<T, 3>& a) {
  return a.surface_area();
}
/// The relative slack of the ray–box tests that must never reject a box the
/// exact triangle test would hit (Ize 2013): a far distance t counts as
/// t + |t| kRayBoxSlack, or is computed with the inverse direction scaled by
/// 1 + kRayBoxSlack (which narrows a negative t: only for rays with tmin >= 0,
/// where a box behind the origin holds no hit). The rounding of
/// (bound - origin) x inverse needs less than 3.6e-7 (2 gamma_3).
inline constexpr float kRayBoxSlack = 4e-7f;
/// A far distance t widened by the slack, t + |t| kRayBoxSlack: for a float
/// or double, or lane by lane for a GCC vector of floats.
// (Always inlined: a wide vector then crosses no call, so no ABI concern.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
template <typename T>
[[gnu::always_inline]] inline T widen_far(T t) {
  return t + (t < T{} ? -t : t) * kRayBoxSlack;
}
#pragma GCC diagnostic pop

/// Parameter interval of the ray inside the box, clipped to [tmin, tmax];
/// first > second on a miss. inv_dir = 1 / direction (infinities allowed).
template <typename T>
std::pair<T, T> ray_interval(const AABB<T, 3>& a, const Ray<T>& ray, const Vec<T, 3>& inv_dir) {
  return ray_box_interval(ray, inv_dir, a);
}
/// Squared distance from p to the box: a lower bound of the squared distance
/// from p to anything inside it.
template <typename T>
T squared_distance(const AABB<T, 3>& a, const Vec<T, 3>& p) {
  return a.squared_distance(p);
}
/// The bounding box (the box itself).
template <typename T>
AABB<T, 3> bounds(const AABB<T, 3>& a) {
  return a;
}
/// True when the whole box lies strictly on the positive side of the plane.
template <typename T>
bool above(const AABB<T, 3>& a, const Plane<T>& plane) {
  if (a.empty()) return true;
  const Vec<T, 3> c = a.center(), e = a.extent() / T(2);
  return plane.signed_distance(c) - plane.normal.cwiseAbs().dot(e) > T(0);
}

}  // namespace geods::bvh
