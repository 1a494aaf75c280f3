#pragma once
// Exact geometric predicates on doubles (orientation and in-circle/in-sphere).
//
// Each returns a double whose SIGN is exact for any finite input; its
// magnitude approximates the determinant. A floating-point filter, inline
// here, decides most calls; uncertain ones go to Shewchuk's adaptive stages
// out of line. Conventions follow Shewchuk's predicates.
#include "geods/core/predicates_filter.hpp"
#include "geods/core/vec.hpp"

namespace geods {

/// > 0 if a, b, c are in counter-clockwise order, < 0 if clockwise, 0 if collinear.
inline double orient2d(const double* a, const double* b, const double* c) {
  return detail::orient2d_filter(a, b, c);
}
/// > 0 if d lies below the plane through a, b, c, where a, b, c appear
/// counter-clockwise seen from above; < 0 above; 0 if coplanar.
/// (The determinant of the rows a - d, b - d, c - d.)
inline double orient3d(const double* a, const double* b, const double* c, const double* d) {
  return detail::orient3d_filter(a, b, c, d);
}
/// For counter-clockwise a, b, c: > 0 if d is inside their circle, < 0 outside, 0 on it.
/// The sign flips for clockwise a, b, c.
inline double incircle(const double* a, const double* b, const double* c, const double* d) {
  return detail::incircle_filter(a, b, c, d);
}
/// For a, b, c, d with orient3d(a, b, c, d) > 0: > 0 if e is inside their sphere,
/// < 0 outside, 0 on it. The sign flips when orient3d(a, b, c, d) < 0.
inline double insphere(const double* a, const double* b, const double* c, const double* d, const double* e) {
  return detail::insphere_filter(a, b, c, d, e);
}

inline double orient2d(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  return orient2d(a.data(), b.data(), c.data());
}
inline double orient3d(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  return orient3d(a.data(), b.data(), c.data(), d.data());
}
inline double incircle(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  return incircle(a.data(), b.data(), c.data(), d.data());
}
inline double insphere(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, const Vec3d& e) {
  return insphere(a.data(), b.data(), c.data(), d.data(), e.data());
}

/// The plain floating-point determinants, without any filter: fast, and wrong
/// in sign near degeneracy. For benchmarks and for callers that know better.
double orient2d_fast(const double* a, const double* b, const double* c);
double orient3d_fast(const double* a, const double* b, const double* c, const double* d);
double incircle_fast(const double* a, const double* b, const double* c, const double* d);
double insphere_fast(const double* a, const double* b, const double* c, const double* d, const double* e);

}  // namespace geods
