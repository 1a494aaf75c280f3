#pragma once
// The point of a segment nearest to a point, in any dimension.
#include <algorithm>

#include "geods/core/vec.hpp"

namespace geods {

/// The point of segment [a, b] nearest to p (a if a == b).
template <typename T, int N>
Vec<T, N> closest_point_on_segment(const Vec<T, N>& p, const Vec<T, N>& a, const Vec<T, N>& b) {
  const Vec<T, N> ab = b - a;
  const T len2 = ab.squaredNorm();
  const T t = len2 > T(0) ? std::clamp(ab.dot(p - a) / len2, T(0), T(1)) : T(0);
  return a + t * ab;
}

}  // namespace geods
