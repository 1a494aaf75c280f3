#pragma once
// Small helpers on a single triangle (a, b, c).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "geods/core/aabb.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/segment.hpp"

namespace geods {

/// Unnormalized normal (b - a) x (c - a); its length is twice the area.
template <typename T>
Vec<T, 3> triangle_normal(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
  return (b - a).cross(c - a);
}

/// Whether the corners are collinear (a repeated corner included), decided
/// exactly: the normal's three components are the orientations of the
/// triangle's projections onto the coordinate planes. For float and double
/// corners (floats convert to double exactly).
template <typename T>
bool has_zero_area(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
  // Filter: a normal component nonzero beyond its rounding (each edge and
  // product off by at most a few units of 2^-53) decides at once.
  const double e[3] = {double(b[0]) - double(a[0]), double(b[1]) - double(a[1]), double(b[2]) - double(a[2])};
  const double f[3] = {double(c[0]) - double(a[0]), double(c[1]) - double(a[1]), double(c[2]) - double(a[2])};
  for (int x = 0; x < 3; ++x) {
    const int y = x == 2 ? 0 : x + 1, z = y == 2 ? 0 : y + 1;
    const double u = e[y] * f[z], v = e[z] * f[y];
    if (std::abs(u - v) > 0x1p-49 * (std::abs(u) + std::abs(v))) return false;
  }
  for (int x = 0; x < 3; ++x) {
    const int y = x == 2 ? 0 : x + 1;
    const double q[3][2] = {{double(a[x]), double(a[y])}, {double(b[x]), double(b[y])}, {double(c[x]), double(c[y])}};
    if (orient2d(q[0], q[1], q[2]) != 0) return false;
  }
  return true;
}

template <typename T>
T triangle_area(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
  return T(0.5) * triangle_normal(a, b, c).norm();
}

template <typename T>
Vec<T, 3> triangle_centroid(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
  return (a + b + c) / T(3);
}

template <typename T>
AABB<T, 3> triangle_bounds(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
  return {a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)};
}

/// Barycentric coordinates (u, v, w) of p's projection onto the triangle's
/// plane, p ~ u a + v b + w c. Returns NaNs for a degenerate triangle.
template <typename T>
Vec<T, 3> barycentric(const Vec<T, 3>& p, const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c) {
  const Vec<T, 3> v0 = b - a, v1 = c - a, v2 = p - a;
  const T d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const T d20 = v2.dot(v0), d21 = v2.dot(v1);
  const T denom = d00 * d11 - d01 * d01;
  const T v = (d11 * d20 - d01 * d21) / denom;
  const T w = (d00 * d21 - d01 * d20) / denom;
  return {T(1) - v - w, v, w};
}

/// Where on a triangle (a, b, c) a closest point lies: a corner, the inside of
/// an edge, or the inside of the face.
enum class TriangleRegion : std::uint8_t { vertex_a, vertex_b, vertex_c, edge_ab, edge_bc, edge_ca, face };

/// Closest point of the triangle to p (Ericson, Real-Time Collision Detection
/// 5.1.5): the Voronoi regions of vertices, edges and face in turn; `region`
/// says which one holds it. Works for degenerate triangles too (it then
/// returns a point on an edge or vertex).
template <typename T>
Vec<T, 3> closest_point_on_triangle(const Vec<T, 3>& p, const Vec<T, 3>& a, const Vec<T, 3>& b,
                                    const Vec<T, 3>& c, TriangleRegion& region) {
  using R = TriangleRegion;
  const Vec<T, 3> ab = b - a, ac = c - a, ap = p - a;
  const T d1 = ab.dot(ap), d2 = ac.dot(ap);
  region = R::vertex_a;
  if (d1 <= T(0) && d2 <= T(0)) return a;
  const Vec<T, 3> bp = p - b;
  const T d3 = ab.dot(bp), d4 = ac.dot(bp);
  region = R::vertex_b;
  if (d3 >= T(0) && d4 <= d3) return b;
  const T vc = d1 * d4 - d3 * d2;
  if (vc <= T(0) && d1 >= T(0) && d3 <= T(0)) {
    const T denom = d1 - d3;
    region = denom > T(0) ? R::edge_ab : R::vertex_a;
    return denom > T(0) ? Vec<T, 3>(a + (d1 / denom) * ab) : a;
  }
  const Vec<T, 3> cp = p - c;
  const T d5 = ab.dot(cp), d6 = ac.dot(cp);
  region = R::vertex_c;
  if (d6 >= T(0) && d5 <= d6) return c;
  const T vb = d5 * d2 - d1 * d6;
  if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) {
    const T denom = d2 - d6;
    region = denom > T(0) ? R::edge_ca : R::vertex_a;
    return denom > T(0) ? Vec<T, 3>(a + (d2 / denom) * ac) : a;
  }
  const T va = d3 * d6 - d5 * d4;
  if (va <= T(0) && (d4 - d3) >= T(0) && (d5 - d6) >= T(0)) {
    const T denom = (d4 - d3) + (d5 - d6);
    region = denom > T(0) ? R::edge_bc : R::vertex_b;
    return denom > T(0) ? Vec<T, 3>(b + ((d4 - d3) / denom) * (c - b)) : b;
  }
  const T sum = va + vb + vc;
  if (!(sum > T(0))) {
    // Degenerate triangle whose regions did not catch p: nearest of the three edges.
    Vec<T, 3> best = closest_point_on_segment(p, a, b);
    region = R::edge_ab;
    const Vec<T, 3> q_bc = closest_point_on_segment(p, b, c), q_ca = closest_point_on_segment(p, c, a);
    if ((q_bc - p).squaredNorm() < (best - p).squaredNorm()) best = q_bc, region = R::edge_bc;
    if ((q_ca - p).squaredNorm() < (best - p).squaredNorm()) best = q_ca, region = R::edge_ca;
    return best;
  }
  const T v = vb / sum, w = vc / sum;
  region = R::face;
  return a + ab * v + ac * w;
}

/// The same without the region.
template <typename T>
Vec<T, 3> closest_point_on_triangle(const Vec<T, 3>& p, const Vec<T, 3>& a, const Vec<T, 3>& b,
                                    const Vec<T, 3>& c) {
  TriangleRegion region;
  return closest_point_on_triangle(p, a, b, c, region);
}

/// The closest points p + s d and q + t e (s, t in [0, 1]) of the segments
/// from p along d and from q along e: {s, t} (Ericson, 5.1.9; degenerate
/// segments are points).
template <typename T>
std::array<T, 2> segment_segment_closest(const Vec<T, 3>& p, const Vec<T, 3>& d, const Vec<T, 3>& q,
                                         const Vec<T, 3>& e) {
  const Vec<T, 3> r = p - q;
  const T a = d.squaredNorm(), c2 = e.squaredNorm(), f = e.dot(r);
  T s = 0, t = 0;
  if (a <= T(0) && c2 <= T(0)) {
  } else if (a <= T(0)) {
    t = std::clamp(f / c2, T(0), T(1));
  } else {
    const T c = d.dot(r);
    if (c2 <= T(0)) {
      s = std::clamp(-c / a, T(0), T(1));
    } else {
      const T b = d.dot(e), denom = a * c2 - b * b;
      s = denom > T(0) ? std::clamp((b * f - c * c2) / denom, T(0), T(1)) : T(0);
      t = (b * s + f) / c2;
      if (t < T(0)) {
        t = 0;
        s = std::clamp(-c / a, T(0), T(1));
      } else if (t > T(1)) {
        t = 1;
        s = std::clamp((b - c) / a, T(0), T(1));
      }
    }
  }
  return {s, t};
}

}  // namespace geods
