// Adaptive exact predicates after Shewchuk, "Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates" (1997).
//
// Each predicate runs through:
//  1. the filter (inline, geods/core/predicates_filter.hpp): the determinant
//     in plain doubles with Shewchuk's forward error bound, widened by an
//     absolute term that covers underflow (his bound assumes none);
//  2. his adaptive stages, when every input lies in an exponent window where
//     no product can overflow or lose bits to underflow: B, the exact
//     determinant of the rounded coordinate differences (exact outright when
//     the differences were); C, B plus the first-order tail terms in doubles;
//     D, the exact determinant;
//  3. big integers, for inputs outside the window (huge, tiny, subnormal,
//     mixed): every coordinate becomes an integer times a common power of two.
#include "geods/core/predicates.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>

#include "big_int.hpp"
#include "expansion.hpp"

namespace geods {
namespace {

using exact::BigInt;
using exact::Expansion;
using exact::product;
using exact::two_diff;
using exact::TwoTerm;

// ---------------------------------------------------------------------------
// The determinants as formulas over any number type (double, BigInt): these
// are the `_fast` predicates and the big-integer path.

template <typename T>
T orient2d_formula(const T* a, const T* b, const T* c) {
  const T acx = a[0] - c[0], acy = a[1] - c[1];
  const T bcx = b[0] - c[0], bcy = b[1] - c[1];
  return acx * bcy - acy * bcx;
}

template <typename T>
T orient3d_formula(const T* a, const T* b, const T* c, const T* d) {
  const T adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
  const T bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
  const T cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
  return adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy);
}

template <typename T>
T incircle_formula(const T* a, const T* b, const T* c, const T* d) {
  const T adx = a[0] - d[0], ady = a[1] - d[1];
  const T bdx = b[0] - d[0], bdy = b[1] - d[1];
  const T cdx = c[0] - d[0], cdy = c[1] - d[1];
  const T alift = adx * adx + ady * ady;
  const T blift = bdx * bdx + bdy * bdy;
  const T clift = cdx * cdx + cdy * cdy;
  return alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) + clift * (adx * bdy - bdx * ady);
}

template <typename T>
T insphere_formula(const T* a, const T* b, const T* c, const T* d, const T* e) {
  const T aex = a[0] - e[0], aey = a[1] - e[1], aez = a[2] - e[2];
  const T bex = b[0] - e[0], bey = b[1] - e[1], bez = b[2] - e[2];
  const T cex = c[0] - e[0], cey = c[1] - e[1], cez = c[2] - e[2];
  const T dex = d[0] - e[0], dey = d[1] - e[1], dez = d[2] - e[2];
  const T ab = aex * bey - bex * aey;
  const T bc = bex * cey - cex * bey;
  const T cd = cex * dey - dex * cey;
  const T da = dex * aey - aex * dey;
  const T ac = aex * cey - cex * aey;
  const T bd = bex * dey - dex * bey;
  const T abc = aez * bc - bez * ac + cez * ab;
  const T bcd = bez * cd - cez * bd + dez * bc;
  const T cda = cez * da + dez * ac + aez * cd;
  const T dab = dez * ab + aez * bd + bez * da;
  const T alift = aex * aex + aey * aey + aez * aez;
  const T blift = bex * bex + bey * bey + bez * bez;
  const T clift = cex * cex + cey * cey + cez * cez;
  const T dlift = dex * dex + dey * dey + dez * dez;
  return (dlift * abc - clift * dab) + (blift * cda - alift * bcd);
}

// ---------------------------------------------------------------------------
// Error bounds of the later stages (the filter's are in predicates_filter.hpp).

using detail::kEpsilon;
using detail::kUnderflowUnit;
constexpr double kResultBound = (3.0 + 8.0 * kEpsilon) * kEpsilon;
constexpr double kOrient2dBoundB = (2.0 + 12.0 * kEpsilon) * kEpsilon;
constexpr double kOrient2dBoundC = (9.0 + 64.0 * kEpsilon) * kEpsilon * kEpsilon;
constexpr double kOrient3dBoundB = (3.0 + 28.0 * kEpsilon) * kEpsilon;
constexpr double kOrient3dBoundC = (26.0 + 288.0 * kEpsilon) * kEpsilon * kEpsilon;
constexpr double kIncircleBoundB = (4.0 + 48.0 * kEpsilon) * kEpsilon;
constexpr double kIncircleBoundC = (44.0 + 576.0 * kEpsilon) * kEpsilon * kEpsilon;
constexpr double kInsphereBoundB = (5.0 + 72.0 * kEpsilon) * kEpsilon;
constexpr double kInsphereBoundC = (71.0 + 1408.0 * kEpsilon) * kEpsilon * kEpsilon;

// ---------------------------------------------------------------------------
// Stage 2 guard: the exponent window where expansion arithmetic is exact.
//
// A normal double with exponent e is a multiple of 2^(e-52), so every term of
// a degree-d formula is a multiple of 2^(d (e_min - 52)); when that is at
// least 2^-1074 even results in the subnormal range are exact. The upper
// limit keeps (2 |x|)^d times the number of terms (under 2^16) below 2^1023.

constexpr int min_exponent(int degree) { return 52 - 1074 / degree; }
constexpr int max_exponent(int degree) { return 1000 / degree - 3; }

template <int Degree>
bool in_window(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  if ((bits << 1) == 0) return true;  // +-0
  // Subnormals read as -1023 and inf/NaN as 1024: both outside.
  const int exponent = int((bits >> 52) & 0x7ff) - 1023;
  return exponent >= min_exponent(Degree) && exponent <= max_exponent(Degree);
}

template <int Degree, int Dim, std::size_t N>
bool fits_expansions(const std::array<const double*, N>& points) {
  bool ok = true;
  for (const double* p : points)
    for (int k = 0; k < Dim; ++k) ok &= in_window<Degree>(p[k]);
  return ok;
}

// ---------------------------------------------------------------------------
// Stage 3: big integers. Each coordinate is sign * m * 2^k with an odd integer
// m; with q the smallest k, a coordinate is the integer (sign * m * 2^(k-q))
// times 2^q, and a homogeneous formula of degree d scales by 2^(d q).

using exact::SplitDouble;
SplitDouble split(double x) { return exact::split_double(x); }

// Formula takes an array of N pointers to Dim BigInt coordinates.
template <int Degree, int Dim, std::size_t N, typename Formula>
[[gnu::noinline]] double with_big_integers(const std::array<const double*, N>& points, const Formula& formula) {
  int min_exponent = std::numeric_limits<int>::max();
  for (const double* p : points)
    for (int k = 0; k < Dim; ++k) {
      // NaN or infinite input: no sign to give.
      if (!std::isfinite(p[k])) return std::numeric_limits<double>::quiet_NaN();
      if (p[k] != 0.0) min_exponent = std::min(min_exponent, split(p[k]).exponent);
    }
  if (min_exponent == std::numeric_limits<int>::max()) return 0.0;  // all coordinates zero

  std::array<std::array<BigInt, Dim>, N> integers;
  std::array<const BigInt*, N> pointers;
  for (std::size_t i = 0; i < N; ++i) {
    for (int k = 0; k < Dim; ++k) {
      const double x = points[i][k];
      if (x == 0.0) continue;
      const SplitDouble s = split(x);
      integers[i][k] = BigInt::from_shifted(s.odd_significand, s.exponent - min_exponent, x < 0.0);
    }
    pointers[i] = integers[i].data();
  }
  return formula(pointers).to_double_scaled(long(Degree) * min_exponent);
}

// ---------------------------------------------------------------------------
// Expansion helpers for the adaptive stages.

using exact::from_four_term;
using exact::from_two_term;
using exact::two_product;
using exact::two_two_diff;

bool all_zero_tails(std::initializer_list<TwoTerm> differences) {
  for (const TwoTerm& t : differences)
    if (t.tail != 0.0) return false;
  return true;
}

// p q' - q p' exactly, as Shewchuk's Two_Two_Diff of two products.
exact::FourTerm cross(double p, double q_prime, double q, double p_prime) {
  return two_two_diff(two_product(p, q_prime), two_product(q, p_prime));
}

// m * |v|^2 over the first Dim coordinates of v.
template <int Dim, int N>
Expansion<Dim * 4 * N> times_lift(const Expansion<N>& m, const double* v) {
  if constexpr (Dim == 2) {
    return (m * v[0]) * v[0] + (m * v[1]) * v[1];
  } else {
    return (m * v[0]) * v[0] + (m * v[1]) * v[1] + (m * v[2]) * v[2];
  }
}

// The 2x2 minor of exact differences, for stage D.
Expansion<16> exact_minor(const Expansion<2>& px, const Expansion<2>& py, const Expansion<2>& qx,
                          const Expansion<2>& qy) {
  return px * qy - qx * py;
}

// Exact lifted determinants on the original coordinates, the exact fallback
// of insphere. With the homogeneous coordinate 1 appended, orient3d =
// det4[x y z 1] and insphere = det5[x y z |p|^2 1].

Expansion<4> minor2(const double* p, const double* q) { return product(p[0], q[1]) - product(q[0], p[1]); }

// det3 of the rows p, q, r (x, y, z), expanded along z.
Expansion<24> minor3(const double* p, const double* q, const double* r) {
  return minor2(q, r) * p[2] - minor2(p, r) * q[2] + minor2(p, q) * r[2];
}

Expansion<96> lifted_orient3d(const double* a, const double* b, const double* c, const double* d) {
  return (minor3(a, c, d) - minor3(b, c, d)) + (minor3(a, b, c) - minor3(a, b, d));
}

// Integer grids (the common exactly degenerate input) need no expansions: when
// every coordinate is an integer of magnitude below 2^52, their differences are
// computed exactly, and when those differences are below 2^bits the plain
// double determinant is exact too (bits = 26 for orient2d: products < 2^52;
// bits = 12 for incircle: lifts and 2x2 minors < 2^25, their products < 2^50,
// the sum of three < 2^52). As CGAL's static filters, this answers the
// degenerate calls of such inputs at the cost of the filter.
template <std::size_t N>
bool small_integer_differences(const std::array<const double*, N>& points, int bits) {
  const double limit = std::ldexp(1.0, bits);
  for (const double* p : points)
    for (int k = 0; k < 2; ++k)
      if (!(std::abs(p[k]) < 0x1p52) || p[k] != std::trunc(p[k])) return false;
  const double* last = points[N - 1];
  for (std::size_t i = 0; i + 1 < N; ++i)
    for (int k = 0; k < 2; ++k)
      if (!(std::abs(points[i][k] - last[k]) < limit)) return false;
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------
// The adaptive stages of each predicate, after Shewchuk's orient2dadapt,
// orient3dadapt, incircleadapt and insphereadapt, behind the window guard.
// In the window every value they compute is a multiple of 2^-1074, so its
// rounding error is relative (or zero), as Shewchuk's bounds assume; only a
// bound itself, a tiny constant times a permanent, can underflow, which
// kUnderflowUnit covers. Each stage B first checks the difference tails: when
// all are zero its expansion is the exact determinant.

namespace detail {

double orient2d_adapt(const double* a, const double* b, const double* c, double permanent) {
  const std::array<const double*, 3> points{a, b, c};
  if (small_integer_differences(points, 26)) return orient2d_formula(a, b, c);
  if (!fits_expansions<2, 2>(points))
    return with_big_integers<2, 2>(points, [](const auto& p) { return orient2d_formula(p[0], p[1], p[2]); });

  const TwoTerm acx = two_diff(a[0], c[0]), acy = two_diff(a[1], c[1]);
  const TwoTerm bcx = two_diff(b[0], c[0]), bcy = two_diff(b[1], c[1]);
  const auto b_det = from_four_term(cross(acx.head, bcy.head, acy.head, bcx.head));
  if (all_zero_tails({acx, acy, bcx, bcy})) return b_det.top();
  double det = b_det.estimate();
  if (std::abs(det) >= kOrient2dBoundB * permanent + kUnderflowUnit) return det;

  // Stage C: the first-order tail terms in doubles.
  const double bound = kOrient2dBoundC * permanent + kResultBound * std::abs(det) + kUnderflowUnit;
  det += (acx.head * bcy.tail + bcy.head * acx.tail) - (acy.head * bcx.tail + bcx.head * acy.tail);
  if (std::abs(det) >= bound) return det;

  // Stage D: every tail term, exactly.
  const auto c1 = b_det + from_four_term(cross(acx.tail, bcy.head, acy.tail, bcx.head));
  const auto c2 = c1 + from_four_term(cross(acx.head, bcy.tail, acy.head, bcx.tail));
  return (c2 + from_four_term(cross(acx.tail, bcy.tail, acy.tail, bcx.tail))).top();
}

double orient3d_adapt(const double* a, const double* b, const double* c, const double* d, double permanent) {
  const std::array<const double*, 4> points{a, b, c, d};
  if (!fits_expansions<3, 3>(points))
    return with_big_integers<3, 3>(points,
                                   [](const auto& p) { return orient3d_formula(p[0], p[1], p[2], p[3]); });

  const TwoTerm adx = two_diff(a[0], d[0]), ady = two_diff(a[1], d[1]), adz = two_diff(a[2], d[2]);
  const TwoTerm bdx = two_diff(b[0], d[0]), bdy = two_diff(b[1], d[1]), bdz = two_diff(b[2], d[2]);
  const TwoTerm cdx = two_diff(c[0], d[0]), cdy = two_diff(c[1], d[1]), cdz = two_diff(c[2], d[2]);
  const auto bc = from_four_term(cross(bdx.head, cdy.head, cdx.head, bdy.head));
  const auto ca = from_four_term(cross(cdx.head, ady.head, adx.head, cdy.head));
  const auto ab = from_four_term(cross(adx.head, bdy.head, bdx.head, ady.head));
  const auto b_det = (bc * adz.head + ca * bdz.head) + ab * cdz.head;
  if (all_zero_tails({adx, ady, adz, bdx, bdy, bdz, cdx, cdy, cdz})) return b_det.top();
  double det = b_det.estimate();
  if (std::abs(det) >= kOrient3dBoundB * permanent + kUnderflowUnit) return det;

  const double bound = kOrient3dBoundC * permanent + kResultBound * std::abs(det) + kUnderflowUnit;
  det += (adz.head * ((bdx.head * cdy.tail + cdy.head * bdx.tail) - (bdy.head * cdx.tail + cdx.head * bdy.tail)) +
          adz.tail * (bdx.head * cdy.head - bdy.head * cdx.head)) +
         (bdz.head * ((cdx.head * ady.tail + ady.head * cdx.tail) - (cdy.head * adx.tail + adx.head * cdy.tail)) +
          bdz.tail * (cdx.head * ady.head - cdy.head * adx.head)) +
         (cdz.head * ((adx.head * bdy.tail + bdy.head * adx.tail) - (ady.head * bdx.tail + bdx.head * ady.tail)) +
          cdz.tail * (adx.head * bdy.head - ady.head * bdx.head));
  if (std::abs(det) >= bound) return det;

  // Stage D: the determinant of the exact differences.
  const Expansion<2> ax = from_two_term(adx), ay = from_two_term(ady), az = from_two_term(adz);
  const Expansion<2> bx = from_two_term(bdx), by = from_two_term(bdy), bz = from_two_term(bdz);
  const Expansion<2> cx = from_two_term(cdx), cy = from_two_term(cdy), cz = from_two_term(cdz);
  const auto exact = (exact_minor(bx, by, cx, cy) * az + exact_minor(cx, cy, ax, ay) * bz) +
                     exact_minor(ax, ay, bx, by) * cz;
  return exact.top();
}

double incircle_adapt(const double* a, const double* b, const double* c, const double* d, double permanent) {
  const std::array<const double*, 4> points{a, b, c, d};
  if (small_integer_differences(points, 12)) return incircle_formula(a, b, c, d);
  if (!fits_expansions<4, 2>(points))
    return with_big_integers<4, 2>(points,
                                   [](const auto& p) { return incircle_formula(p[0], p[1], p[2], p[3]); });

  const TwoTerm adx = two_diff(a[0], d[0]), ady = two_diff(a[1], d[1]);
  const TwoTerm bdx = two_diff(b[0], d[0]), bdy = two_diff(b[1], d[1]);
  const TwoTerm cdx = two_diff(c[0], d[0]), cdy = two_diff(c[1], d[1]);
  const double ad[2] = {adx.head, ady.head}, bd[2] = {bdx.head, bdy.head}, cd[2] = {cdx.head, cdy.head};
  const auto bc = from_four_term(cross(bdx.head, cdy.head, cdx.head, bdy.head));
  const auto ca = from_four_term(cross(cdx.head, ady.head, adx.head, cdy.head));
  const auto ab = from_four_term(cross(adx.head, bdy.head, bdx.head, ady.head));
  const auto b_det = times_lift<2>(bc, ad) + times_lift<2>(ca, bd) + times_lift<2>(ab, cd);
  if (all_zero_tails({adx, ady, bdx, bdy, cdx, cdy})) return b_det.top();
  double det = b_det.estimate();
  if (std::abs(det) >= kIncircleBoundB * permanent + kUnderflowUnit) return det;

  const double adxh = adx.head, adyh = ady.head, bdxh = bdx.head, bdyh = bdy.head, cdxh = cdx.head, cdyh = cdy.head;
  const double bound = kIncircleBoundC * permanent + kResultBound * std::abs(det) + kUnderflowUnit;
  det += ((adxh * adxh + adyh * adyh) * ((bdxh * cdy.tail + cdyh * bdx.tail) - (bdyh * cdx.tail + cdxh * bdy.tail)) +
          2.0 * (adxh * adx.tail + adyh * ady.tail) * (bdxh * cdyh - bdyh * cdxh)) +
         ((bdxh * bdxh + bdyh * bdyh) * ((cdxh * ady.tail + adyh * cdx.tail) - (cdyh * adx.tail + adxh * cdy.tail)) +
          2.0 * (bdxh * bdx.tail + bdyh * bdy.tail) * (cdxh * adyh - cdyh * adxh)) +
         ((cdxh * cdxh + cdyh * cdyh) * ((adxh * bdy.tail + bdyh * adx.tail) - (adyh * bdx.tail + bdxh * ady.tail)) +
          2.0 * (cdxh * cdx.tail + cdyh * cdy.tail) * (adxh * bdyh - adyh * bdxh));
  if (std::abs(det) >= bound) return det;

  // Stage D: the determinant of the exact differences.
  const Expansion<2> ax = from_two_term(adx), ay = from_two_term(ady);
  const Expansion<2> bx = from_two_term(bdx), by = from_two_term(bdy);
  const Expansion<2> cx = from_two_term(cdx), cy = from_two_term(cdy);
  const auto exact = (exact_minor(bx, by, cx, cy) * (ax * ax + ay * ay) +
                      exact_minor(cx, cy, ax, ay) * (bx * bx + by * by)) +
                     exact_minor(ax, ay, bx, by) * (cx * cx + cy * cy);
  return exact.top();
}

double insphere_adapt(const double* a, const double* b, const double* c, const double* d, const double* e,
                      double permanent) {
  const std::array<const double*, 5> points{a, b, c, d, e};
  if (!fits_expansions<5, 3>(points))
    return with_big_integers<5, 3>(
        points, [](const auto& p) { return insphere_formula(p[0], p[1], p[2], p[3], p[4]); });

  const TwoTerm aex = two_diff(a[0], e[0]), aey = two_diff(a[1], e[1]), aez = two_diff(a[2], e[2]);
  const TwoTerm bex = two_diff(b[0], e[0]), bey = two_diff(b[1], e[1]), bez = two_diff(b[2], e[2]);
  const TwoTerm cex = two_diff(c[0], e[0]), cey = two_diff(c[1], e[1]), cez = two_diff(c[2], e[2]);
  const TwoTerm dex = two_diff(d[0], e[0]), dey = two_diff(d[1], e[1]), dez = two_diff(d[2], e[2]);
  const double ae[3] = {aex.head, aey.head, aez.head}, be[3] = {bex.head, bey.head, bez.head};
  const double ce[3] = {cex.head, cey.head, cez.head}, de[3] = {dex.head, dey.head, dez.head};
  const exact::FourTerm ab4 = cross(ae[0], be[1], be[0], ae[1]), bc4 = cross(be[0], ce[1], ce[0], be[1]);
  const exact::FourTerm cd4 = cross(ce[0], de[1], de[0], ce[1]), da4 = cross(de[0], ae[1], ae[0], de[1]);
  const exact::FourTerm ac4 = cross(ae[0], ce[1], ce[0], ae[1]), bd4 = cross(be[0], de[1], de[0], be[1]);
  double det;
  {
    const auto ab = from_four_term(ab4), bc = from_four_term(bc4), cd = from_four_term(cd4);
    const auto da = from_four_term(da4), ac = from_four_term(ac4), bd = from_four_term(bd4);
    const auto abc = bc * ae[2] - ac * be[2] + ab * ce[2];
    const auto bcd = cd * be[2] - bd * ce[2] + bc * de[2];
    const auto cda = da * ce[2] + ac * de[2] + cd * ae[2];
    const auto dab = ab * de[2] + bd * ae[2] + da * be[2];
    const auto b_det = (times_lift<3>(abc, de) - times_lift<3>(dab, ce)) +
                       (times_lift<3>(cda, be) - times_lift<3>(bcd, ae));
    if (all_zero_tails({aex, aey, aez, bex, bey, bez, cex, cey, cez, dex, dey, dez})) return b_det.top();
    det = b_det.estimate();
    if (std::abs(det) >= kInsphereBoundB * permanent + kUnderflowUnit) return det;
  }

  // Stage C, with Shewchuk's rounded 2x2 minors.
  const double ab3 = ab4.c[3], bc3 = bc4.c[3], cd3 = cd4.c[3], da3 = da4.c[3], ac3 = ac4.c[3], bd3 = bd4.c[3];
  const auto eps = [](const TwoTerm& px, const TwoTerm& py, const TwoTerm& qx, const TwoTerm& qy) {
    return (px.head * qy.tail + qy.head * px.tail) - (py.head * qx.tail + qx.head * py.tail);
  };
  const double abeps = eps(aex, aey, bex, bey), bceps = eps(bex, bey, cex, cey), cdeps = eps(cex, cey, dex, dey);
  const double daeps = eps(dex, dey, aex, aey), aceps = eps(aex, aey, cex, cey), bdeps = eps(bex, bey, dex, dey);
  const auto lift = [](const double* v) { return v[0] * v[0] + v[1] * v[1] + v[2] * v[2]; };
  const auto lift_tail = [](const TwoTerm& x, const TwoTerm& y, const TwoTerm& z) {
    return x.head * x.tail + y.head * y.tail + z.head * z.tail;
  };
  const double bound = kInsphereBoundC * permanent + kResultBound * std::abs(det) + kUnderflowUnit;
  det += ((lift(be) * ((ce[2] * daeps + de[2] * aceps + ae[2] * cdeps) +
                       (cez.tail * da3 + dez.tail * ac3 + aez.tail * cd3)) +
           lift(de) * ((ae[2] * bceps - be[2] * aceps + ce[2] * abeps) +
                       (aez.tail * bc3 - bez.tail * ac3 + cez.tail * ab3))) -
          (lift(ae) * ((be[2] * cdeps - ce[2] * bdeps + de[2] * bceps) +
                       (bez.tail * cd3 - cez.tail * bd3 + dez.tail * bc3)) +
           lift(ce) * ((de[2] * abeps + ae[2] * bdeps + be[2] * daeps) +
                       (dez.tail * ab3 + aez.tail * bd3 + bez.tail * da3)))) +
         2.0 * ((lift_tail(bex, bey, bez) * (ce[2] * da3 + de[2] * ac3 + ae[2] * cd3) +
                 lift_tail(dex, dey, dez) * (ae[2] * bc3 - be[2] * ac3 + ce[2] * ab3)) -
                (lift_tail(aex, aey, aez) * (be[2] * cd3 - ce[2] * bd3 + de[2] * bc3) +
                 lift_tail(cex, cey, cez) * (de[2] * ab3 + ae[2] * bd3 + be[2] * da3)));
  if (std::abs(det) >= bound) return det;

  // Stage D: the exact lifted determinant of the original coordinates.
  const auto lifted =
      (times_lift<3>(lifted_orient3d(a, c, d, e), b) - times_lift<3>(lifted_orient3d(b, c, d, e), a)) +
      (times_lift<3>(lifted_orient3d(a, b, c, e), d) - times_lift<3>(lifted_orient3d(a, b, d, e), c)) -
      times_lift<3>(lifted_orient3d(a, b, c, d), e);
  return lifted.top();
}

}  // namespace detail

double orient2d_fast(const double* a, const double* b, const double* c) { return orient2d_formula(a, b, c); }

double orient3d_fast(const double* a, const double* b, const double* c, const double* d) {
  return orient3d_formula(a, b, c, d);
}

double incircle_fast(const double* a, const double* b, const double* c, const double* d) {
  return incircle_formula(a, b, c, d);
}

double insphere_fast(const double* a, const double* b, const double* c, const double* d, const double* e) {
  return insphere_formula(a, b, c, d, e);
}

}  // namespace geods
