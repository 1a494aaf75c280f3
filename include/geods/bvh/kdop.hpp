#pragma once
// Discrete oriented polytope (k-DOP): the intersection of k/2 slabs along
// fixed directions, k = 6 (the box), 14 (box + 4 corner diagonals), 18 (box +
// 6 edge diagonals) or 26 (all 13). The slab bounds are projections onto the
// unnormalized directions, so fitting is a min/max of dot products. Volume and
// surface area come from clipping the box by the diagonal slabs (kdop.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "geods/bvh/aabb_bv.hpp"
#include "geods/core/plane.hpp"
#include "geods/core/ray.hpp"

namespace geods::bvh {

/// The 13 directions of the 26-DOP; a k-DOP uses the first 3 (k = 6), the
/// first 7 (k = 14), the first 3 and the last 6 (k = 18), or all (k = 26).
inline constexpr std::array<std::array<int, 3>, 13> kdop_all_directions = {{
    {1, 0, 0}, {0, 1, 0}, {0, 0, 1},                                          // faces
    {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1},                            // corners
    {1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1}, {0, 1, 1}, {0, 1, -1}}};  // edges

template <int K>
constexpr std::array<int, K / 2> kdop_direction_indices() {
  static_assert(K == 6 || K == 14 || K == 18 || K == 26, "k-DOPs have k = 6, 14, 18 or 26");
  std::array<int, K / 2> idx{};
  if constexpr (K == 18) {
    for (int i = 0; i < 3; ++i) idx[i] = i;
    for (int i = 0; i < 6; ++i) idx[3 + i] = 7 + i;
  } else {
    for (int i = 0; i < K / 2; ++i) idx[i] = i;
  }
  return idx;
}

template <int K>
Vec3d kdop_direction(int axis) {
  const auto& d = kdop_all_directions[kdop_direction_indices<K>()[axis]];
  return {double(d[0]), double(d[1]), double(d[2])};
}

/// Volume and surface area of the polytope {x : lo[i] <= n_i·x <= hi[i]} for
/// the given directions (the first three must be the coordinate axes).
std::pair<double, double> slab_polytope_measures(std::span<const Vec3d> directions,
                                                 std::span<const double> lo, std::span<const double> hi);

template <typename T, int K>
struct Kdop {
  static constexpr int num_axes = K / 2;
  std::array<T, K / 2> lo;
  std::array<T, K / 2> hi;

  Kdop() {
    lo.fill(std::numeric_limits<T>::infinity());
    hi.fill(-std::numeric_limits<T>::infinity());
  }
  bool empty() const { return lo[0] > hi[0]; }

  /// Projection of p onto direction `axis` (unnormalized).
  static T project(const Vec<T, 3>& p, int axis) {
    const auto& d = kdop_all_directions[kdop_direction_indices<K>()[axis]];
    return T(d[0]) * p[0] + T(d[1]) * p[1] + T(d[2]) * p[2];
  }
  /// Adds p. Projections are computed in double and rounded outwards, so
  /// the k-DOP holds p exactly (no rounding can put a vertex outside).
  Kdop& extend(const Vec<T, 3>& p) {
    for (int i = 0; i < num_axes; ++i) {
      const auto& d = kdop_all_directions[kdop_direction_indices<K>()[i]];
      const double s = d[0] * double(p[0]) + d[1] * double(p[1]) + d[2] * double(p[2]);
      T down = T(s), up = T(s);
      if (double(down) > s) down = std::nextafter(down, -std::numeric_limits<T>::infinity());
      if (double(up) < s) up = std::nextafter(up, std::numeric_limits<T>::infinity());
      lo[i] = std::min(lo[i], down);
      hi[i] = std::max(hi[i], up);
    }
    return *this;
  }
};

template <typename T>
using Kdop6 = Kdop<T, 6>;
template <typename T>
using Kdop14 = Kdop<T, 14>;
template <typename T>
using Kdop18 = Kdop<T, 18>;
template <typename T>
using Kdop26 = Kdop<T, 26>;

template <typename T, int K>
Kdop<T, K> fit_kdop(std::span<const Vec<T, 3>> points) {
  Kdop<T, K> k;
  for (const auto& p : points) k.extend(p);
  return k;
}

/// Slab-wise overlap: exact for k = 6, conservative otherwise (two k-DOPs can
/// overlap on every slab and still be disjoint), as in every k-DOP tree.
template <typename T, int K>
bool overlaps(const Kdop<T, K>& a, const Kdop<T, K>& b) {
  for (int i = 0; i < K / 2; ++i)
    if (a.lo[i] > b.hi[i] || b.lo[i] > a.hi[i]) return false;
  return true;
}
template <typename T, int K>
bool contains(const Kdop<T, K>& a, const Vec<T, 3>& p) {
  for (int i = 0; i < K / 2; ++i) {
    const auto& d = kdop_all_directions[kdop_direction_indices<K>()[i]];
    const double s = d[0] * double(p[0]) + d[1] * double(p[1]) + d[2] * double(p[2]);
    if (s < double(a.lo[i]) || s > double(a.hi[i])) return false;
  }
  return true;
}
/// Slab-wise containment (sufficient; exact for k-DOPs fitted to geometry).
template <typename T, int K>
bool contains(const Kdop<T, K>& a, const Kdop<T, K>& b) {
  if (b.empty()) return true;
  for (int i = 0; i < K / 2; ++i)
    if (b.lo[i] < a.lo[i] || b.hi[i] > a.hi[i]) return false;
  return true;
}
template <typename T, int K>
Kdop<T, K> merge(const Kdop<T, K>& a, const Kdop<T, K>& b) {
  Kdop<T, K> m;
  for (int i = 0; i < K / 2; ++i) {
    m.lo[i] = std::min(a.lo[i], b.lo[i]);
    m.hi[i] = std::max(a.hi[i], b.hi[i]);
  }
  return m;
}
template <typename T, int K>
std::pair<double, double> kdop_measures(const Kdop<T, K>& a) {
  if (a.empty()) return {0.0, 0.0};
  std::array<Vec3d, K / 2> dirs;
  std::array<double, K / 2> lo, hi;
  for (int i = 0; i < K / 2; ++i) {
    dirs[i] = kdop_direction<K>(i);
    lo[i] = double(a.lo[i]);
    hi[i] = double(a.hi[i]);
  }
  return slab_polytope_measures(dirs, lo, hi);
}
template <typename T, int K>
T volume(const Kdop<T, K>& a) {
  return T(kdop_measures(a).first);
}
template <typename T, int K>
T surface_area(const Kdop<T, K>& a) {
  return T(kdop_measures(a).second);
}
template <typename T, int K>
std::pair<T, T> ray_interval(const Kdop<T, K>& a, const Ray<T>& ray, const Vec<T, 3>& /*inv_dir*/) {
  // In double: the slabs of the diagonal directions mix coordinates, and a
  // culling test must never lose a hit of the exact triangle test.
  double t0 = ray.tmin, t1 = ray.tmax;
  const Vec3d o = ray.origin.template cast<double>(), dir = ray.direction.template cast<double>();
  for (int i = 0; i < K / 2; ++i) {
    const Vec3d n = kdop_direction<K>(i);
    const double po = n.dot(o), d = n.dot(dir);
    const double pad = 1e-9 * (std::abs(double(a.lo[i])) + std::abs(double(a.hi[i])) + std::abs(po));
    const double lo = double(a.lo[i]) - pad, hi = double(a.hi[i]) + pad;
    if (d == 0) {
      if (po < lo || po > hi) return {T(1), T(0)};
      continue;
    }
    double near = (lo - po) / d, far = (hi - po) / d;
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
  }
  // The slack of the AABB traversal: a triangle whose float t rounded below
  // t1 may lie in a box whose exact interval starts a few ulps above it.
  if (t0 > widen_far(t1)) return {T(1), T(0)};
  // Round outwards to T.
  T near = T(t0), far = T(t1);
  if (double(near) > t0) near = std::nextafter(near, -std::numeric_limits<T>::infinity());
  if (double(far) < t1) far = std::nextafter(far, std::numeric_limits<T>::infinity());
  return {near, far};
}
/// A lower bound of the squared distance from p to the k-DOP: the largest
/// distance to a slab.
template <typename T, int K>
T squared_distance(const Kdop<T, K>& a, const Vec<T, 3>& p) {
  if (a.empty()) return std::numeric_limits<T>::infinity();
  T best = 0;
  for (int i = 0; i < K / 2; ++i) {
    const T s = Kdop<T, K>::project(p, i);
    const T gap = std::max({a.lo[i] - s, s - a.hi[i], T(0)});
    const T len2 = T(kdop_direction<K>(i).squaredNorm());
    best = std::max(best, gap * gap / len2);
  }
  return best;
}
template <typename T, int K>
AABB<T, 3> bounds(const Kdop<T, K>& a) {
  if (a.empty()) return {};
  return {{a.lo[0], a.lo[1], a.lo[2]}, {a.hi[0], a.hi[1], a.hi[2]}};
}
/// Conservative: tests the k-DOP's bounding box.
template <typename T, int K>
bool above(const Kdop<T, K>& a, const Plane<T>& plane) {
  return above(bounds(a), plane);
}

}  // namespace geods::bvh
