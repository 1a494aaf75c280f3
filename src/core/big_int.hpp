#pragma once
// A small signed arbitrary-precision integer: just enough (add, subtract,
// multiply, sign, conversion to double) for the last-resort exact path of the
// predicates, where doubles span the whole exponent range and floating-point
// expansions could overflow or underflow. Schoolbook algorithms on 64-bit
// limbs; the numbers there have at most a few hundred limbs.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace geods::exact {

/// A finite nonzero double as odd_significand * 2^exponent: the integer it
/// scales to when every value of a formula is shifted by the smallest exponent.
struct SplitDouble {
  std::uint64_t odd_significand;
  int exponent;  // of its lowest bit
};

inline SplitDouble split_double(double x) {
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

class BigInt {
 public:
  BigInt() = default;

  /// magnitude * 2^shift with the given sign; shift >= 0.
  static BigInt from_shifted(std::uint64_t magnitude, int shift, bool negative) {
    BigInt r;
    if (magnitude == 0) return r;
    r.negative_ = negative;
    r.limbs_.assign(std::size_t(shift / 64) + 2, 0);
    const int bit = shift % 64;
    r.limbs_[std::size_t(shift / 64)] = magnitude << bit;
    if (bit != 0) r.limbs_[std::size_t(shift / 64) + 1] = magnitude >> (64 - bit);
    r.trim();
    return r;
  }

  int sign() const { return limbs_.empty() ? 0 : (negative_ ? -1 : 1); }

  /// The value times 2^exponent as a double: the sign exactly, the magnitude
  /// to about 1 ulp, clamped to the finite nonzero doubles.
  double to_double_scaled(long exponent) const {
    if (limbs_.empty()) return 0.0;
    const int top_bits = 64 - std::countl_zero(limbs_.back());
    // Leading 128 bits (fewer if the number is short) as a double.
    double lead = double(limbs_.back());
    long lead_exponent = long(limbs_.size() - 1) * 64;
    if (limbs_.size() >= 2) {
      lead = std::ldexp(lead, 64) + double(limbs_[limbs_.size() - 2]);
      lead_exponent -= 64;
    }
    const long magnitude_exponent = long(limbs_.size() - 1) * 64 + top_bits + exponent;  // value < 2^this
    double m;
    if (magnitude_exponent > 1024) {
      m = std::numeric_limits<double>::max();
    } else if (magnitude_exponent < -1074) {
      m = std::numeric_limits<double>::denorm_min();
    } else {
      m = std::ldexp(lead, int(lead_exponent + exponent));
      if (std::isinf(m)) m = std::numeric_limits<double>::max();
      if (m == 0.0) m = std::numeric_limits<double>::denorm_min();
    }
    return negative_ ? -m : m;
  }

  friend BigInt operator-(BigInt a) {
    if (!a.limbs_.empty()) a.negative_ = !a.negative_;
    return a;
  }
  friend BigInt operator+(const BigInt& a, const BigInt& b) { return add(a, b, b.negative_); }
  friend BigInt operator-(const BigInt& a, const BigInt& b) { return add(a, b, !b.negative_); }

  friend BigInt operator*(const BigInt& a, const BigInt& b) {
    BigInt r;
    if (a.limbs_.empty() || b.limbs_.empty()) return r;
    r.limbs_.assign(a.limbs_.size() + b.limbs_.size(), 0);
    for (std::size_t i = 0; i < a.limbs_.size(); ++i) {
      std::uint64_t carry = 0;
      for (std::size_t j = 0; j < b.limbs_.size(); ++j) {
        const __uint128_t t = __uint128_t(a.limbs_[i]) * b.limbs_[j] + r.limbs_[i + j] + carry;
        r.limbs_[i + j] = std::uint64_t(t);
        carry = std::uint64_t(t >> 64);
      }
      r.limbs_[i + b.limbs_.size()] = carry;
    }
    r.negative_ = a.negative_ != b.negative_;
    r.trim();
    return r;
  }

 private:
  // a + (b with sign b_negative).
  static BigInt add(const BigInt& a, const BigInt& b, bool b_negative) {
    if (a.negative_ == b_negative || a.limbs_.empty() || b.limbs_.empty()) {
      BigInt r = add_magnitudes(a, b);
      r.negative_ = a.limbs_.empty() ? b_negative : a.negative_;
      r.trim();
      return r;
    }
    // Opposite signs: the larger magnitude minus the smaller, with its sign.
    const bool a_larger = compare_magnitudes(a, b) >= 0;
    BigInt r = a_larger ? subtract_magnitudes(a, b) : subtract_magnitudes(b, a);
    r.negative_ = a_larger ? a.negative_ : b_negative;
    r.trim();
    return r;
  }

  static BigInt add_magnitudes(const BigInt& a, const BigInt& b) {
    const BigInt& longer = a.limbs_.size() >= b.limbs_.size() ? a : b;
    const BigInt& shorter = a.limbs_.size() >= b.limbs_.size() ? b : a;
    BigInt r;
    r.limbs_.resize(longer.limbs_.size() + 1);
    std::uint64_t carry = 0;
    for (std::size_t i = 0; i < longer.limbs_.size(); ++i) {
      const __uint128_t t =
          __uint128_t(longer.limbs_[i]) + (i < shorter.limbs_.size() ? shorter.limbs_[i] : 0) + carry;
      r.limbs_[i] = std::uint64_t(t);
      carry = std::uint64_t(t >> 64);
    }
    r.limbs_.back() = carry;
    return r;
  }

  // |a| - |b| for |a| >= |b|.
  static BigInt subtract_magnitudes(const BigInt& a, const BigInt& b) {
    BigInt r;
    r.limbs_.resize(a.limbs_.size());
    std::uint64_t borrow = 0;
    for (std::size_t i = 0; i < a.limbs_.size(); ++i) {
      const std::uint64_t bi = i < b.limbs_.size() ? b.limbs_[i] : 0;
      const __uint128_t t = __uint128_t(a.limbs_[i]) - bi - borrow;
      r.limbs_[i] = std::uint64_t(t);
      borrow = std::uint64_t(t >> 64) != 0 ? 1 : 0;
    }
    return r;
  }

  static int compare_magnitudes(const BigInt& a, const BigInt& b) {
    if (a.limbs_.size() != b.limbs_.size()) return a.limbs_.size() < b.limbs_.size() ? -1 : 1;
    for (std::size_t i = a.limbs_.size(); i-- > 0;)
      if (a.limbs_[i] != b.limbs_[i]) return a.limbs_[i] < b.limbs_[i] ? -1 : 1;
    return 0;
  }

  // Drops leading zero limbs; zero is the empty vector and never negative.
  void trim() {
    while (!limbs_.empty() && limbs_.back() == 0) limbs_.pop_back();
    if (limbs_.empty()) negative_ = false;
  }

  std::vector<std::uint64_t> limbs_;  // magnitude, least significant first
  bool negative_ = false;
};

}  // namespace geods::exact
