#pragma once
// Rectangle swept sphere (RSS, Larsen, Gottschalk, Lin and Manocha 1999): the
// points within `radius` of a rectangle (centre, two in-plane axes, half
// lengths), with the bounding volume operations of aabb_bv.hpp. Fitted like
// the OBB (obb.hpp): the principal axes of the points, the rectangle in the
// plane of the two largest, the radius from the extent along the third. Its
// distance to another RSS is the rectangles' distance less both radii, exact
// (rectangle_distance), which makes it a tight volume for distance queries.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/bvh/aabb_bv.hpp"
#include "geods/bvh/obb.hpp"
#include "geods/core/triangle.hpp"

namespace geods::bvh {

template <typename T>
struct Rss {
  Vec<T, 3> center = Vec<T, 3>::Zero();  // of the rectangle
  /// Columns: the rectangle's two axes, then its normal.
  Eigen::Matrix<T, 3, 3> axes = Eigen::Matrix<T, 3, 3>::Identity();
  Vec<T, 2> half = Vec<T, 2>::Zero();  // half lengths of the rectangle along axes 0 and 1
  T radius = -T(1);                    // negative: empty

  bool empty() const { return radius < T(0); }
  /// p in the rectangle's frame (coordinates along the axes, relative to the centre).
  Vec<T, 3> to_local(const Vec<T, 3>& p) const { return axes.transpose() * (p - center); }
  /// Distance from p to the rectangle (not to the volume).
  T rectangle_distance_to(const Vec<T, 3>& p) const {
    const Vec<T, 3> q = to_local(p);
    const T dx = std::max(std::abs(q[0]) - half[0], T(0)), dy = std::max(std::abs(q[1]) - half[1], T(0));
    return std::sqrt(dx * dx + dy * dy + q[2] * q[2]);
  }
  /// The rectangle's corners, in order around it.
  std::array<Vec<T, 3>, 4> corners() const {
    const Vec<T, 3> u = axes.col(0) * half[0], v = axes.col(1) * half[1];
    return {center - u - v, center + u - v, center + u + v, center - u + v};
  }
  /// The box around the volume: the rectangle grown by the radius, in its frame.
  Obb<T> box() const {
    Obb<T> b;
    if (empty()) return b;
    b.center = center;
    b.axes = axes;
    b.half = Vec<T, 3>(half[0] + radius, half[1] + radius, radius);
    return b;
  }
};

}  // namespace geods::bvh
template <typename T>
struct geods::is_bytewise<geods::bvh::Rss<T>> : geods::is_bytewise<geods::Vec<T, 3>> {};
namespace geods::bvh {

using Rss3f = Rss<float>;
using Rss3d = Rss<double>;

namespace detail {
// Squared distance between the segments p + s d (s in [0, 1]) and q + t e (t in [0, 1]).
template <typename T>
T segment_distance2(const Vec<T, 3>& p, const Vec<T, 3>& d, const Vec<T, 3>& q, const Vec<T, 3>& e) {
  const auto [s, t] = segment_segment_closest(p, d, q, e);
  return (p - q + s * d - t * e).squaredNorm();
}

// Whether an edge of the closed polygon p (4 corners, in the frame of the
// rectangle |x| <= h0, |y| <= h1, z = 0) crosses that rectangle's plane
// inside it. Edges lying in the plane are left to the feature distances.
template <typename T>
bool edge_crosses_rectangle(const std::array<Vec<T, 3>, 4>& p, T h0, T h1) {
  for (int k = 0; k < 4; ++k) {
    const Vec<T, 3>& s = p[k];
    const Vec<T, 3>& e = p[(k + 1) & 3];
    if ((s[2] > T(0) && e[2] > T(0)) || (s[2] < T(0) && e[2] < T(0)) || s[2] == e[2]) continue;
    const T w = s[2] / (s[2] - e[2]);
    const T x = s[0] + w * (e[0] - s[0]), y = s[1] + w * (e[1] - s[1]);
    if (std::abs(x) <= h0 && std::abs(y) <= h1) return true;
  }
  return false;
}
}  // namespace detail

/// Distance between the rectangles A = {(x, y, 0) : |x| <= a0, |y| <= a1} and
/// B = {c + u r0 + v r1 : |u| <= b0, |v| <= b1}, where r0, r1 are the first
/// two columns of the rotation r (B's axes in A's frame). Larsen et al.'s
/// rectangle distance, written out over the features: 0 if an edge of one
/// crosses the other (the rectangles meet), else the least of the 16
/// edge-edge distances and of the corners whose projection falls inside the
/// other rectangle (the closest points of two disjoint convex polygons are
/// on two edges, or a corner and its projection on the other's face).
template <typename T>
T rectangle_distance(const Eigen::Matrix<T, 3, 3>& r, const Vec<T, 3>& c, T a0, T a1, T b0, T b1) {
  using V = Vec<T, 3>;
  const V u = r.col(0) * b0, v = r.col(1) * b1;
  const std::array<V, 4> pb = {c - u - v, c + u - v, c + u + v, c - u + v};  // B's corners in A's frame
  // A's corners in B's frame: x_b = r^T (x_a - c).
  const V ca = -(r.transpose() * c);
  const V ua = r.row(0).transpose() * a0, va = r.row(1).transpose() * a1;
  const std::array<V, 4> pa = {ca - ua - va, ca + ua - va, ca + ua + va, ca - ua + va};
  if (detail::edge_crosses_rectangle(pb, a0, a1) || detail::edge_crosses_rectangle(pa, b0, b1)) return T(0);
  T best = std::numeric_limits<T>::infinity();
  for (int k = 0; k < 4; ++k) {
    if (std::abs(pb[k][0]) <= a0 && std::abs(pb[k][1]) <= a1) best = std::min(best, pb[k][2] * pb[k][2]);
    if (std::abs(pa[k][0]) <= b0 && std::abs(pa[k][1]) <= b1) best = std::min(best, pa[k][2] * pa[k][2]);
  }
  const std::array<V, 4> qa = {V(-a0, -a1, 0), V(a0, -a1, 0), V(a0, a1, 0), V(-a0, a1, 0)};
  for (int i = 0; i < 4; ++i) {
    const V di = qa[(i + 1) & 3] - qa[i];
    for (int j = 0; j < 4; ++j) best = std::min(best, detail::segment_distance2(qa[i], di, pb[j], V(pb[(j + 1) & 3] - pb[j])));
  }
  return std::sqrt(best);
}

/// The rectangle distance of two RSS (each in its own frame).
template <typename T>
T rectangle_distance(const Rss<T>& a, const Rss<T>& b) {
  const Eigen::Matrix<T, 3, 3> r = a.axes.transpose() * b.axes;
  const Vec<T, 3> c = a.to_local(b.center);
  return rectangle_distance<T>(r, c, a.half[0], a.half[1], b.half[0], b.half[1]);
}

/// RSS around the points (empty for none): the principal axes of the points
/// (as fit_obb with ObbFit::pca), the radius half the extent along the
/// smallest, the rectangle as small as the rounded ends allow (PQP's fit: each
/// side moved in by what the sphere's cap covers, then grown where a point
/// still falls outside). Grown by a relative 1e-6 so that rounding never
/// leaves a point outside.
template <typename T>
Rss<T> fit_rss(std::span<const Vec<T, 3>> points) {
  Rss<T> s;
  if (points.empty()) return s;
  std::vector<Vec3d> pd(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) pd[i] = points[i].template cast<double>();
  const Eigen::Matrix3d axes = detail::obb_fit_axes(pd, ObbFit::pca);
  Vec3d mean = Vec3d::Zero();
  for (const Vec3d& p : pd) mean += p;
  mean /= double(pd.size());
  std::vector<Vec3d> q(pd.size());
  double zlo = std::numeric_limits<double>::infinity(), zhi = -zlo;
  Vec3d lo = Vec3d::Constant(zlo), hi = -lo;
  for (std::size_t i = 0; i < pd.size(); ++i) {
    q[i] = axes.transpose() * (pd[i] - mean);
    lo = lo.cwiseMin(q[i]);
    hi = hi.cwiseMax(q[i]);
  }
  zlo = lo[2], zhi = hi[2];
  const double radius = (zhi - zlo) / 2, cz = (zlo + zhi) / 2;
  double rlo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double rhi[2] = {-rlo[0], -rlo[0]};
  for (const Vec3d& p : q) {
    const double dz = p[2] - cz;
    const double cap = std::sqrt(std::max(0.0, radius * radius - dz * dz));
    for (int k = 0; k < 2; ++k) {
      rlo[k] = std::min(rlo[k], p[k] + cap);
      rhi[k] = std::max(rhi[k], p[k] - cap);
    }
  }
  for (int k = 0; k < 2; ++k)
    if (rlo[k] > rhi[k]) rlo[k] = rhi[k] = (rlo[k] + rhi[k]) / 2;
  for (const Vec3d& p : q) {
    const double dz = p[2] - cz;
    auto outside = [&] {
      const double dx = std::max({rlo[0] - p[0], p[0] - rhi[0], 0.0});
      const double dy = std::max({rlo[1] - p[1], p[1] - rhi[1], 0.0});
      return dx * dx + dy * dy + dz * dz > radius * radius;
    };
    for (int k = 0; k < 2 && outside(); ++k) rlo[k] = std::min(rlo[k], p[k]), rhi[k] = std::max(rhi[k], p[k]);
  }
  const double scale = std::max(1.0, (hi - lo).cwiseAbs().maxCoeff() + mean.cwiseAbs().maxCoeff());
  const Vec3d mid((rlo[0] + rhi[0]) / 2, (rlo[1] + rhi[1]) / 2, cz);
  s.center = (mean + axes * mid).template cast<T>();
  s.axes = axes.template cast<T>();
  s.half = Vec<T, 2>(T((rhi[0] - rlo[0]) / 2), T((rhi[1] - rlo[1]) / 2));
  s.radius = T(radius + scale * 1e-6);
  return s;
}

template <typename T>
bool overlaps(const Rss<T>& a, const Rss<T>& b) {
  if (a.empty() || b.empty()) return false;
  return rectangle_distance(a, b) <= a.radius + b.radius;
}
template <typename T>
bool contains(const Rss<T>& a, const Vec<T, 3>& p) {
  return !a.empty() && a.rectangle_distance_to(p) <= a.radius;
}
/// b's rectangle within a.radius - b.radius of a's (at its corners, hence everywhere: convexity).
template <typename T>
bool contains(const Rss<T>& a, const Rss<T>& b) {
  if (b.empty()) return true;
  if (a.empty()) return false;
  for (const auto& c : b.corners())
    if (a.rectangle_distance_to(c) + b.radius > a.radius) return false;
  return true;
}
/// An RSS fitted to the corners of both volumes' boxes (contains both).
template <typename T>
Rss<T> merge(const Rss<T>& a, const Rss<T>& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  std::array<Vec<T, 3>, 16> pts;
  const auto ca = a.box().corners(), cb = b.box().corners();
  std::copy(ca.begin(), ca.end(), pts.begin());
  std::copy(cb.begin(), cb.end(), pts.begin() + 8);
  return fit_rss<T>(pts);
}
/// Steiner's formula for the rectangle (sides x, y) grown by r:
/// 2 x y r + pi (x + y) r^2 + 4/3 pi r^3.
template <typename T>
T volume(const Rss<T>& a) {
  if (a.empty()) return T(0);
  const T x = T(2) * a.half[0], y = T(2) * a.half[1], r = a.radius, pi = std::numbers::pi_v<T>;
  return T(2) * x * y * r + pi * (x + y) * r * r + T(4) / T(3) * pi * r * r * r;
}
/// Its derivative in r: 2 x y + 2 pi (x + y) r + 4 pi r^2.
template <typename T>
T surface_area(const Rss<T>& a) {
  if (a.empty()) return T(0);
  const T x = T(2) * a.half[0], y = T(2) * a.half[1], r = a.radius, pi = std::numbers::pi_v<T>;
  return T(2) * x * y + T(2) * pi * (x + y) * r + T(4) * pi * r * r;
}
/// The interval of the box around the volume (conservative: it may start earlier).
template <typename T>
std::pair<T, T> ray_interval(const Rss<T>& a, const Ray<T>& ray, const Vec<T, 3>& inv_dir) {
  return ray_interval(a.box(), ray, inv_dir);
}
template <typename T>
T squared_distance(const Rss<T>& a, const Vec<T, 3>& p) {
  if (a.empty()) return std::numeric_limits<T>::infinity();
  const T d = std::max(T(0), a.rectangle_distance_to(p) - a.radius);
  return d * d;
}
template <typename T>
AABB<T, 3> bounds(const Rss<T>& a) {
  if (a.empty()) return {};
  const Vec<T, 3> e = a.axes.col(0).cwiseAbs() * a.half[0] + a.axes.col(1).cwiseAbs() * a.half[1] +
                      Vec<T, 3>::Constant(a.radius);
  return {a.center - e, a.center + e};
}
template <typename T>
bool above(const Rss<T>& a, const Plane<T>& plane) {
  if (a.empty()) return true;
  const T reach = std::abs(plane.normal.dot(a.axes.col(0))) * a.half[0] +
                  std::abs(plane.normal.dot(a.axes.col(1))) * a.half[1] + a.radius * plane.normal.norm();
  return plane.signed_distance(a.center) > reach;
}

}  // namespace geods::bvh
