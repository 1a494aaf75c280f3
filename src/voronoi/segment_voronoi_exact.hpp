#pragma once
// Exact evaluation of the signs of the segment Voronoi predicates (internal).
//
// Every quantity the sweep decides on (a circle event's x = centre.x + radius,
// its y, the breakpoint distances of the beach line) is an expression built
// from the snapped integer coordinates (|x| <= 2^25) with +, -, *, / and
// square roots. Its sign is decided in two stages:
//
// 1. Iv: interval arithmetic on doubles, every operation rounded outward by
//    one unit in the last place (round-to-nearest result r widened to
//    r -+ (|r| 2^-52 + 2^-1074), which is at least one ulp whatever the
//    binade, so the exact result stays inside). A sign is returned when the
//    interval excludes 0 (or is the exact point 0); otherwise Uncertain is thrown.
// 2. Bx: the expression as n / d with division-free n and d > 0 (the sign
//    of a divisor is decided exactly before dividing), each a Ball: an MPFR
//    midpoint rounded to nearest at precision p with a rigorous radius 2^e
//    (carried as a log2), together with the BFMSS separation bound of the
//    expression (Burnikel, Fleischer, Mehlhorn, Schirra 2000, as in CORE and
//    LEDA reals): u and l with u(a) = |a|, l(a) = 1 for an integer;
//    E1 +- E2: u = u1 l2 + l1 u2, l = l1 l2; E1 E2: u = u1 u2, l = l1 l2;
//    sqrt(E1): u = sqrt(u1 l1), l = l1; and D the product of the indices of
//    the distinct radicals (2 per square root; the square roots of one integer
//    are one radical; an exact square root of a perfect square is a leaf).
//    If E != 0 then |E| >= 1 / (u^(D-1) l). The sign is the ball's when the
//    ball excludes 0; when it holds 0 and |E| <= |mid| + radius is below the
//    bound, E = 0; otherwise NeedPrecision is thrown and the whole expression
//    is evaluated again at 4x the precision. The bound is finite, so the loop
//    ends (from 192 bits; the deepest case, two point/segment/segment circles
//    compared, can need a few hundred thousand bits when they coincide).
#include <gmp.h>
#include <mpfr.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "geods/core/error.hpp"

namespace geods::voronoi::detail::exact {

struct Uncertain {};
struct NeedPrecision {};

// ---------------------------------------------------------------- double intervals
#define GEODS_EXACT_INLINE [[gnu::always_inline]] inline
GEODS_EXACT_INLINE double round_down(double r) { return r - (std::fabs(r) * 0x1p-52 + 0x1p-1074); }
GEODS_EXACT_INLINE double round_up(double r) { return r + (std::fabs(r) * 0x1p-52 + 0x1p-1074); }

struct Iv {
  double lo = 0, hi = 0;
  Iv() = default;
  explicit Iv(double v) : lo(v), hi(v) {}  // v exact
  Iv(double l, double h) : lo(l), hi(h) {}
  double mid() const { return 0.5 * lo + 0.5 * hi; }
  bool point() const { return lo == hi; }
};
GEODS_EXACT_INLINE Iv operator+(Iv a, Iv b) {
  if (a.point() && b.point()) {  // exact when the two-sum error is 0
    const double s = a.lo + b.lo, bb = s - a.lo, err = (a.lo - (s - bb)) + (b.lo - bb);
    if (err == 0) return Iv(s);
  }
  return {round_down(a.lo + b.lo), round_up(a.hi + b.hi)};
}
GEODS_EXACT_INLINE Iv operator-(Iv a) { return {-a.hi, -a.lo}; }
GEODS_EXACT_INLINE Iv operator-(Iv a, Iv b) { return a + (-b); }
GEODS_EXACT_INLINE Iv operator*(Iv a, Iv b) {
  const double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
  return {round_down(std::min(std::min(p1, p2), std::min(p3, p4))), round_up(std::max(std::max(p1, p2), std::max(p3, p4)))};
}
GEODS_EXACT_INLINE Iv operator/(Iv a, Iv b) {
  if (b.hi < 0) {  // a / b = (-a) / (-b)
    a = -a;
    b = -b;
  } else if (!(b.lo > 0)) {
    throw Uncertain{};
  }
  // b > 0: x / b increases with x; for a fixed x it decreases with b when x >= 0.
  return {round_down(a.lo / (a.lo >= 0 ? b.hi : b.lo)), round_up(a.hi / (a.hi >= 0 ? b.lo : b.hi))};
}
GEODS_EXACT_INLINE Iv sqrt(Iv a) {
  if (a.hi < 0) throw Uncertain{};
  return {std::max(0.0, round_down(std::sqrt(std::max(a.lo, 0.0)))), round_up(std::sqrt(a.hi))};
}
GEODS_EXACT_INLINE int sgn(Iv a) {
  if (a.lo > 0) return 1;
  if (a.hi < 0) return -1;
  if (a.lo == 0 && a.hi == 0) return 0;
  throw Uncertain{};
}

// ---------------------------------------------------------------- MPFR balls with a separation bound
inline thread_local mpfr_prec_t bx_precision = 192;
// The square roots of the current evaluation: integer radicands (below 2^53)
// are shared by value, so that sqrt(dx^2 + dy^2) of one segment is one radical.
inline thread_local int bx_radicals = 0;
inline thread_local double bx_radicands[64];
constexpr double kNegInf = -std::numeric_limits<double>::infinity();

// log2(2^a + 2^b) <= max(a, b) + 1 (a or b may be -inf).
inline double log_add(double a, double b) {
  if (a == kNegInf) return b;
  if (b == kNegInf) return a;
  return std::max(a, b) + 1;
}

// A real number known as an MPFR midpoint and a radius 2^e, with the BFMSS
// parameters of the division-free expression it came from.
class Ball {
 public:
  Ball() {
    mpfr_init2(m_, bx_precision);
    mpfr_set_zero(m_, 1);
  }
  explicit Ball(double v) : Ball() {  // v an integer below 2^53: exact
    mpfr_set_d(m_, v, MPFR_RNDN);
    lu_ = v == 0 ? kNegInf : std::ilogb(std::fabs(v)) + 1.0;
  }
  Ball(const Ball& o) {
    mpfr_init2(m_, mpfr_get_prec(o.m_));
    mpfr_set(m_, o.m_, MPFR_RNDN);
    e_ = o.e_;
    lu_ = o.lu_;
    ll_ = o.ll_;
    rad_ = o.rad_;
  }
  Ball(Ball&& o) noexcept : Ball() { swap(o); }
  Ball& operator=(Ball o) noexcept {
    swap(o);
    return *this;
  }
  ~Ball() { mpfr_clear(m_); }
  void swap(Ball& o) noexcept {
    mpfr_swap(m_, o.m_);
    std::swap(e_, o.e_);
    std::swap(lu_, o.lu_);
    std::swap(ll_, o.ll_);
    std::swap(rad_, o.rad_);
  }
  bool exact() const { return e_ == kNegInf; }
  bool equal_exactly(const Ball& o) const { return exact() && o.exact() && mpfr_equal_p(m_, o.m_); }

  friend Ball operator+(const Ball& a, const Ball& b) { return add(a, b, false); }
  friend Ball operator-(const Ball& a, const Ball& b) { return add(a, b, true); }
  friend Ball operator-(const Ball& a) {
    Ball r(a);
    mpfr_neg(r.m_, r.m_, MPFR_RNDN);
    return r;
  }
  friend Ball operator*(const Ball& a, const Ball& b) {
    Ball r;
    const int t = mpfr_mul(r.m_, a.m_, b.m_, MPFR_RNDN);
    r.e_ = log_add(log_add(mag(a) + b.e_, mag(b) + a.e_), a.e_ + b.e_);
    r.round_error(t);
    r.lu_ = a.lu_ + b.lu_;
    r.ll_ = a.ll_ + b.ll_;
    r.rad_ = a.rad_ | b.rad_;
    return r;
  }
  // Only for converting a result to doubles (its BFMSS parameters are not used).
  friend Ball operator/(const Ball& a, const Ball& b) {
    // |b~| >= 2^(mag-1) and a radius below 2^(mag-2) give |b| >= 2^(mag-2).
    if (mpfr_zero_p(b.m_) || !(b.e_ < mag(b) - 2)) throw NeedPrecision{};
    Ball r;
    const int t = mpfr_div(r.m_, a.m_, b.m_, MPFR_RNDN);
    const double mb = mag(b);
    r.e_ = log_add(a.e_ - (mb - 2), mag(a) + b.e_ - (mb - 2) - (mb - 1));
    r.round_error(t);
    r.lu_ = a.lu_ + b.ll_;
    r.ll_ = a.ll_ + b.lu_;
    r.rad_ = a.rad_ | b.rad_;
    return r;
  }
  friend Ball sqrt(const Ball& a) {  // the caller knows a >= 0
    Ball r;
    int t = 0;
    if (mpfr_sgn(a.m_) > 0) t = mpfr_sqrt(r.m_, a.m_, MPFR_RNDN);
    if (a.exact() && t == 0) {
      // A perfect square (a is then an integer: the expressions are division-free): a leaf.
      r.lu_ = mpfr_zero_p(r.m_) ? kNegInf : mag(r);
      r.ll_ = 0;
      return r;
    }
    if (!a.exact()) {
      // |sqrt(a) - sqrt(a~)| <= sqrt(|a - a~|), and <= |a - a~| / sqrt(a~) when a~ > 0.
      r.e_ = a.e_ / 2;
      if (mpfr_sgn(a.m_) > 0) r.e_ = std::min(r.e_, a.e_ - (mag(a) - 1) / 2);
    }
    r.round_error(t);
    r.lu_ = (a.lu_ + a.ll_ + 1) / 2;
    r.ll_ = a.ll_;
    int bit = -1;
    const bool small_integer = a.exact() && a.rad_ == 0 && mag(a) <= 53;
    const double key = small_integer ? mpfr_get_d(a.m_, MPFR_RNDN) : -1;
    for (int i = 0; small_integer && i < bx_radicals && bit < 0; ++i)
      if (bx_radicands[i] == key) bit = i;
    if (bit < 0) {
      if (bx_radicals >= 64) throw Error("segment Voronoi: too many radicals in an exact predicate");
      bit = bx_radicals++;
      bx_radicands[bit] = key;
    }
    r.rad_ = a.rad_ | (std::uint64_t{1} << bit);
    return r;
  }
  // The exact sign: the ball's when it excludes 0; 0 when |E| is below the
  // BFMSS bound 1 / (u^(D-1) l); otherwise NeedPrecision.
  friend int sgn(const Ball& a) {
    if (!mpfr_zero_p(a.m_) && mag(a) - 1 > a.e_) return mpfr_sgn(a.m_);
    const double bound_mag = log_add(mag(a), a.e_);  // |E| <= |mid| + radius < 2^bound_mag
    const double degree = std::ldexp(1.0, std::popcount(a.rad_));
    const double separation = std::max(a.ll_, 0.0) + std::max(a.lu_, 0.0) * (degree - 1) + 2;
    if (bound_mag < -separation) return 0;
    throw NeedPrecision{};
  }
  double lower() const { return to_double(MPFR_RNDD, -1); }
  double upper() const { return to_double(MPFR_RNDU, 1); }

 private:
  static double mag(const Ball& a) { return mpfr_zero_p(a.m_) ? kNegInf : static_cast<double>(mpfr_get_exp(a.m_)); }
  static Ball add(const Ball& a, const Ball& b, bool subtract) {
    Ball r;
    const int t = subtract ? mpfr_sub(r.m_, a.m_, b.m_, MPFR_RNDN) : mpfr_add(r.m_, a.m_, b.m_, MPFR_RNDN);
    r.e_ = log_add(a.e_, b.e_);
    r.round_error(t);
    r.lu_ = log_add(a.lu_ + b.ll_, a.ll_ + b.lu_);
    r.ll_ = a.ll_ + b.ll_;
    r.rad_ = a.rad_ | b.rad_;
    return r;
  }
  void round_error(int ternary) {
    if (ternary != 0) e_ = log_add(e_, mag(*this) - static_cast<double>(mpfr_get_prec(m_)));
  }
  double to_double(mpfr_rnd_t mode, int dir) const {
    const double v = mpfr_get_d(m_, mode);
    if (exact()) return v;
    const double rad = e_ < -1074 ? 0x1p-1074 : std::ldexp(1.0, static_cast<int>(std::ceil(e_)));
    return dir < 0 ? round_down(v - rad) : round_up(v + rad);
  }

  mpfr_t m_;
  double e_ = kNegInf;            // |value - m_| <= 2^e_
  double lu_ = kNegInf, ll_ = 0;  // log2 of the BFMSS u and l
  std::uint64_t rad_ = 0;         // the square roots in the expression
};

// An exact real as n / d with division-free n and d > 0, so that the BFMSS
// parameters of n stay small (a quotient inside sums would square the l
// parameter at every addition). sqrt(n / d) = sqrt(n d) / d.
class Bx {
 public:
  Bx() : d_(1.0) {}
  explicit Bx(double v) : d_(1.0) {  // v a multiple of 1/4 below 2^51: exact
    double k = 1;
    while (v * k != std::floor(v * k)) k *= 2;
    n_ = Ball(v * k);
    d_ = Ball(k);
  }
  friend Bx operator+(const Bx& a, const Bx& b) { return add(a, b, false); }
  friend Bx operator-(const Bx& a, const Bx& b) { return add(a, b, true); }
  friend Bx operator-(const Bx& a) { return Bx(-a.n_, a.d_); }
  friend Bx operator*(const Bx& a, const Bx& b) {
    return Bx(a.n_ * b.n_, a.d_.equal_exactly(Ball(1.0)) ? b.d_ : b.d_.equal_exactly(Ball(1.0)) ? a.d_ : a.d_ * b.d_);
  }
  friend Bx operator/(const Bx& a, const Bx& b) {  // the caller knows b != 0
    const int s = sgn(b.n_);
    if (s == 0) throw Error("segment Voronoi: division by zero in an exact predicate");
    Ball n = a.n_ * b.d_, d = a.d_ * b.n_;
    return s > 0 ? Bx(std::move(n), std::move(d)) : Bx(-n, -d);
  }
  friend Bx sqrt(const Bx& a) {  // the caller knows a >= 0
    if (a.d_.equal_exactly(Ball(1.0))) return Bx(sqrt(a.n_), a.d_);
    return Bx(sqrt(a.n_ * a.d_), a.d_);
  }
  friend int sgn(const Bx& a) { return sgn(a.n_); }
  double lower() const { return (n_ / d_).lower(); }
  double upper() const { return (n_ / d_).upper(); }

 private:
  Bx(Ball n, Ball d) : n_(std::move(n)), d_(std::move(d)) {}
  static Bx add(const Bx& a, const Bx& b, bool subtract) {
    if (a.d_.equal_exactly(b.d_)) return Bx(subtract ? a.n_ - b.n_ : a.n_ + b.n_, a.d_);
    const Ball l = a.n_ * b.d_, r = b.n_ * a.d_;
    return Bx(subtract ? l - r : l + r, a.d_ * b.d_);
  }
  Ball n_, d_;
};

// The sign of f(type) evaluated exactly with balls: f is called with
// std::type_identity<Bx> and returns a Bx (or throws NeedPrecision through
// sgn() and /, when a branch or a divisor needs more bits).
// Counters of the exact evaluations (for tests and tuning).
struct ExactStats {
  std::uint64_t evaluations = 0, rounds = 0;
  long max_precision = 0;
};
inline thread_local ExactStats exact_stats;

template <class F>
int exact_sign(F&& f) {
  ++exact_stats.evaluations;
  for (mpfr_prec_t p = 192;; p *= 4) {
    ++exact_stats.rounds;
    exact_stats.max_precision = std::max<long>(exact_stats.max_precision, p);
    if (p > (mpfr_prec_t{1} << 26)) throw Error("segment Voronoi: an exact predicate did not converge");
    bx_precision = p;
    bx_radicals = 0;
    try {
      return sgn(f(std::type_identity<Bx>{}));
    } catch (const NeedPrecision&) {
    }
  }
}

// Filter first (f with std::type_identity<Iv>), then exact.
template <class F>
int filtered_sign(F&& f) {
  try {
    return sgn(f(std::type_identity<Iv>{}));
  } catch (const Uncertain&) {
  }
  return exact_sign(f);
}

}  // namespace geods::voronoi::detail::exact
