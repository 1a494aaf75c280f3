#pragma once
// The coordinates a floating-point computation on points can take. Distances,
// circumcentres and the like are polynomials in coordinate differences: one of
// degree k overflows when the coordinates reach about 2^(max_exponent / k), and
// loses the differences of a point set whose extent E is so small that
// (E * 2^-digits)^k falls below the smallest normal number. Structures that
// compute such polynomials in T check their input here and refuse, with a
// clear geods::Error, what they would otherwise answer wrongly (points scaled
// by 1e300 or 1e-300). The exact predicates need no such range.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

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

/// What one pass over n points of `dim` coordinates (row i at coords[i *
/// stride]) finds: whether every coordinate is finite and within +-limit, and
/// the largest extent of the points' bounding box (meaningful when they are).
template <typename T>
struct CoordinateScan {
  bool finite_within = true;
  T extent = 0;
};

namespace detail {
// Widens lo/hi (dim values each) by the rows [begin, end); false if one of
// their coordinates is not finite or lies beyond +-limit. No early exit and no
// throw inside the loop, so it compiles to straight compare and min/max code
// (D > 0: the dimension, fixed). NaN fails the comparison and leaves lo/hi.
template <int D, typename T>
bool scan_rows(const T* coords, std::size_t begin, std::size_t end, std::size_t dim, std::size_t stride, T limit,
               T* lo, T* hi) {
  bool within = true;
  auto rows = [&](std::size_t d, T* l, T* h) {
    for (std::size_t i = begin; i < end; ++i) {
      const T* p = coords + i * stride;
      for (std::size_t a = 0; a < d; ++a) {
        const T x = p[a];
        within &= std::abs(x) <= limit;
        l[a] = std::min(l[a], x);
        h[a] = std::max(h[a], x);
      }
    }
  };
  if constexpr (D > 0) {  // in registers: lo and hi could alias coords
    std::array<T, D> l, h;
    std::copy_n(lo, D, l.begin());
    std::copy_n(hi, D, h.begin());
    rows(D, l.data(), h.data());
    std::copy_n(l.begin(), D, lo);
    std::copy_n(h.begin(), D, hi);
  } else {
    rows(dim, lo, hi);
  }
  return within;
}
}  // namespace detail

/// The pass of CoordinateScan, split over the threads for many points.
template <typename T>
CoordinateScan<T> scan_coordinates(const T* coords, std::size_t n, std::size_t dim, std::size_t stride, T limit) {
  CoordinateScan<T> scan;
  if (n == 0 || dim == 0) return scan;
  constexpr std::size_t kRows = 65536;  // rows per chunk
  const std::size_t chunks = (n + kRows - 1) / kRows;
  std::vector<T> lo(chunks * dim), hi(chunks * dim);
  std::vector<char> within(chunks);
  parallel_for(0, chunks, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) {
      const std::size_t first = c * kRows, last = std::min(n, first + kRows);
      T* l = lo.data() + c * dim;
      T* h = hi.data() + c * dim;
      std::copy_n(coords + first * stride, dim, l);
      std::copy_n(coords + first * stride, dim, h);
      if (dim == 2)
        within[c] = detail::scan_rows<2>(coords, first, last, dim, stride, limit, l, h);
      else if (dim == 3)
        within[c] = detail::scan_rows<3>(coords, first, last, dim, stride, limit, l, h);
      else
        within[c] = detail::scan_rows<0>(coords, first, last, dim, stride, limit, l, h);
    }
  });
  for (std::size_t c = 0; c < chunks; ++c) scan.finite_within &= bool(within[c]);
  for (std::size_t a = 0; a < dim; ++a) {
    T l = lo[a], h = hi[a];
    for (std::size_t c = 1; c < chunks; ++c) {
      l = std::min(l, lo[c * dim + a]);
      h = std::max(h, hi[c * dim + a]);
    }
    scan.extent = std::max(scan.extent, h - l);
  }
  return scan;
}

/// Throws geods::Error "<what>: ..." if a point set's largest extent is above
/// zero but below `floor` (its distances would underflow).
template <typename T>
void check_coordinate_extent(T extent, T floor, const std::string& what) {
  if (extent > 0 && extent < floor)
    throw Error(what + ": the points span only " + format_number(double(extent)) + " (below " +
                format_number(double(floor)) + "), where their distances underflow; scale the input");
}

/// Checks that n points of `dim` coordinates (row i at coords[i * stride])
/// lie within +-limit and that their bounding box's largest extent is zero or
/// at least `floor`. Throws geods::Error "<what>: ..." saying which and why.
/// Non-finite coordinates are the caller's to refuse (with their own message).
template <typename T>
void check_coordinate_range(const T* coords, std::size_t n, std::size_t dim, std::size_t stride, T limit, T floor,
                            const std::string& what) {
  if (n == 0 || dim == 0) return;
  CoordinateScan<T> scan = scan_coordinates(coords, n, dim, stride, limit);
  if (!scan.finite_within) {  // name the first coordinate beyond the limit, axis by axis; NaN passes here
    scan.extent = 0;
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
      scan.extent = hi - lo > scan.extent ? hi - lo : scan.extent;
    }
  }
  check_coordinate_extent(scan.extent, floor, what);
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
