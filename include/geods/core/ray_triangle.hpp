#pragma once
// Watertight ray-triangle intersection (Woop, Benthin and Wald, "Watertight
// Ray/Triangle Intersection", JCGT 2013). The ray is sheared so that it points
// along +z; the three edge functions of the projected triangle are then
// evaluated in the same way for every triangle that shares an edge, so a ray
// through a shared edge or vertex of a closed mesh hits at least one of the
// triangles around it: it never slips through a crack.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>

#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/ray.hpp"
#include "geods/core/triangle.hpp"

namespace geods {

/// The closest hit found so far along a ray. prim is the triangle index
/// (no_hit when the ray missed); (u, v) are the barycentric weights of the
/// triangle's second and third corner: p = (1-u-v) a + u b + v c.
struct RayHit {
  static constexpr std::uint32_t no_hit = std::numeric_limits<std::uint32_t>::max();
  float t = std::numeric_limits<float>::infinity();
  std::uint32_t prim = no_hit;
  float u = 0.0f;
  float v = 0.0f;

  bool hit() const { return prim != no_hit; }
};

/// The coordinates at which RayTriangleTest<float> answers as at unit scale
/// (the hits of an input scaled by a power of two are those of the unit-scale
/// input, t scaled): its terms are of degree 3 in corner - origin, which
/// overflow beyond |coordinate| 2^35 (coordinate_limit<float>(3), 3.4e10)
/// and lose precision when the cube of a mesh's extent nears the smallest
/// normal float, below 2^-34 (5.8e-11). The ray queries refuse meshes and ray
/// origins outside (geods::Error) rather than answer them wrongly.
inline constexpr float kRayCoordinateLimit = coordinate_limit<float>(3);
inline constexpr float kRayExtentFloor =
    power_of_two<float>((std::numeric_limits<float>::min_exponent - 1 + std::numeric_limits<float>::digits) / 3);

/// Empty if triangles within `bounds` (empty: no triangles) are in the range
/// above (an extent of 0 is: every triangle is one point); else why not, as a
/// message "<what>: ...".
inline std::string ray_range_problem(const AABB3f& bounds, const std::string& what) {
  if (bounds.empty()) return {};
  const float reach = std::max(bounds.lo.cwiseAbs().maxCoeff(), bounds.hi.cwiseAbs().maxCoeff());
  const float extent = (bounds.hi - bounds.lo).maxCoeff();
  if (!(reach <= kRayCoordinateLimit))
    return what + ": a coordinate of " + format_number(reach) + " is beyond +-" + format_number(kRayCoordinateLimit) +
           ", where the ray-triangle test would overflow; scale the mesh for ray queries";
  if (extent > 0 && extent < kRayExtentFloor)  // (0: points only, which no ray hits)
    return what + ": the triangles span only " + format_number(extent) + " (below " +
           format_number(kRayExtentFloor) + "), where the ray-triangle test loses precision; scale the mesh for ray queries";
  return {};
}

/// Throws `problem` (ray_range_problem of the mesh) if it is not empty, or an
/// error if the ray's origin lies beyond kRayCoordinateLimit. (A NaN origin
/// passes: such a ray hits nothing.)
inline void check_ray_range(const std::string& problem, const Vec3f& origin, const char* what) {
  if (!problem.empty()) [[unlikely]]
    throw Error(problem);
  check_query_range(std::span<const float>(origin.data(), 3), kRayCoordinateLimit, what);
}

/// Per-ray precomputation of the watertight test; build once per ray, then
/// call intersect() on every candidate triangle. Triangles are two-sided.
template <typename T>
class RayTriangleTest {
 public:
  explicit RayTriangleTest(const Ray<T>& ray) : origin_(ray.origin) {
    const Vec<T, 3>& d = ray.direction;
    // kz: the largest |d| component, the first of equals; kx, ky the next two,
    // swapped for a negative z (which keeps the winding, so the sign of the
    // edge functions does not depend on the ray's direction). Computed without
    // branches (GCC keeps them for ?: here): on random directions they
    // mispredict, a per-ray cost of incoherent rays.
    const T a0 = std::abs(d[0]), a1 = std::abs(d[1]);
    const int y_over_x = int(a1 > a0);
    kz_ = y_over_x + int(std::abs(d[2]) > std::max(a0, a1)) * (2 - y_over_x);  // max: a1 if a1 > a0, else a0
    const int next = kz_ + 1 - 3 * int(kz_ == 2), after = 3 - kz_ - next;
    const int swap = -int(d[kz_] < T(0));
    kx_ = next ^ ((next ^ after) & swap);
    ky_ = after ^ ((next ^ after) & swap);
    shear_x_ = d[kx_] / d[kz_];
    shear_y_ = d[ky_] / d[kz_];
    // A direction with an infinite component (then d[kz] is one) hits
    // nothing: its shear would put every triangle around the origin's
    // projection at t = 0. A NaN t rejects them all (and a NaN component
    // already makes the edge functions NaN).
    shear_z_ = std::isfinite(d[kz_]) ? T(1) / d[kz_] : std::numeric_limits<T>::quiet_NaN();
  }

  /// Parameter t and barycentrics (u, v) of the hit with triangle (a, b, c)
  /// if t lies in [tmin, tmax]; false otherwise (also for triangles of zero
  /// area, has_zero_area, and a zero or non-finite direction).
  bool intersect(const Vec<T, 3>& a, const Vec<T, 3>& b, const Vec<T, 3>& c, T tmin, T tmax, T& t,
                 T& u, T& v) const {
    const Vec<T, 3> pa = a - origin_, pb = b - origin_, pc = c - origin_;
    const T ax = pa[kx_] - shear_x_ * pa[kz_], ay = pa[ky_] - shear_y_ * pa[kz_];
    const T bx = pb[kx_] - shear_x_ * pb[kz_], by = pb[ky_] - shear_y_ * pb[kz_];
    const T cx = pc[kx_] - shear_x_ * pc[kz_], cy = pc[ky_] - shear_y_ * pc[kz_];
    T eu = cx * by - cy * bx;
    T ev = ax * cy - ay * cx;
    T ew = bx * ay - by * ax;
    // An edge function that rounds to zero is recomputed in double, so the
    // ray-on-edge decision is the same for both triangles of that edge.
    if constexpr (sizeof(T) < sizeof(double)) {
      if (eu == T(0) || ev == T(0) || ew == T(0)) {
        eu = T(double(cx) * double(by) - double(cy) * double(bx));
        ev = T(double(ax) * double(cy) - double(ay) * double(cx));
        ew = T(double(bx) * double(ay) - double(by) * double(ax));
      }
    }
    if ((eu < T(0) || ev < T(0) || ew < T(0)) && (eu > T(0) || ev > T(0) || ew > T(0))) return false;
    const T det = eu + ev + ew;
    if (det == T(0) || !std::isfinite(det)) return false;
    const T az = shear_z_ * pa[kz_], bz = shear_z_ * pb[kz_], cz = shear_z_ * pc[kz_];
    const T scaled_t = eu * az + ev * bz + ew * cz;
    const T inv_det = T(1) / det;
    const T hit_t = scaled_t * inv_det;
    if (!(hit_t >= tmin && hit_t <= tmax)) return false;
    // Exactly, a triangle with collinear corners is never hit (its edge
    // functions sum to zero); rounded, its sheared projection can get a
    // sliver of area around the ray and a "hit" off the triangle. On hits
    // only: a det beyond the rounding of the sheared corners and of the edge
    // functions (about 20 units of u times the sizes of their terms) shows
    // area at once, else zero area is decided exactly.
    const T mz = std::abs(pa[kz_]) + std::abs(pb[kz_]) + std::abs(pc[kz_]);
    const T mx = std::abs(pa[kx_]) + std::abs(pb[kx_]) + std::abs(pc[kx_]) + std::abs(shear_x_) * mz;
    const T my = std::abs(pa[ky_]) + std::abs(pb[ky_]) + std::abs(pc[ky_]) + std::abs(shear_y_) * mz;
    if (!(std::abs(det) > T(16) * std::numeric_limits<T>::epsilon() * mx * my) && has_zero_area(a, b, c)) [[unlikely]]
      return false;
    t = hit_t;
    u = ev * inv_det;
    v = ew * inv_det;
    return true;
  }

  // The per-ray setup, for SIMD versions of the test that must decide exactly
  // as this one does (bvh/ray_triangle4.hpp).
  const Vec<T, 3>& origin() const { return origin_; }
  int axis_x() const { return kx_; }
  int axis_y() const { return ky_; }
  int axis_z() const { return kz_; }
  T shear_x() const { return shear_x_; }
  T shear_y() const { return shear_y_; }
  T shear_z() const { return shear_z_; }

 private:
  Vec<T, 3> origin_;
  int kx_, ky_, kz_;
  T shear_x_, shear_y_, shear_z_;
};

}  // namespace geods
