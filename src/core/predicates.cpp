// Adaptive exact predicates after Shewchuk, "Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates" (1997).
//
// Each predicate runs up to three stages:
//  1. filter: the determinant in plain doubles with Shewchuk's forward error
//     bound, widened by an absolute term that covers underflow (his bound
//     assumes none). Overflow makes the bound inf or NaN, which never passes.
//  2. expansions, when every input lies in an exponent window where no
//     product can overflow or lose bits to underflow: the exact determinant of
//     the rounded coordinate differences (Shewchuk's stage B, exact outright
//     when the differences were), else the exact lifted determinant of the
//     original coordinates (his stage D; his stage C is left out).
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
// Stage 1 constants: Shewchuk's error bounds, in units of the unit roundoff.

constexpr double kEpsilon = 0x1p-53;
constexpr double kOrient2dBoundA = (3.0 + 16.0 * kEpsilon) * kEpsilon;
constexpr double kOrient2dBoundB = (2.0 + 12.0 * kEpsilon) * kEpsilon;
constexpr double kOrient3dBoundA = (7.0 + 56.0 * kEpsilon) * kEpsilon;
constexpr double kOrient3dBoundB = (3.0 + 28.0 * kEpsilon) * kEpsilon;
constexpr double kIncircleBoundA = (10.0 + 96.0 * kEpsilon) * kEpsilon;
constexpr double kIncircleBoundB = (4.0 + 48.0 * kEpsilon) * kEpsilon;
constexpr double kInsphereBoundA = (16.0 + 224.0 * kEpsilon) * kEpsilon;
constexpr double kInsphereBoundB = (5.0 + 72.0 * kEpsilon) * kEpsilon;

// A product that underflows is off by up to eta = 2^-1075 in absolute terms,
// and later products scale that error by their other factors. The filters add
// kUnderflowUnit times a bound on those factors (at least 1); the worst case,
// insphere, needs eta * (8 L Z + 12 L + 12 M + 4), with L the sum of the
// lifts, Z of the |z| differences and M of the 3x3 minor permanents. The unit
// is far above 32 eta so that the term stays a normal number: subnormal
// results are very slow on x86. It only sends determinants below about
// 1e-301 to the exact stages.
constexpr double kUnderflowUnit = 0x1p-1000;

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

struct SplitDouble {
  std::uint64_t odd_significand;
  int exponent;  // of its lowest bit
};

SplitDouble split(double x) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  const int biased = int((bits >> 52) & 0x7ff);
  std::uint64_t significand = bits & ((std::uint64_t(1) << 52) - 1);
  int exponent = -1074;
  if (biased != 0) {
    significand |= std::uint64_t(1) << 52;
    exponent = biased - 1075;
  }
  const int zeros = std::countr_zero(significand);
  return {significand >> zeros, exponent + zeros};
}

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
// Exact lifted determinants on the original coordinates (stage D). With the
// homogeneous coordinate 1 appended, orient2d = det3[x y 1], orient3d =
// det4[x y z 1], incircle = det4[x y |p|^2 1], insphere = det5[x y z |p|^2 1].

Expansion<4> minor2(const double* p, const double* q) { return product(p[0], q[1]) - product(q[0], p[1]); }

Expansion<12> lifted_orient2d(const double* a, const double* b, const double* c) {
  return minor2(a, b) + minor2(b, c) + minor2(c, a);
}

// det3 of the rows p, q, r (x, y, z), expanded along z.
Expansion<24> minor3(const double* p, const double* q, const double* r) {
  return minor2(q, r) * p[2] - minor2(p, r) * q[2] + minor2(p, q) * r[2];
}

Expansion<96> lifted_orient3d(const double* a, const double* b, const double* c, const double* d) {
  return (minor3(a, c, d) - minor3(b, c, d)) + (minor3(a, b, c) - minor3(a, b, d));
}

// m * |p|^2 over the first Dim coordinates of p (or of a difference vector).
template <int Dim, int N>
Expansion<Dim * 4 * N> times_lift(const Expansion<N>& m, const double* p) {
  if constexpr (Dim == 2) {
    return (m * p[0]) * p[0] + (m * p[1]) * p[1];
  } else {
    return (m * p[0]) * p[0] + (m * p[1]) * p[1] + (m * p[2]) * p[2];
  }
}

// ---------------------------------------------------------------------------
// The slow paths of each predicate (stages 2 and 3), out of line so that the
// filters stay small. `permanent` is the filter's, for Shewchuk's stage B bound.

bool all_zero_tails(std::initializer_list<TwoTerm> differences) {
  for (const TwoTerm& t : differences)
    if (t.tail != 0.0) return false;
  return true;
}

[[gnu::noinline]] double orient2d_slow(const double* a, const double* b, const double* c, double permanent) {
  const std::array<const double*, 3> points{a, b, c};
  if (!fits_expansions<2, 2>(points))
    return with_big_integers<2, 2>(points, [](const auto& p) { return orient2d_formula(p[0], p[1], p[2]); });

  const TwoTerm acx = two_diff(a[0], c[0]), acy = two_diff(a[1], c[1]);
  const TwoTerm bcx = two_diff(b[0], c[0]), bcy = two_diff(b[1], c[1]);
  const auto det = product(acx.head, bcy.head) - product(acy.head, bcx.head);
  if (all_zero_tails({acx, acy, bcx, bcy})) return det.top();
  const double estimate = det.estimate();
  if (std::abs(estimate) >= kOrient2dBoundB * permanent) return estimate;
  return lifted_orient2d(a, b, c).top();
}

[[gnu::noinline]] double orient3d_slow(const double* a, const double* b, const double* c, const double* d,
                                       double permanent) {
  const std::array<const double*, 4> points{a, b, c, d};
  if (!fits_expansions<3, 3>(points))
    return with_big_integers<3, 3>(points,
                                   [](const auto& p) { return orient3d_formula(p[0], p[1], p[2], p[3]); });

  const TwoTerm adx = two_diff(a[0], d[0]), ady = two_diff(a[1], d[1]), adz = two_diff(a[2], d[2]);
  const TwoTerm bdx = two_diff(b[0], d[0]), bdy = two_diff(b[1], d[1]), bdz = two_diff(b[2], d[2]);
  const TwoTerm cdx = two_diff(c[0], d[0]), cdy = two_diff(c[1], d[1]), cdz = two_diff(c[2], d[2]);
  const auto bc = product(bdx.head, cdy.head) - product(cdx.head, bdy.head);
  const auto ca = product(cdx.head, ady.head) - product(adx.head, cdy.head);
  const auto ab = product(adx.head, bdy.head) - product(bdx.head, ady.head);
  const auto det = bc * adz.head + ca * bdz.head + ab * cdz.head;
  if (all_zero_tails({adx, ady, adz, bdx, bdy, bdz, cdx, cdy, cdz})) return det.top();
  const double estimate = det.estimate();
  if (std::abs(estimate) >= kOrient3dBoundB * permanent) return estimate;
  return lifted_orient3d(a, b, c, d).top();
}

[[gnu::noinline]] double incircle_slow(const double* a, const double* b, const double* c, const double* d,
                                       double permanent) {
  const std::array<const double*, 4> points{a, b, c, d};
  if (!fits_expansions<4, 2>(points))
    return with_big_integers<4, 2>(points,
                                   [](const auto& p) { return incircle_formula(p[0], p[1], p[2], p[3]); });

  const TwoTerm adx = two_diff(a[0], d[0]), ady = two_diff(a[1], d[1]);
  const TwoTerm bdx = two_diff(b[0], d[0]), bdy = two_diff(b[1], d[1]);
  const TwoTerm cdx = two_diff(c[0], d[0]), cdy = two_diff(c[1], d[1]);
  const double ad[2] = {adx.head, ady.head}, bd[2] = {bdx.head, bdy.head}, cd[2] = {cdx.head, cdy.head};
  const auto bc = product(bdx.head, cdy.head) - product(cdx.head, bdy.head);
  const auto ca = product(cdx.head, ady.head) - product(adx.head, cdy.head);
  const auto ab = product(adx.head, bdy.head) - product(bdx.head, ady.head);
  const auto det = times_lift<2>(bc, ad) + times_lift<2>(ca, bd) + times_lift<2>(ab, cd);
  if (all_zero_tails({adx, ady, bdx, bdy, cdx, cdy})) return det.top();
  const double estimate = det.estimate();
  if (std::abs(estimate) >= kIncircleBoundB * permanent) return estimate;

  const auto lifted = (times_lift<2>(lifted_orient2d(b, c, d), a) - times_lift<2>(lifted_orient2d(a, c, d), b)) +
                      (times_lift<2>(lifted_orient2d(a, b, d), c) - times_lift<2>(lifted_orient2d(a, b, c), d));
  return lifted.top();
}

[[gnu::noinline]] double insphere_slow(const double* a, const double* b, const double* c, const double* d,
                                       const double* e, double permanent) {
  const std::array<const double*, 5> points{a, b, c, d, e};
  if (!fits_expansions<5, 3>(points))
    return with_big_integers<5, 3>(
        points, [](const auto& p) { return insphere_formula(p[0], p[1], p[2], p[3], p[4]); });

  const TwoTerm aex = two_diff(a[0], e[0]), aey = two_diff(a[1], e[1]), aez = two_diff(a[2], e[2]);
  const TwoTerm bex = two_diff(b[0], e[0]), bey = two_diff(b[1], e[1]), bez = two_diff(b[2], e[2]);
  const TwoTerm cex = two_diff(c[0], e[0]), cey = two_diff(c[1], e[1]), cez = two_diff(c[2], e[2]);
  const TwoTerm dex = two_diff(d[0], e[0]), dey = two_diff(d[1], e[1]), dez = two_diff(d[2], e[2]);
  {
    const double ae[3] = {aex.head, aey.head, aez.head}, be[3] = {bex.head, bey.head, bez.head};
    const double ce[3] = {cex.head, cey.head, cez.head}, de[3] = {dex.head, dey.head, dez.head};
    const auto ab = minor2(ae, be), bc = minor2(be, ce), cd = minor2(ce, de);
    const auto da = minor2(de, ae), ac = minor2(ae, ce), bd = minor2(be, de);
    const auto abc = bc * ae[2] - ac * be[2] + ab * ce[2];
    const auto bcd = cd * be[2] - bd * ce[2] + bc * de[2];
    const auto cda = da * ce[2] + ac * de[2] + cd * ae[2];
    const auto dab = ab * de[2] + bd * ae[2] + da * be[2];
    const auto det = (times_lift<3>(abc, de) - times_lift<3>(dab, ce)) +
                     (times_lift<3>(cda, be) - times_lift<3>(bcd, ae));
    if (all_zero_tails({aex, aey, aez, bex, bey, bez, cex, cey, cez, dex, dey, dez})) return det.top();
    const double estimate = det.estimate();
    if (std::abs(estimate) >= kInsphereBoundB * permanent) return estimate;
  }
  const auto lifted =
      (times_lift<3>(lifted_orient3d(a, c, d, e), b) - times_lift<3>(lifted_orient3d(b, c, d, e), a)) +
      (times_lift<3>(lifted_orient3d(a, b, c, e), d) - times_lift<3>(lifted_orient3d(a, b, d, e), c)) -
      times_lift<3>(lifted_orient3d(a, b, c, d), e);
  return lifted.top();
}

}  // namespace

// ---------------------------------------------------------------------------
// The filters (stage 1): Shewchuk's formulas and permanents.

double orient2d(const double* a, const double* b, const double* c) {
  const double acx = a[0] - c[0], acy = a[1] - c[1];
  const double bcx = b[0] - c[0], bcy = b[1] - c[1];
  const double left = acx * bcy, right = acy * bcx;
  const double det = left - right;
  const double permanent = std::abs(left) + std::abs(right);
  if (std::abs(det) > kOrient2dBoundA * permanent + kUnderflowUnit) [[likely]]
    return det;
  return orient2d_slow(a, b, c, permanent);
}

double orient3d(const double* a, const double* b, const double* c, const double* d) {
  const double adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
  const double bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double az = std::abs(adz), bz = std::abs(bdz), cz = std::abs(cdz);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * az +
                           (std::abs(cdxady) + std::abs(adxcdy)) * bz +
                           (std::abs(adxbdy) + std::abs(bdxady)) * cz;
  const double underflow = (az + bz + cz + 1.0) * kUnderflowUnit;
  if (std::abs(det) > kOrient3dBoundA * permanent + underflow) [[likely]]
    return det;
  return orient3d_slow(a, b, c, d, permanent);
}

double incircle(const double* a, const double* b, const double* c, const double* d) {
  const double adx = a[0] - d[0], ady = a[1] - d[1];
  const double bdx = b[0] - d[0], bdy = b[1] - d[1];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1];
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double alift = adx * adx + ady * ady;
  const double blift = bdx * bdx + bdy * bdy;
  const double clift = cdx * cdx + cdy * cdy;
  const double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  const double bc = std::abs(bdxcdy) + std::abs(cdxbdy);
  const double ca = std::abs(cdxady) + std::abs(adxcdy);
  const double ab = std::abs(adxbdy) + std::abs(bdxady);
  const double permanent = bc * alift + ca * blift + ab * clift;
  const double underflow = ((bc + ca + ab) + (alift + blift + clift) + 1.0) * kUnderflowUnit;
  if (std::abs(det) > kIncircleBoundA * permanent + underflow) [[likely]]
    return det;
  return incircle_slow(a, b, c, d, permanent);
}

double insphere(const double* a, const double* b, const double* c, const double* d, const double* e) {
  const double aex = a[0] - e[0], aey = a[1] - e[1], aez = a[2] - e[2];
  const double bex = b[0] - e[0], bey = b[1] - e[1], bez = b[2] - e[2];
  const double cex = c[0] - e[0], cey = c[1] - e[1], cez = c[2] - e[2];
  const double dex = d[0] - e[0], dey = d[1] - e[1], dez = d[2] - e[2];
  const double aexbey = aex * bey, bexaey = bex * aey;
  const double bexcey = bex * cey, cexbey = cex * bey;
  const double cexdey = cex * dey, dexcey = dex * cey;
  const double dexaey = dex * aey, aexdey = aex * dey;
  const double aexcey = aex * cey, cexaey = cex * aey;
  const double bexdey = bex * dey, dexbey = dex * bey;
  const double ab = aexbey - bexaey, bc = bexcey - cexbey, cd = cexdey - dexcey;
  const double da = dexaey - aexdey, ac = aexcey - cexaey, bd = bexdey - dexbey;
  const double abc = aez * bc - bez * ac + cez * ab;
  const double bcd = bez * cd - cez * bd + dez * bc;
  const double cda = cez * da + dez * ac + aez * cd;
  const double dab = dez * ab + aez * bd + bez * da;
  const double alift = aex * aex + aey * aey + aez * aez;
  const double blift = bex * bex + bey * bey + bez * bez;
  const double clift = cex * cex + cey * cey + cez * cez;
  const double dlift = dex * dex + dey * dey + dez * dez;
  const double det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);

  const double az = std::abs(aez), bz = std::abs(bez), cz = std::abs(cez), dz = std::abs(dez);
  const double ab_plus = std::abs(aexbey) + std::abs(bexaey), bc_plus = std::abs(bexcey) + std::abs(cexbey);
  const double cd_plus = std::abs(cexdey) + std::abs(dexcey), da_plus = std::abs(dexaey) + std::abs(aexdey);
  const double ac_plus = std::abs(aexcey) + std::abs(cexaey), bd_plus = std::abs(bexdey) + std::abs(dexbey);
  const double abc_plus = bc_plus * az + ac_plus * bz + ab_plus * cz;
  const double bcd_plus = cd_plus * bz + bd_plus * cz + bc_plus * dz;
  const double cda_plus = da_plus * cz + ac_plus * dz + cd_plus * az;
  const double dab_plus = ab_plus * dz + bd_plus * az + da_plus * bz;
  const double permanent = bcd_plus * alift + cda_plus * blift + dab_plus * clift + abc_plus * dlift;
  const double lifts = (alift + blift) + (clift + dlift);
  const double underflow = (((az + bz) + (cz + dz) + 1.0) * lifts + ((abc_plus + bcd_plus) + (cda_plus + dab_plus)) + 1.0) *
                           kUnderflowUnit;
  if (std::abs(det) > kInsphereBoundA * permanent + underflow) [[likely]]
    return det;
  return insphere_slow(a, b, c, d, e, permanent);
}

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
