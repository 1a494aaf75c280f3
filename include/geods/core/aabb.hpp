#pragma once
// Axis-aligned bounding box in 2D or 3D, float or double.
#include <algorithm>
#include <limits>

#include "geods/core/vec.hpp"

namespace geods {

template <typename T, int N>
struct AABB {
  using VecT = Vec<T, N>;

  // An empty box has lo > hi so that extending it by a point gives that point.
  VecT lo = VecT::Constant(std::numeric_limits<T>::infinity());
  VecT hi = VecT::Constant(-std::numeric_limits<T>::infinity());

  AABB() = default;
  AABB(const VecT& lo_, const VecT& hi_) : lo(lo_), hi(hi_) {}

  static AABB of_point(const VecT& p) { return {p, p}; }

  bool empty() const { return (lo.array() > hi.array()).any(); }

  AABB& extend(const VecT& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    return *this;
  }
  AABB& extend(const AABB& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
    return *this;
  }

  /// Closed containment: points on the boundary are inside.
  bool contains(const VecT& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
  bool contains(const AABB& b) const {
    return (b.lo.array() >= lo.array()).all() && (b.hi.array() <= hi.array()).all();
  }
  /// Closed overlap: boxes that touch overlap.
  bool overlaps(const AABB& b) const {
    return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
  }
  AABB intersection(const AABB& b) const { return {lo.cwiseMax(b.lo), hi.cwiseMin(b.hi)}; }

  VecT center() const { return (lo + hi) / T(2); }
  VecT extent() const { return empty() ? VecT::Zero() : VecT(hi - lo); }
  int longest_axis() const {
    int axis = 0;
    extent().maxCoeff(&axis);
    return axis;
  }
  /// Area in 2D, volume in 3D; 0 for an empty box.
  T volume() const { return extent().prod(); }
  /// Perimeter in 2D, surface area in 3D; 0 for an empty box.
  T surface_area() const {
    const VecT e = extent();
    if constexpr (N == 2) {
      return T(2) * (e[0] + e[1]);
    } else {
      return T(2) * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
    }
  }
  /// Squared distance from p to the box (0 inside).
  T squared_distance(const VecT& p) const {
    const VecT d = (lo - p).cwiseMax(p - hi).cwiseMax(VecT::Zero());
    return d.squaredNorm();
  }

  bool operator==(const AABB& b) const { return lo == b.lo && hi == b.hi; }
};
template <typename T, int N>
struct is_bytewise<AABB<T, N>> : is_bytewise<Vec<T, N>> {};

using AABB2f = AABB<float, 2>;
using AABB3f = AABB<float, 3>;
using AABB2d = AABB<double, 2>;
using AABB3d = AABB<double, 3>;

/// Bounds of a range of points.
template <typename T, int N, typename Range>
AABB<T, N> bounds_of(const Range& points) {
  AABB<T, N> box;
  for (const auto& p : points) box.extend(p);
  return box;
}

}  // namespace geods
