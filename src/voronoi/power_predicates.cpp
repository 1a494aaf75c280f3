// The exact power test and its collinear form: a floating-point filter, then
// big integers (coordinates as integers times 2^q, weights times 2^2q).
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "../core/big_int.hpp"
#include "../core/expansion.hpp"
#include "geods/voronoi/power_diagram.hpp"

namespace geods::voronoi {
namespace {

using exact::BigInt;

using exact::SplitDouble;
constexpr auto split = exact::split_double;

int floor_half(int e) { return e >= 0 ? e / 2 : -((-e + 1) / 2); }

// N weighted points as big integers: coordinate / 2^q and weight / 2^(2q), with
// q small enough that all are integers. Homogeneous formulas keep their sign.
template <std::size_t N>
struct Integers {
  std::array<BigInt, N> x, y, w;

  Integers(const std::array<const Vec2d*, N>& p, const std::array<double, N>& weights) {
    int q = std::numeric_limits<int>::max();
    for (std::size_t i = 0; i < N; ++i) {
      for (int k = 0; k < 2; ++k)
        if ((*p[i])[k] != 0) q = std::min(q, split((*p[i])[k]).exponent);
      if (weights[i] != 0) q = std::min(q, floor_half(split(weights[i]).exponent));
    }
    if (q == std::numeric_limits<int>::max()) q = 0;
    const auto make = [](double v, int shift) {
      if (v == 0) return BigInt();
      const SplitDouble s = split(v);
      return BigInt::from_shifted(s.odd_significand, s.exponent - shift, v < 0);
    };
    for (std::size_t i = 0; i < N; ++i) {
      x[i] = make((*p[i])[0], q);
      y[i] = make((*p[i])[1], q);
      w[i] = make(weights[i], 2 * q);
    }
  }
};

int exact_power_test(const Vec2d& a, double wa, const Vec2d& b, double wb, const Vec2d& c, double wc, const Vec2d& d,
                     double wd) {
  const Integers<4> v({&a, &b, &c, &d}, {wa, wb, wc, wd});
  const BigInt adx = v.x[0] - v.x[3], ady = v.y[0] - v.y[3];
  const BigInt bdx = v.x[1] - v.x[3], bdy = v.y[1] - v.y[3];
  const BigInt cdx = v.x[2] - v.x[3], cdy = v.y[2] - v.y[3];
  const BigInt alift = adx * adx + ady * ady - (v.w[0] - v.w[3]);
  const BigInt blift = bdx * bdx + bdy * bdy - (v.w[1] - v.w[3]);
  const BigInt clift = cdx * cdx + cdy * cdy - (v.w[2] - v.w[3]);
  return (alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) + clift * (adx * bdy - bdx * ady)).sign();
}

// The exponent window where expansion arithmetic on the degree-4 determinant is
// exact (as predicates.cpp's in_window: every term a multiple of 2^-1074, no
// overflow); weights are of degree 2 and get twice the window.
bool in_window(double x, int degree) {
  if (x == 0) return true;
  const int e = std::ilogb(x);
  return e >= degree * (52 - 1074 / 4) && e <= degree * (1000 / 4 - 3);
}

// Shewchuk's expansions: exact, and fast on the ties of integer grids.
int expansion_power_test(const Vec2d& a, double wa, const Vec2d& b, double wb, const Vec2d& c, double wc,
                         const Vec2d& d, double wd) {
  using exact::Expansion;
  const auto diff = [](double x, double y) { return exact::from_two_term(exact::two_diff(x, y)); };
  const Expansion<2> adx = diff(a[0], d[0]), ady = diff(a[1], d[1]);
  const Expansion<2> bdx = diff(b[0], d[0]), bdy = diff(b[1], d[1]);
  const Expansion<2> cdx = diff(c[0], d[0]), cdy = diff(c[1], d[1]);
  const auto lift = [&](const Expansion<2>& x, const Expansion<2>& y, double w) {
    return (x * x + y * y) - (exact::exact(w) - exact::exact(wd));
  };
  const auto det = lift(adx, ady, wa) * (bdx * cdy - cdx * bdy) + lift(bdx, bdy, wb) * (cdx * ady - adx * cdy) +
                   lift(cdx, cdy, wc) * (adx * bdy - bdx * ady);
  const double top = det.top();
  return (top > 0) - (top < 0);
}

}  // namespace

int power_test(const Vec2d& a, double wa, const Vec2d& b, double wb, const Vec2d& c, double wc, const Vec2d& d,
               double wd) {
  const double adx = a[0] - d[0], ady = a[1] - d[1];
  const double bdx = b[0] - d[0], bdy = b[1] - d[1];
  const double cdx = c[0] - d[0], cdy = c[1] - d[1];
  const double ad = wa - wd, bd = wb - wd, cd = wc - wd;
  const double alift = adx * adx + ady * ady - ad, blift = bdx * bdx + bdy * bdy - bd, clift = cdx * cdx + cdy * cdy - cd;
  const double m_a = bdx * cdy - cdx * bdy, m_b = cdx * ady - adx * cdy, m_c = adx * bdy - bdx * ady;
  const double det = alift * m_a + blift * m_b + clift * m_c;
  // Every rounded operation errs by at most u of its magnitude; the permanent
  // (all terms made positive) bounds the magnitudes, 32 u of it the total error
  // with room to spare; the absolute term covers underflow.
  const double pa = adx * adx + ady * ady + std::abs(wa) + std::abs(wd);
  const double pb = bdx * bdx + bdy * bdy + std::abs(wb) + std::abs(wd);
  const double pc = cdx * cdx + cdy * cdy + std::abs(wc) + std::abs(wd);
  const double permanent = pa * (std::abs(bdx * cdy) + std::abs(cdx * bdy)) +
                           pb * (std::abs(cdx * ady) + std::abs(adx * cdy)) +
                           pc * (std::abs(adx * bdy) + std::abs(bdx * ady));
  const double bound = 32 * std::numeric_limits<double>::epsilon() * permanent + 1e-300;
  if (det > bound) return 1;   // false for NaN or inf: those go the exact way
  if (det < -bound) return -1;
  bool window = true;
  for (const Vec2d* p : {&a, &b, &c, &d}) window &= in_window((*p)[0], 1) && in_window((*p)[1], 1);
  for (double w : {wa, wb, wc, wd}) window &= in_window(w, 2);
  if (window) return expansion_power_test(a, wa, b, wb, c, wc, d, wd);
  return exact_power_test(a, wa, b, wb, c, wc, d, wd);
}

int collinear_power_test(const Vec2d& a, double wa, const Vec2d& m, double wm, const Vec2d& b, double wb) {
  const Integers<3> v({&a, &m, &b}, {wa, wm, wb});
  const int axis = a[0] != b[0] ? 0 : 1;
  const auto& u = axis == 0 ? v.x : v.y;
  const auto lift = [&](std::size_t i) { return v.x[i] * v.x[i] + v.y[i] * v.y[i] - v.w[i]; };
  // lift(m) (ub - ua) - lift(a) (ub - um) - lift(b) (um - ua): negative (for ub > ua) when m is below.
  const BigInt e = lift(1) * (u[2] - u[0]) - lift(0) * (u[2] - u[1]) - lift(2) * (u[1] - u[0]);
  const int direction = (u[2] - u[0]).sign();
  return -e.sign() * direction;
}

}  // namespace geods::voronoi
