#pragma once
// The coordinates a floating-point computation on points can take. Distances,
// circumcentres and the like are polynomials in coordinate differences: one of
// degree k overflows when the coordinates reach about 2^(max_exponent / k), and
// loses the differences of a point set whose extent E is so small that
// (E * 2^-digits)^k falls below the smallest normal number. Structures that
// compute such polynomials in T check their input here and refuse, with a
// clear geods::Error, what they would otherwise answer wrongly (points scaled
// by 1e300 or 1e-300). The exact predicates need no such range.
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>

#include "geods/core/error.hpp"

namespace geods {

/// 2^e, exactly, in a constant expression (std::ldexp is not constexpr).
template <typename T>
constexpr T power_of_two(int e) {
  T r = 1;
  for (; e > 0; --e) r *= 2;
  for (; e < 0; ++e) r /= 2;
  return r;
}

/// The largest |coordinate| for which polynomials of the given degree in
/// coordinate differences (summed over up to 2^16 terms) stay finite in T:
/// 2^502 (1.3e151) for distances in double, 2^54 (1.8e16) in float, 2^334
/// (3.5e100) for circumcentres in double.
template <typename T>
constexpr T coordinate_limit(int degree) {
  return power_of_two<T>((std::numeric_limits<T>::max_exponent - 18) / degree - 1);
}

/// The smallest extent of a point set whose resolvable differences
/// (extent * 2^-digits) still have a normal k-th power in T: 2^-458 for
/// distances in double, 2^-39 in float.
template <typename T>
constexpr T extent_floor(int degree) {
  const int min_exponent = std::numeric_limits<T>::min_exponent - 1;
  return power_of_two<T>(-(-min_exponent / degree) + std::numeric_limits<T>::digits);
}

/// Checks that n points of `dim` coordinates (row i at coords[i * stride])
/// lie within +-limit and that their bounding box's largest extent is zero or
/// at least `floor`. Throws geods::Error "<what>: ..." saying which and why.
/// Non-finite coordinates are the caller's to refuse (with their own message).
template <typename T>
void check_coordinate_range(const T* coords, std::size_t n, std::size_t dim, std::size_t stride, T limit, T floor,
                            const std::string& what) {
  if (n == 0 || dim == 0) return;
  T extent = 0;
  for (std::size_t a = 0; a < dim; ++a) {
    T lo = coords[a], hi = coords[a];
    for (std::size_t i = 0; i < n; ++i) {
      const T x = coords[i * stride + a];
      if (std::abs(x) > limit)
        throw Error(what + ": coordinate " + format_number(double(x)) + " of point " + std::to_string(i) +
                    " is beyond +-" + format_number(double(limit)) + ", where its distances would overflow; " +
                    "scale the input");
      lo = x < lo ? x : lo;
      hi = x > hi ? x : hi;
    }
    extent = hi - lo > extent ? hi - lo : extent;
  }
  if (extent > 0 && extent < floor)
    throw Error(what + ": the points span only " + format_number(double(extent)) + " (below " +
                format_number(double(floor)) + "), where their distances underflow; scale the input");
}

/// check_coordinate_range for polynomials of `degree` in T: coordinate_limit
/// and extent_floor.
template <typename T>
void check_coordinate_range(const T* coords, std::size_t n, std::size_t dim, std::size_t stride, int degree,
                            const std::string& what) {
  check_coordinate_range(coords, n, dim, stride, coordinate_limit<T>(degree), extent_floor<T>(degree), what);
}

namespace detail {
// The error of check_query_range, out of line: the check itself runs on every
// query (every ray), and with the message built inline GCC called it instead
// of inlining it.
template <typename T>
[[noreturn, gnu::cold, gnu::noinline]] void throw_query_beyond(std::span<const T> q, T limit, const char* what) {
  T x = 0;
  for (T c : q)
    if (std::abs(c) > limit) {
      x = c;
      break;
    }
  throw Error(std::string(what) + ": query coordinate " + format_number(double(x)) + " is beyond +-" +
              format_number(double(limit)) + ", where its distances would overflow");
}
}  // namespace detail

/// Checks one query point against +-limit (a far query's distances overflow
/// like a far point's). NaN coordinates pass: they are the caller's to refuse.
template <typename T>
inline void check_query_range(std::span<const T> q, T limit, const char* what) {
  bool beyond = false;
  for (T x : q) beyond |= std::abs(x) > limit;
  if (beyond) [[unlikely]]
    detail::throw_query_beyond(q, limit, what);
}

/// check_query_range against coordinate_limit. On the query path: the limit is a constant.
template <int Degree, typename T>
void check_query_range(std::span<const T> q, const char* what) {
  constexpr T limit = coordinate_limit<T>(Degree);
  check_query_range(q, limit, what);
}

}  // namespace geods
