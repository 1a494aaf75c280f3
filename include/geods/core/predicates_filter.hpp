#pragma once
// The inline half of the exact predicates of geods/core/predicates.hpp: the
// determinant in plain doubles and Shewchuk's forward error bound. Most calls
// end here without a function call; the rest go to the out-of-line adaptive
// stages in src/core/predicates.cpp.
#include <cmath>

namespace geods::detail {

// Shewchuk's error bounds, in units of the unit roundoff.
inline constexpr double kEpsilon = 0x1p-53;
inline constexpr double kOrient2dBoundA = (3.0 + 16.0 * kEpsilon) * kEpsilon;
inline constexpr double kOrient3dBoundA = (7.0 + 56.0 * kEpsilon) * kEpsilon;
inline constexpr double kIncircleBoundA = (10.0 + 96.0 * kEpsilon) * kEpsilon;
inline constexpr double kInsphereBoundA = (16.0 + 224.0 * kEpsilon) * kEpsilon;

// Shewchuk's bounds assume no underflow. A product that underflows is off by
// up to eta = 2^-1075 in absolute terms, and later products scale that error
// by their other factors. The filters add kUnderflowUnit times a bound on
// those factors (at least 1); the worst case, insphere, needs
// eta * (8 L Z + 12 L + 12 M + 4), with L the sum of the lifts, Z of the |z|
// differences and M of the 3x3 minor permanents. The unit is far above
// 32 eta so that the term stays a normal number: subnormal results are very
// slow on x86. It only sends determinants below about 1e-301 to the exact
// stages. Overflow makes a bound inf or NaN, which never passes.
inline constexpr double kUnderflowUnit = 0x1p-1000;

// The adaptive stages, for the calls the filters cannot decide; `permanent`
// is the filter's, which the later error bounds are relative to.
[[gnu::noinline]] double orient2d_adapt(const double* a, const double* b, const double* c, double permanent);
[[gnu::noinline]] double orient3d_adapt(const double* a, const double* b, const double* c, const double* d,
                                        double permanent);
[[gnu::noinline]] double incircle_adapt(const double* a, const double* b, const double* c, const double* d,
                                        double permanent);
[[gnu::noinline]] double insphere_adapt(const double* a, const double* b, const double* c, const double* d,
                                        const double* e, double permanent);

inline double orient2d_filter(const double* a, const double* b, const double* c) {
  const double acx = a[0] - c[0], acy = a[1] - c[1];
  const double bcx = b[0] - c[0], bcy = b[1] - c[1];
  const double left = acx * bcy, right = acy * bcx;
  const double det = left - right;
  const double permanent = std::abs(left) + std::abs(right);
  if (std::abs(det) > kOrient2dBoundA * permanent + kUnderflowUnit) [[likely]]
    return det;
  return orient2d_adapt(a, b, c, permanent);
}

inline double orient3d_filter(const double* a, const double* b, const double* c, const double* d) {
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
  return orient3d_adapt(a, b, c, d, permanent);
}

inline double incircle_filter(const double* a, const double* b, const double* c, const double* d) {
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
  return incircle_adapt(a, b, c, d, permanent);
}

inline double insphere_filter(const double* a, const double* b, const double* c, const double* d,
                              const double* e) {
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
  const double underflow =
      (((az + bz) + (cz + dz) + 1.0) * lifts + ((abc_plus + bcd_plus) + (cda_plus + dab_plus)) + 1.0) *
      kUnderflowUnit;
  if (std::abs(det) > kInsphereBoundA * permanent + underflow) [[likely]]
    return det;
  return insphere_adapt(a, b, c, d, e, permanent);
}

}  // namespace geods::detail
