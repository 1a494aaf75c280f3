#pragma once
// Oriented bounding box: center, three orthonormal axes (the columns of
// `axes`) and half extents along them, with the bounding volume operations of
// aabb_bv.hpp. The fit tries the principal axes of the points (PCA, as in
// Gottschalk's OBB-tree) and orientations from their convex hull, and keeps
// the smallest box.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/bvh/aabb_bv.hpp"

namespace geods::bvh {

template <typename T>
struct Obb {
  Vec<T, 3> center = Vec<T, 3>::Zero();
  Eigen::Matrix<T, 3, 3> axes = Eigen::Matrix<T, 3, 3>::Identity();
  Vec<T, 3> half = Vec<T, 3>::Constant(-T(1));  // negative: empty

  bool empty() const { return half[0] < T(0); }
  /// p in the box frame (coordinates along the axes, relative to the center).
  Vec<T, 3> to_local(const Vec<T, 3>& p) const { return axes.transpose() * (p - center); }
  std::array<Vec<T, 3>, 8> corners() const {
    std::array<Vec<T, 3>, 8> c;
    for (int i = 0; i < 8; ++i) {
      const Vec<T, 3> s((i & 1) ? half[0] : -half[0], (i & 2) ? half[1] : -half[1], (i & 4) ? half[2] : -half[2]);
      c[i] = center + axes * s;
    }
    return c;
  }
};

}  // namespace geods::bvh
template <typename T>
struct geods::is_bytewise<geods::bvh::Obb<T>> : geods::is_bytewise<geods::Vec<T, 3>> {};
namespace geods::bvh {

using Obb3f = Obb<float>;
using Obb3d = Obb<double>;

/// How fit_obb orients the box.
enum class ObbFit {
  /// The principal axes of the points (PCA of their covariance; Gottschalk's
  /// OBB-tree): O(n), but dense clusters of points tilt the box.
  pca,
  /// The smallest of several candidates: the principal axes, the principal
  /// axes of the convex hull's surface (Gottschalk's continuous formula), and
  /// for each of the 16 largest hull faces the face normal with the
  /// minimum-area rectangle of the hull's projection on that face (rotating
  /// calipers; O'Rourke's optimal box has a face flush with a hull face in
  /// most cases). Never larger than the pca box; O(n log n) for the hull.
  hull,
};

namespace detail {
/// Axes (columns, right-handed) of the box fit_obb builds. "Smallest" is the
/// least product of the extents, each grown by 1e-6 of the diameter so that
/// flat sets compare by area. Degenerate sets get PCA or the coordinate axes.
Eigen::Matrix3d obb_fit_axes(std::span<const Vec3d> points, ObbFit fit);
}  // namespace detail

/// Box around the points, oriented as `fit` says. Grown by a relative 1e-6
/// so that rounding never leaves a point outside.
template <typename T>
Obb<T> fit_obb(std::span<const Vec<T, 3>> points, ObbFit fit = ObbFit::pca) {
  Obb<T> box;
  if (points.empty()) return box;
  std::vector<Vec3d> converted;
  std::span<const Vec3d> pd;
  if constexpr (std::is_same_v<T, double>) {
    pd = points;
  } else {
    converted.reserve(points.size());
    for (const auto& p : points) converted.push_back(p.template cast<double>());
    pd = converted;
  }
  const Eigen::Matrix3d axes = detail::obb_fit_axes(pd, fit);
  Vec3d mean = Vec3d::Zero();
  for (const Vec3d& p : pd) mean += p;
  mean /= double(pd.size());
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3d& p : pd) {
    const Vec3d s = axes.transpose() * (p - mean);
    lo = lo.cwiseMin(s);
    hi = hi.cwiseMax(s);
  }
  const Vec3d mid = (lo + hi) / 2;
  const double scale = std::max(1.0, (hi - lo).cwiseAbs().maxCoeff() + mean.cwiseAbs().maxCoeff());
  const Vec3d half = (hi - lo) / 2 + Vec3d::Constant(scale * 1e-6);
  box.center = (mean + axes * mid).template cast<T>();
  box.axes = axes.template cast<T>();
  box.half = half.template cast<T>();
  return box;
}

/// Separating-axis test over the 15 candidate axes (Gottschalk).
template <typename T>
bool overlaps(const Obb<T>& a, const Obb<T>& b) {
  if (a.empty() || b.empty()) return false;
  const Eigen::Matrix<T, 3, 3> r = a.axes.transpose() * b.axes;
  Eigen::Matrix<T, 3, 3> abs_r = r.cwiseAbs();
  abs_r.array() += T(1e-6);  // near-parallel edges give a zero cross product
  const Vec<T, 3> t = a.axes.transpose() * (b.center - a.center);
  for (int i = 0; i < 3; ++i)
    if (std::abs(t[i]) > a.half[i] + b.half.dot(abs_r.row(i).transpose())) return false;
  for (int j = 0; j < 3; ++j)
    if (std::abs(t.dot(r.col(j))) > a.half.dot(abs_r.col(j)) + b.half[j]) return false;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const T ra = a.half[i1] * abs_r(i2, j) + a.half[i2] * abs_r(i1, j);
      const T rb = b.half[j1] * abs_r(i, j2) + b.half[j2] * abs_r(i, j1);
      if (std::abs(t[i2] * r(i1, j) - t[i1] * r(i2, j)) > ra + rb) return false;
    }
  }
  return true;
}
template <typename T>
bool contains(const Obb<T>& a, const Vec<T, 3>& p) {
  if (a.empty()) return false;
  return (a.to_local(p).cwiseAbs().array() <= a.half.array()).all();
}
template <typename T>
bool contains(const Obb<T>& a, const Obb<T>& b) {
  if (b.empty()) return true;
  for (const auto& c : b.corners())
    if (!contains(a, c)) return false;
  return true;
}
/// A box around both, fitted (principal axes) to their 16 corners (contains both).
template <typename T>
Obb<T> merge(const Obb<T>& a, const Obb<T>& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  std::array<Vec<T, 3>, 16> pts;
  const auto ca = a.corners(), cb = b.corners();
  std::copy(ca.begin(), ca.end(), pts.begin());
  std::copy(cb.begin(), cb.end(), pts.begin() + 8);
  return fit_obb<T>(pts);
}
template <typename T>
T volume(const Obb<T>& a) {
  return a.empty() ? T(0) : T(8) * a.half.prod();
}
template <typename T>
T surface_area(const Obb<T>& a) {
  if (a.empty()) return T(0);
  const Vec<T, 3> e = T(2) * a.half;
  return T(2) * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
}
template <typename T>
std::pair<T, T> ray_interval(const Obb<T>& a, const Ray<T>& ray, const Vec<T, 3>& /*inv_dir*/) {
  if (a.empty()) return {T(1), T(0)};
  Ray<T> local = ray;
  local.origin = a.to_local(ray.origin);
  local.direction = a.axes.transpose() * ray.direction;
  Vec<T, 3> inv = local.direction.cwiseInverse();
  const Vec<T, 3> pad = a.half.cwiseAbs() * T(1e-5) + Vec<T, 3>::Constant(std::numeric_limits<T>::min());
  return ray_box_interval(local, inv, AABB<T, 3>(-a.half - pad, a.half + pad));
}
template <typename T>
T squared_distance(const Obb<T>& a, const Vec<T, 3>& p) {
  if (a.empty()) return std::numeric_limits<T>::infinity();
  const Vec<T, 3> d = (a.to_local(p).cwiseAbs() - a.half).cwiseMax(Vec<T, 3>::Zero());
  return d.squaredNorm();
}
template <typename T>
AABB<T, 3> bounds(const Obb<T>& a) {
  if (a.empty()) return {};
  const Vec<T, 3> e = a.axes.cwiseAbs() * a.half;
  return {a.center - e, a.center + e};
}
template <typename T>
bool above(const Obb<T>& a, const Plane<T>& plane) {
  if (a.empty()) return true;
  const T radius = (a.axes.transpose() * plane.normal).cwiseAbs().dot(a.half);
  return plane.signed_distance(a.center) > radius;
}

}  // namespace geods::bvh
