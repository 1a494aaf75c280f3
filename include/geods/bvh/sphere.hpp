#pragma once
// Bounding sphere: center and radius, with the bounding volume operations of
// aabb_bv.hpp. The fit is Ritter's (two sweeps from extreme points, then
// growing), which is within a few percent of the minimal sphere in practice.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <utility>

#include "geods/core/aabb.hpp"
#include "geods/core/plane.hpp"
#include "geods/core/ray.hpp"

namespace geods::bvh {

template <typename T>
struct Sphere {
  Vec<T, 3> center = Vec<T, 3>::Zero();
  T radius = -T(1);  // negative: empty

  bool empty() const { return radius < T(0); }
};

}  // namespace geods::bvh
template <typename T>
struct geods::is_bytewise<geods::bvh::Sphere<T>> : geods::is_bytewise<geods::Vec<T, 3>> {};
namespace geods::bvh {

using Sphere3f = Sphere<float>;
using Sphere3d = Sphere<double>;

/// Ritter's sphere around the points, grown by a relative 1e-6 so that
/// rounding never leaves a point outside (empty sphere for none).
template <typename T>
Sphere<T> fit_sphere(std::span<const Vec<T, 3>> points) {
  Sphere<T> s;
  if (points.empty()) return s;
  auto farthest = [&](const Vec<T, 3>& from) {
    std::size_t best = 0;
    T best_d = T(-1);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const T d = (points[i] - from).squaredNorm();
      if (d > best_d) best_d = d, best = i;
    }
    return points[best];
  };
  const Vec<T, 3> a = farthest(points[0]);
  const Vec<T, 3> b = farthest(a);
  s.center = (a + b) / T(2);
  s.radius = (b - a).norm() / T(2);
  for (const auto& p : points) {
    const T d = (p - s.center).norm();
    if (d > s.radius) {
      const T grown = (s.radius + d) / T(2);
      s.center += ((grown - s.radius) / d) * (p - s.center);
      s.radius = grown;
    }
  }
  T max_d = 0;
  for (const auto& p : points) max_d = std::max(max_d, (p - s.center).norm());
  s.radius = max_d * (T(1) + T(1e-6)) + std::numeric_limits<T>::min();
  return s;
}

template <typename T>
bool overlaps(const Sphere<T>& a, const Sphere<T>& b) {
  if (a.empty() || b.empty()) return false;
  const T r = a.radius + b.radius;
  return (a.center - b.center).squaredNorm() <= r * r;
}
template <typename T>
bool contains(const Sphere<T>& a, const Vec<T, 3>& p) {
  return !a.empty() && (p - a.center).squaredNorm() <= a.radius * a.radius;
}
template <typename T>
bool contains(const Sphere<T>& a, const Sphere<T>& b) {
  if (b.empty()) return true;
  return !a.empty() && (a.center - b.center).norm() + b.radius <= a.radius;
}
/// The smallest sphere containing both.
template <typename T>
Sphere<T> merge(const Sphere<T>& a, const Sphere<T>& b) {
  if (a.empty() || contains(b, a)) return b;
  if (b.empty() || contains(a, b)) return a;
  const T d = (b.center - a.center).norm();
  const T r = (d + a.radius + b.radius) / T(2);
  Sphere<T> m;
  m.center = a.center + ((r - a.radius) / d) * (b.center - a.center);
  m.radius = r * (T(1) + T(1e-6));
  return m;
}
template <typename T>
T volume(const Sphere<T>& a) {
  return a.empty() ? T(0) : T(4) / T(3) * std::numbers::pi_v<T> * a.radius * a.radius * a.radius;
}
template <typename T>
T surface_area(const Sphere<T>& a) {
  return a.empty() ? T(0) : T(4) * std::numbers::pi_v<T> * a.radius * a.radius;
}
template <typename T>
std::pair<T, T> ray_interval(const Sphere<T>& a, const Ray<T>& ray, const Vec<T, 3>& /*inv_dir*/) {
  const T miss = std::numeric_limits<T>::infinity();
  if (a.empty()) return {miss, -miss};
  // Solve |o + t d - c|^2 = r^2 with the closest approach point for accuracy.
  const Vec<T, 3> oc = ray.origin - a.center;
  const T dd = ray.direction.squaredNorm();
  if (dd == T(0)) return oc.squaredNorm() <= a.radius * a.radius ? std::pair<T, T>{ray.tmin, ray.tmax}
                                                                   : std::pair<T, T>{miss, -miss};
  const T tc = -oc.dot(ray.direction) / dd;
  const T dist2 = (oc + tc * ray.direction).squaredNorm();
  const T h2 = a.radius * a.radius - dist2;
  if (h2 < T(0)) return {miss, -miss};
  // Pad by a relative epsilon: this is a culling test and must not miss a hit.
  const T h = std::sqrt(h2 / dd) * (T(1) + T(1e-5)) + std::abs(tc) * T(1e-6);
  return {std::max(ray.tmin, tc - h), std::min(ray.tmax, tc + h)};
}
template <typename T>
T squared_distance(const Sphere<T>& a, const Vec<T, 3>& p) {
  if (a.empty()) return std::numeric_limits<T>::infinity();
  const T d = std::max(T(0), (p - a.center).norm() - a.radius);
  return d * d;
}
template <typename T>
AABB<T, 3> bounds(const Sphere<T>& a) {
  if (a.empty()) return {};
  const Vec<T, 3> r = Vec<T, 3>::Constant(a.radius);
  return {a.center - r, a.center + r};
}
template <typename T>
bool above(const Sphere<T>& a, const Plane<T>& plane) {
  return a.empty() || plane.signed_distance(a.center) > a.radius * plane.normal.norm();
}

}  // namespace geods::bvh
