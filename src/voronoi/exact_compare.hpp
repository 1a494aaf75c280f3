#pragma once
// The circumcentre, and exact signs of small sums of products of coordinate differences, for the
// distance comparisons of the voronoi module (which of two sites is nearer to
// a query; is a point inside a diametral circle). A floating-point filter
// decides almost every call; the rest are evaluated exactly with Shewchuk's
// expansions (exact while coordinates stay within about 1e-140..1e140).
#include <algorithm>
#include <cmath>
#include <limits>

#include "../core/expansion.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi::detail {

/// The centre of the circle through a, b, c (not collinear). The exact
/// orientation keeps the denominator non-zero however flat the triangle is.
inline Vec2d circumcentre(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  const Vec2d ab = b - a, ac = c - a;
  const double d = 2 * orient2d(a, b, c);
  const double ab2 = ab.squaredNorm(), ac2 = ac.squaredNorm();
  return a + Vec2d(ac[1] * ab2 - ab[1] * ac2, ab[0] * ac2 - ac[0] * ab2) / d;
}

/// The centre of the sphere through a, b, c, d (not coplanar), the same way.
inline Vec3d circumcentre(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Vec3d ab = b - a, ac = c - a, ad = d - a;
  const double det = -2 * orient3d(a.data(), b.data(), c.data(), d.data());  // 2 det(ab, ac, ad)
  return a + (ab.squaredNorm() * ac.cross(ad) + ac.squaredNorm() * ad.cross(ab) + ad.squaredNorm() * ab.cross(ac)) / det;
}

inline exact::Expansion<2> exact_diff(double a, double b) { return exact::from_two_term(exact::two_diff(a, b)); }

/// Sign of (a0 - b0)(c0 - d0) + (a1 - b1)(c1 - d1) - (e0 - f0)(g0 - h0) - (e1 - f1)(g1 - h1),
/// given as 2D vectors: the sign of (a - b).(c - d) - (e - f).(g - h).
inline int dot_difference_sign(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d, const Vec2d& e,
                               const Vec2d& f, const Vec2d& g, const Vec2d& h) {
  const double t0 = (a[0] - b[0]) * (c[0] - d[0]), t1 = (a[1] - b[1]) * (c[1] - d[1]);
  const double t2 = (e[0] - f[0]) * (g[0] - h[0]), t3 = (e[1] - f[1]) * (g[1] - h[1]);
  const double value = (t0 + t1) - (t2 + t3);
  // Each difference rounds by at most u relative, each product and sum by u more: 8u of the
  // magnitudes bounds the error with room to spare.
  const double bound = 8 * std::numeric_limits<double>::epsilon() *
                       (std::abs(t0) + std::abs(t1) + std::abs(t2) + std::abs(t3));
  if (value > bound) return 1;
  if (value < -bound) return -1;
  const auto p0 = exact_diff(a[0], b[0]) * exact_diff(c[0], d[0]);
  const auto p1 = exact_diff(a[1], b[1]) * exact_diff(c[1], d[1]);
  const auto p2 = exact_diff(e[0], f[0]) * exact_diff(g[0], h[0]);
  const auto p3 = exact_diff(e[1], f[1]) * exact_diff(g[1], h[1]);
  const double top = ((p0 + p1) - (p2 + p3)).top();
  return (top > 0) - (top < 0);
}

/// Sign of |q - a|^2 - |q - b|^2: negative when a is nearer to q, zero on a tie. Exact.
inline int compare_distance(const Vec2d& q, const Vec2d& a, const Vec2d& b) {
  return dot_difference_sign(q, a, q, a, q, b, q, b);
}

/// |d|^2 as mantissa * 2^exponent: finite and normal for any finite d, where
/// squaring the components of a 1e300 or 1e-300 difference directly overflows
/// or underflows. Its order is that of d.squaredNorm() wherever that is exact
/// in range (the scaling by a power of two commutes with the rounding).
struct WideSquaredNorm {
  double mantissa = 0;  // in [1, 8), or 0 for d = 0
  int exponent = 0;

  explicit WideSquaredNorm(const Vec2d& d) {
    const double m = std::max(std::abs(d[0]), std::abs(d[1]));
    if (m == 0) return;
    const int e = std::ilogb(m);
    const double x = std::ldexp(d[0], -e), y = std::ldexp(d[1], -e);
    mantissa = x * x + y * y;
    exponent = 2 * e;
  }
  friend bool operator<(const WideSquaredNorm& a, const WideSquaredNorm& b) {
    if (a.mantissa == 0 || b.mantissa == 0) return a.mantissa < b.mantissa;
    if (a.exponent == b.exponent) return a.mantissa < b.mantissa;
    return std::ldexp(a.mantissa, a.exponent - b.exponent) < b.mantissa;  // saturates to 0 or inf: still ordered
  }
};

/// Sign of (p - a).(p - b): <= 0 exactly when p lies in the closed disc with diameter ab. Exact.
inline int diametral_sign(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
  const Vec2d zero(0, 0);
  return dot_difference_sign(p, a, p, b, zero, zero, zero, zero);
}

}  // namespace geods::voronoi::detail
