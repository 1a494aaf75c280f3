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

inline ::geods::exact::Expansion<2> exact_diff(double a, double b) {
  return ::geods::exact::from_two_term(::geods::exact::two_diff(a, b));
}

constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2;

// Whether a rounded circumcentre a + n / (2 o) (up to sign) is within 2^-40 of
// the exact one, relative to its offset from a and to a, given bounds on the
// errors of the numerator n (largest component n_max) and of the orientation o.
// (Ordered so that no intermediate overflows where the result does not: the
// test takes the same branch at any power-of-two scale of the input.)
inline bool rounded_centre_is_accurate(double n_error, double n_max, double o, double o_error, double offset_max,
                                       double a_max) {
  const double offset_error = (n_error + n_max * (o_error / std::abs(o))) / std::abs(2 * o);
  return o_error < 0x1p-20 * std::abs(o) && offset_error <= 0x1p-40 * (offset_max + a_max);
}

/// The centre of the circle through a, b, c (not collinear), accurate to about
/// 2^-40 of its offset from a and of a however flat the triangle: the rounded
/// formula where its error bound allows that, else its numerators and the
/// orientation summed exactly (a nearly flat triangle's formula cancels most
/// of its digits: its centre was off by 1e-5 of its distance on nearly
/// collinear sites). The exact orientation keeps the denominator non-zero.
inline Vec2d circumcentre(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  const Vec2d ab = b - a, ac = c - a;
  const double o = orient2d(a, b, c);
  const double ab2 = ab.squaredNorm(), ac2 = ac.squaredNorm();
  const Vec2d n(ac[1] * ab2 - ab[1] * ac2, ab[0] * ac2 - ac[0] * ab2);
  const Vec2d offset = n / (2 * o);
  // Forward error bounds: each rounded difference, product and sum adds at most
  // u = eps / 2 relative to its magnitude; orient2d's value is within its stage
  // A bound, about 3u of its terms' magnitudes (here taken about c, as it does).
  const Vec2d ca = a - c, cb = b - c;
  const double o_error = 4 * kUnitRoundoff * (std::abs(ca[0] * cb[1]) + std::abs(ca[1] * cb[0]));
  const double n_error = 8 * kUnitRoundoff * std::max(std::abs(ac[1]) * ab2 + std::abs(ab[1]) * ac2,
                                                      std::abs(ab[0]) * ac2 + std::abs(ac[0]) * ab2);
  if (rounded_centre_is_accurate(n_error, n.cwiseAbs().maxCoeff(), o, o_error, offset.cwiseAbs().maxCoeff(),
                                 a.cwiseAbs().maxCoeff()))
    return a + offset;
  const auto abx = exact_diff(b[0], a[0]), aby = exact_diff(b[1], a[1]);
  const auto acx = exact_diff(c[0], a[0]), acy = exact_diff(c[1], a[1]);
  const auto ab2_exact = abx * abx + aby * aby, ac2_exact = acx * acx + acy * acy;
  const double o_exact = (abx * acy - aby * acx).estimate();
  return a + Vec2d((acy * ab2_exact - aby * ac2_exact).estimate(), (abx * ac2_exact - acx * ab2_exact).estimate()) /
                 (2 * o_exact);
}

/// The centre of the sphere through a, b, c, d (not coplanar), the same way as
/// the circle's: the rounded formula where its error bound allows 2^-40, else
/// the numerators and the orientation summed exactly (a sliver's rounded
/// centre was off by up to a tenth of its distance).
inline Vec3d circumcentre(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Vec3d ab = b - a, ac = c - a, ad = d - a;
  const double o = orient3d(a.data(), b.data(), c.data(), d.data());
  const double det = -2 * o;  // 2 det(ab, ac, ad)
  const double ab2 = ab.squaredNorm(), ac2 = ac.squaredNorm(), ad2 = ad.squaredNorm();
  const Vec3d n = ab2 * ac.cross(ad) + ac2 * ad.cross(ab) + ad2 * ab.cross(ac);
  const Vec3d offset = n / det;
  // Forward error bounds as in 2D: the numerators from the magnitudes of their
  // terms, orient3d's value from its stage A bound (about 7u of its permanent, about d).
  const auto magnitudes = [](const Vec3d& x, const Vec3d& y) {
    return Vec3d(std::abs(x[1] * y[2]) + std::abs(x[2] * y[1]), std::abs(x[2] * y[0]) + std::abs(x[0] * y[2]),
                 std::abs(x[0] * y[1]) + std::abs(x[1] * y[0]));
  };
  const double n_error =
      16 * kUnitRoundoff * (ab2 * magnitudes(ac, ad) + ac2 * magnitudes(ad, ab) + ad2 * magnitudes(ab, ac)).maxCoeff();
  const Vec3d da = a - d, db = b - d, dc = c - d;
  const double o_error = 8 * kUnitRoundoff * da.cwiseAbs().dot(magnitudes(db, dc));
  if (rounded_centre_is_accurate(n_error, n.cwiseAbs().maxCoeff(), o, o_error, offset.cwiseAbs().maxCoeff(),
                                 a.cwiseAbs().maxCoeff()))
    return a + offset;
  const auto abx = exact_diff(b[0], a[0]), aby = exact_diff(b[1], a[1]), abz = exact_diff(b[2], a[2]);
  const auto acx = exact_diff(c[0], a[0]), acy = exact_diff(c[1], a[1]), acz = exact_diff(c[2], a[2]);
  const auto adx = exact_diff(d[0], a[0]), ady = exact_diff(d[1], a[1]), adz = exact_diff(d[2], a[2]);
  const auto ab2_exact = abx * abx + aby * aby + abz * abz;
  const auto ac2_exact = acx * acx + acy * acy + acz * acz;
  const auto ad2_exact = adx * adx + ady * ady + adz * adz;
  // The cross products' components, then each numerator component and the determinant.
  const auto cd_x = acy * adz - acz * ady, cd_y = acz * adx - acx * adz, cd_z = acx * ady - acy * adx;  // ac x ad
  const auto db_x = ady * abz - adz * aby, db_y = adz * abx - adx * abz, db_z = adx * aby - ady * abx;  // ad x ab
  const auto bc_x = aby * acz - abz * acy, bc_y = abz * acx - abx * acz, bc_z = abx * acy - aby * acx;  // ab x ac
  const double det_exact = 2 * (abx * cd_x + aby * cd_y + abz * cd_z).estimate();
  const auto numerator = [&](const auto& cd, const auto& db, const auto& bc) {
    return (ab2_exact * cd + ac2_exact * db + ad2_exact * bc).estimate();
  };
  return a + Vec3d(numerator(cd_x, db_x, bc_x), numerator(cd_y, db_y, bc_y), numerator(cd_z, db_z, bc_z)) / det_exact;
}

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
