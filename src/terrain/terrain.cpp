// The 4-8 hierarchy of Lindstrom & Pascucci: exact nested errors, nested
// bounding spheres, the interleaved quadtree layout, refinement into one
// triangle strip and a triangle list, tiles, and the mapped terrain file.
#include "geods/terrain/terrain.hpp"

#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "geods/core/default_init_allocator.hpp"
#include "geods/core/error.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/core/parallel.hpp"
#include "triangle_raster.hpp"

namespace geods::terrain {
namespace {

using detail::P2;
using detail::triangle_error;

constexpr float kInf = std::numeric_limits<float>::infinity();

// The smallest float >= v, for v >= 0 (or +inf).
float round_up(double v) {
  const float f = float(v);
  return std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) + std::uint32_t(double(f) < v));  // no branch
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

#if defined(__x86_64__) && defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// rows_error<0>() with AVX-512: every row by row_max8(), short ones too (one
// masked block), the rows' terms kept in two vectors and reduced once per
// triangle instead of once per row.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) double rows_error_avx512(const float* z, std::int64_t n, const detail::Plane& p,
                                                                                P2 a, std::int64_t r0, std::int64_t rows,
                                                                                std::int64_t lo0, std::int64_t dlo, std::int64_t hi0,
                                                                                std::int64_t dhi) {
  __m512d m0 = _mm512_setzero_pd(), m1 = _mm512_setzero_pd();
  for (std::int64_t r = 0; r < rows; ++r) {
    const std::int64_t dy = r0 + r;
    detail::row_max8(z + (a.y + dy) * n, a.x + lo0 + dlo * r, a.x + hi0 + dhi * r, p.base(dy), p.gx, a.x, m0, m1);
  }
  return _mm512_reduce_max_pd(_mm512_max_pd(m0, m1));
}
#pragma GCC diagnostic pop
#endif

// The largest |z - plane| over the samples of a triangle whose corner a is the
// plane's origin: rows a.y + r0 + r for r in [0, rows), row r covering
// x in [a.x + lo0 + dlo r, a.x + hi0 + dhi r]. Every term rounded as
// triangle_error() rounds it, so the same value.
template <int S>
[[gnu::always_inline]] inline double rows_error(const float* z, std::int64_t n, const detail::Plane& p, P2 a,
                                               std::int64_t r0, std::int64_t rows, std::int64_t lo0, std::int64_t dlo,
                                               std::int64_t hi0, std::int64_t dhi) {
  double m = 0;
#if defined(__x86_64__) && defined(__GNUC__)
  const bool avx2 = S == 0 && simd_level() >= SimdLevel::avx2;  // long rows only
  const bool avx512 = avx2 && simd_level() >= SimdLevel::avx512;
  if (avx512) return rows_error_avx512(z, n, p, a, r0, rows, lo0, dlo, hi0, dhi);
#endif
#if defined(__SSE2__)
  __m128d m2 = _mm_setzero_pd();
  const __m128d sign = _mm_set1_pd(-0.0), gx = _mm_set1_pd(p.gx);
#endif
  for (std::int64_t r = 0; r < rows; ++r) {
    const std::int64_t dy = r0 + r;
    const float* row = z + (a.y + dy) * n;
    if constexpr (S > 0) {  // spans of at most 2 S + 1 samples: straight-line code
      const double base = p.base(dy);
      std::int64_t dx = lo0 + dlo * r;
      const std::int64_t hi = hi0 + dhi * r;
#if defined(__SSE2__)
      const __m128d b2 = _mm_set1_pd(base);
      for (; dx + 1 <= hi; dx += 2) {  // two neighbours at a time
        const __m128d h = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + a.x + dx))));
        const __m128d x2 = _mm_set_pd(double(dx + 1), double(dx));
        m2 = _mm_max_pd(_mm_andnot_pd(sign, _mm_sub_pd(h, _mm_add_pd(b2, _mm_mul_pd(gx, x2)))), m2);
      }
#endif
      for (; dx <= hi; ++dx) {
        const double d = std::abs(double(row[a.x + dx]) - (base + p.gx * double(dx)));
        m = std::max(m, d);  // maxsd, no branch
      }
    } else {
      const std::int64_t lo = a.x + lo0 + dlo * r, hi = a.x + hi0 + dhi * r;
#if defined(__x86_64__) && defined(__GNUC__)
      if (hi - lo >= 7 && avx2) {
        m = std::max(m, detail::row_max_avx2(row, lo, hi, p.base(dy), p.gx, a.x));
        continue;
      }
#endif
      m = std::max(m, detail::row_max(row, lo, hi, p.base(dy), p.gx, a.x));
    }
  }
#if defined(__SSE2__)
  m = std::max({m, _mm_cvtsd_f64(m2), _mm_cvtsd_f64(_mm_unpackhi_pd(m2, m2))});
#endif
  return m;
}

// The children of a vertex in the nesting: their offsets, as index offsets, and
// their squared horizontal distances.
struct Children {
  std::array<P2, 4> off;
  std::array<std::ptrdiff_t, 4> dw;
  std::array<double, 4> d2;
};

#if defined(__x86_64__) && defined(__GNUC__)
#define GEODS_TERRAIN_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline
// The fine levels with AVX2, four vertices of one kind at a time (the lanes
// St samples apart along a row): the same planes and terms as rows_error<S>,
// lane by lane, so the same errors bit for bit.

// p[0], p[St], p[2 St], p[3 St] (reads up to p[3 St + 3]).
template <int St>
GEODS_TERRAIN_AVX2_INLINE __m128 load4f(const float* p) {
  if constexpr (St == 2) {
    return _mm256_castps256_ps128(_mm256_permutevar8x32_ps(_mm256_loadu_ps(p), _mm256_set_epi32(7, 5, 3, 1, 6, 4, 2, 0)));
  } else if constexpr (St == 4) {  // p0 p0 p8 p8 | p4 p4 p12 p12, then in order
    const __m256 v = _mm256_shuffle_ps(_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8), 0);
    return _mm256_castps256_ps128(_mm256_permutevar8x32_ps(v, _mm256_set_epi32(7, 5, 3, 1, 6, 2, 4, 0)));
  } else {
    return _mm_set_ps(p[3 * St], p[2 * St], p[St], p[0]);
  }
}
template <int St>
GEODS_TERRAIN_AVX2_INLINE __m256d load4(const float* p) {
  return _mm256_cvtps_pd(load4f<St>(p));
}

// p[0], p[St], p[2 St], p[3 St] = v.
template <int St>
GEODS_TERRAIN_AVX2_INLINE void store4f(float* p, __m128 v) {
  alignas(16) float out[4];
  _mm_store_ps(out, v);
  for (int j = 0; j < 4; ++j) p[St * j] = out[j];
}

// round_up() of four doubles.
GEODS_TERRAIN_AVX2_INLINE __m128 round_up4(__m256d m) {
  const __m128 f = _mm256_cvtpd_ps(m);
  const __m256d below = _mm256_cmp_pd(_mm256_cvtps_pd(f), m, _CMP_LT_OQ);  // all ones: one ulp up
  const __m256i low_halves = _mm256_permutevar8x32_epi32(_mm256_castpd_si256(below), _mm256_set_epi32(7, 5, 3, 1, 6, 4, 2, 0));
  return _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(f), _mm_srli_epi32(_mm256_castsi256_si128(low_halves), 31)));
}

// detail::Plane of the corners at offsets a, b, c from the lanes' vertices v.
struct Plane4 {
  const float* a;
  __m256d za, gx, gy;
};
template <int St>
GEODS_TERRAIN_AVX2_INLINE Plane4 plane4(const float* v, std::int64_t n, P2 a, P2 b, P2 c) {
  Plane4 p;
  p.a = v + a.y * n + a.x;
  p.za = load4<St>(p.a);
  const __m256d zb = load4<St>(v + b.y * n + b.x), zc = load4<St>(v + c.y * n + c.x);
  const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
  // det is +-2^k (+-2 s^2 or +-4 s^2): dividing by it is multiplying by 1 / det, exactly.
  const __m256d inv = _mm256_set1_pd(1 / (ux * vy - uy * vx));
  const __m256d db = _mm256_sub_pd(zb, p.za), dc = _mm256_sub_pd(zc, p.za);
  p.gx = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(db, _mm256_set1_pd(vy)), _mm256_mul_pd(dc, _mm256_set1_pd(uy))), inv);
  p.gy = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(dc, _mm256_set1_pd(ux)), _mm256_mul_pd(db, _mm256_set1_pd(vx))), inv);
  return p;
}

// The term of the lanes' samples h at (dx, dy) from the plane's origin into m.
// A term times a zero offset is +-0: left out, it changes at most the sign of
// a zero, which the absolute value drops; so the same |d|.
GEODS_TERRAIN_AVX2_INLINE void term4(__m256d& m, const Plane4& p, __m256d base, __m256d h, std::int64_t dx) {
  const __m256d q = dx == 0 ? base : _mm256_add_pd(base, _mm256_mul_pd(p.gx, _mm256_set1_pd(double(dx))));
  m = _mm256_max_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), _mm256_sub_pd(h, q)), m);
}

// rows_error<S>() of the four lanes, into m. Lanes 8 or more samples apart
// take rows of three or more samples eight at a time, by a 4 x 8
// transposition of eight floats per lane (reads up to row + 3 St + hi + 7).
template <int St>
GEODS_TERRAIN_AVX2_INLINE void rows4(__m256d& m, std::int64_t n, const Plane4& p, std::int64_t r0, std::int64_t rows,
                                      std::int64_t lo0, std::int64_t dlo, std::int64_t hi0, std::int64_t dhi) {
  for (std::int64_t r = 0; r < rows; ++r) {
    const std::int64_t dy = r0 + r, lo = lo0 + dlo * r, hi = hi0 + dhi * r;
    const __m256d base = dy == 0 ? p.za : _mm256_add_pd(p.za, _mm256_mul_pd(p.gy, _mm256_set1_pd(double(dy))));
    const float* row = p.a + dy * n;
    if constexpr (St >= 8)
      if (hi - lo >= 2) {
        for (std::int64_t b = lo; b <= hi; b += 8) {
          const float* q = row + b;
          const __m256 l0 = _mm256_loadu_ps(q), l1 = _mm256_loadu_ps(q + St), l2 = _mm256_loadu_ps(q + 2 * St),
                       l3 = _mm256_loadu_ps(q + 3 * St);
          const __m256 t0 = _mm256_unpacklo_ps(l0, l1), t1 = _mm256_unpackhi_ps(l0, l1), t2 = _mm256_unpacklo_ps(l2, l3),
                       t3 = _mm256_unpackhi_ps(l2, l3);
          const __m256 c[4] = {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xEE), _mm256_shuffle_ps(t1, t3, 0x44),
                               _mm256_shuffle_ps(t1, t3, 0xEE)};  // samples b + k (low half), b + k + 4 (high)
          for (int k = 0; k < 8 && b + k <= hi; ++k) {
            if (b + k == 0 && dy == 0) continue;  // the plane's origin: |d| = 0
            const __m128 h = k < 4 ? _mm256_castps256_ps128(c[k]) : _mm256_extractf128_ps(c[k - 4], 1);
            term4(m, p, base, _mm256_cvtps_pd(h), b + k);
          }
        }
        continue;
      }
    for (std::int64_t dx = lo; dx <= hi; ++dx)
      if (dx != 0 || dy != 0) term4(m, p, base, load4<St>(row + dx), dx);  // at the plane's origin |d| = 0
  }
}

// err of the lanes' vertices (x + St j, y): round_up() of m, +inf where a
// corner of the diamond (spacing s) leaves W x H.
template <int St>
GEODS_TERRAIN_AVX2_INLINE void store4(float* err, std::int64_t n, std::int64_t x, std::int64_t y, std::int64_t s, std::int64_t W,
                                      std::int64_t H, __m256d m) {
  float* e = err + y * n + x;
  store4f<St>(e, round_up4(m));
  for (int j = 0; j < 4; ++j)
    if (x + St * j + s > W - 1 || y + s > H - 1) e[St * j] = kInf;
}

// The red vertices of row y (spacing S, N / S >= 16): both diagonals, four
// vertices of one at a time (4 S apart).
template <int S>
__attribute__((target("avx2"))) void red_row_avx2(const float* z, std::int64_t n, std::int64_t W, std::int64_t H, std::uint32_t t,
                                                  std::int64_t y, float* err) {
  constexpr std::int64_t s = S;
  const std::int64_t N = n - 1;
  for (std::int64_t parity = 0; parity < 2; ++parity) {
    const bool main_parents = ((parity + ((y - s) >> (t + 1))) & 1) != 0;
    for (std::int64_t x = s + 2 * s * parity; x < N; x += 16 * s) {
      const float* v = z + y * n + x;
      __m256d m = _mm256_setzero_pd();
      if (main_parents) {
        const P2 a{-s, s}, b{s, -s};
        rows4<4 * S>(m, n, plane4<4 * S>(v, n, a, b, {-s, -s}), -2 * s, 2 * s + 1, 0, 0, 2 * s, -1);
        rows4<4 * S>(m, n, plane4<4 * S>(v, n, a, b, {s, s}), -2 * s, 2 * s + 1, 2 * s, -1, 2 * s, 0);
      } else {
        const P2 a{-s, -s}, b{s, s};
        rows4<4 * S>(m, n, plane4<4 * S>(v, n, a, b, {-s, s}), 0, 2 * s + 1, 0, 0, 0, 1);
        rows4<4 * S>(m, n, plane4<4 * S>(v, n, a, b, {s, -s}), 0, 2 * s + 1, 0, 1, 2 * s, 0);
      }
      store4<4 * S>(err, n, x, y, s, W, H, m);
    }
  }
}

// The blue vertices of row y on horizontal edges (0 < y < N): all of them.
template <int S>
__attribute__((target("avx2"))) void blue_h_row_avx2(const float* z, std::int64_t n, std::int64_t W, std::int64_t H, std::int64_t y,
                                                     float* err) {
  constexpr std::int64_t s = S;
  for (std::int64_t x = s; x < n - 1; x += 8 * s) {
    const float* v = z + y * n + x;
    __m256d m = _mm256_setzero_pd();
    rows4<2 * S>(m, n, plane4<2 * S>(v, n, {-s, 0}, {s, 0}, {0, -s}), -s, s + 1, s, -1, s, 1);
    rows4<2 * S>(m, n, plane4<2 * S>(v, n, {-s, 0}, {s, 0}, {0, s}), 0, s + 1, 0, 1, 2 * s, -1);
    store4<2 * S>(err, n, x, y, s, W, H, m);
  }
}

// The blue vertices of row y on vertical edges from x = 2 S to N - 8 S;
// returns the first x not done.
template <int S>
__attribute__((target("avx2"))) std::int64_t blue_v_row_avx2(const float* z, std::int64_t n, std::int64_t W, std::int64_t H,
                                                             std::int64_t y, float* err) {
  constexpr std::int64_t s = S;
  std::int64_t x = 2 * s;
  for (; x + 6 * s <= n - 1 - 2 * s; x += 8 * s) {
    const float* v = z + y * n + x;
    __m256d m = _mm256_setzero_pd();
    const Plane4 l = plane4<2 * S>(v, n, {0, -s}, {0, s}, {-s, 0}), r = plane4<2 * S>(v, n, {0, -s}, {0, s}, {s, 0});
    rows4<2 * S>(m, n, l, 0, s + 1, 0, -1, 0, 0);
    rows4<2 * S>(m, n, l, s + 1, s, 1 - s, 1, 0, 0);
    rows4<2 * S>(m, n, r, 0, s + 1, 0, 0, 0, 1);
    rows4<2 * S>(m, n, r, s + 1, s, 0, 0, s - 1, -1);
    store4<2 * S>(err, n, x, y, s, W, H, m);
  }
  return x;
}

// The nesting (nest() in the constructor) of the vertices x0, x0 + step, ...
// < x1 of row y, whose four children lie in the grid: the four square roots
// in one instruction (the same terms as two at a time). Returns the first x
// not done.
__attribute__((target("avx2"))) std::int64_t nest_row_avx2(const float* z, float* err, float* rad, std::int64_t n, std::int64_t y,
                                                   std::int64_t x0, std::int64_t x1, std::int64_t step, const Children& ch) {
  const __m256d d2 = _mm256_loadu_pd(ch.d2.data());
  std::int64_t x = x0;
  for (; x < x1; x += step) {
    const std::ptrdiff_t v = y * n + x, w0 = v + ch.dw[0], w1 = v + ch.dw[1], w2 = v + ch.dw[2], w3 = v + ch.dw[3];
    err[v] = std::max({err[v], err[w0], err[w1], err[w2], err[w3]});
    const __m256d dz = _mm256_sub_pd(_mm256_cvtps_pd(_mm_set_ps(z[w3], z[w2], z[w1], z[w0])), _mm256_set1_pd(z[v]));
    const __m256d r = _mm256_add_pd(_mm256_sqrt_pd(_mm256_add_pd(d2, _mm256_mul_pd(dz, dz))),
                                    _mm256_cvtps_pd(_mm_set_ps(rad[w3], rad[w2], rad[w1], rad[w0])));
    const __m128d m = _mm_max_pd(_mm256_castpd256_pd128(r), _mm256_extractf128_pd(r, 1));
    rad[v] = round_up(std::max(_mm_cvtsd_f64(m), _mm_cvtsd_f64(_mm_unpackhi_pd(m, m))));
  }
  return x;
}

// nest_row_avx2() four vertices at a time (the lanes St = 2 s apart, all four
// with four children): the same maxima and terms lane by lane.
template <int St>
__attribute__((target("avx2"))) std::int64_t nest_row4(const float* z, float* err, float* rad, std::int64_t n, std::int64_t y,
                                                       std::int64_t x0, std::int64_t x1, const Children& ch) {
  std::int64_t x = x0;
  for (; x + 3 * St < x1; x += 4 * St) {
    const std::ptrdiff_t v = y * n + x;
    __m128 e = load4f<St>(err + v);
    const __m256d zv = load4<St>(z + v);
    __m256d best = _mm256_setzero_pd();
    for (int k = 0; k < 4; ++k) {
      const std::ptrdiff_t w = v + ch.dw[k];
      e = _mm_max_ps(e, load4f<St>(err + w));
      const __m256d dz = _mm256_sub_pd(load4<St>(z + w), zv);
      best = _mm256_max_pd(best, _mm256_add_pd(_mm256_sqrt_pd(_mm256_add_pd(_mm256_set1_pd(ch.d2[k]), _mm256_mul_pd(dz, dz))),
                                               load4<St>(rad + w)));
    }
    store4f<St>(err + v, e);
    store4f<St>(rad + v, round_up4(best));
  }
  return x;
}
#undef GEODS_TERRAIN_AVX2_INLINE

#define GEODS_TERRAIN_AVX512_INLINE __attribute__((target("avx512f,avx512vl,avx512dq,avx2"), always_inline)) inline
// GCC 12 warns about the undefined pass-through operand inside its own AVX-512 intrinsics.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// p[0], p[St], ..., p[7 St] (for St = 2, 4, 8 reads up to p[8 St - 1], past the last lane as load4f does).
template <int St>
GEODS_TERRAIN_AVX512_INLINE __m256 load8f(const float* p) {
  if constexpr (St == 2) {
    return _mm512_castps512_ps256(_mm512_permutexvar_ps(_mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 14, 12, 10, 8, 6, 4, 2, 0),
                                                        _mm512_loadu_ps(p)));
  } else if constexpr (St == 4) {
    return _mm512_castps512_ps256(_mm512_permutex2var_ps(
        _mm512_loadu_ps(p), _mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 28, 24, 20, 16, 12, 8, 4, 0), _mm512_loadu_ps(p + 16)));
  } else if constexpr (St >= 16) {
    return _mm256_set_ps(p[7 * St], p[6 * St], p[5 * St], p[4 * St], p[3 * St], p[2 * St], p[St], p[0]);
  } else {
    static_assert(St == 8);
    const __m512i every8 = _mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 24, 16, 8, 0);
    const __m512 lo = _mm512_permutex2var_ps(_mm512_loadu_ps(p), every8, _mm512_loadu_ps(p + 16));
    const __m512 hi = _mm512_permutex2var_ps(_mm512_loadu_ps(p + 32), every8, _mm512_loadu_ps(p + 48));
    return _mm256_insertf128_ps(_mm512_castps512_ps256(lo), _mm512_castps512_ps128(hi), 1);
  }
}

// p[0], p[St], ..., p[7 St] = v: for St = 2 and 4 by masked stores of the
// lanes spread apart (the floats between untouched), else one at a time.
template <int St>
GEODS_TERRAIN_AVX512_INLINE void store8f(float* p, __m256 v) {
  const __m512 w = _mm512_castps256_ps512(v);
  if constexpr (St == 2) {
    _mm512_mask_storeu_ps(p, 0x5555, _mm512_permutexvar_ps(_mm512_set_epi32(0, 7, 0, 6, 0, 5, 0, 4, 0, 3, 0, 2, 0, 1, 0, 0), w));
  } else if constexpr (St == 4) {
    _mm512_mask_storeu_ps(p, 0x1111, _mm512_permutexvar_ps(_mm512_set_epi32(0, 0, 0, 3, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 0), w));
    _mm512_mask_storeu_ps(p + 16, 0x1111, _mm512_permutexvar_ps(_mm512_set_epi32(0, 0, 0, 7, 0, 0, 0, 6, 0, 0, 0, 5, 0, 0, 0, 4), w));
  } else {
    alignas(32) float out[8];
    _mm256_store_ps(out, v);
    for (int j = 0; j < 8; ++j) p[St * j] = out[j];
  }
}

// nest_row4() eight vertices at a time with AVX-512: the same maxima and terms lane by lane.
template <int St>
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) std::int64_t nest_row8(const float* z, float* err, float* rad, std::int64_t n,
                                                                               std::int64_t y, std::int64_t x0, std::int64_t x1,
                                                                               const Children& ch) {
  std::int64_t x = x0;
  for (; x + 7 * St < x1; x += 8 * St) {
    const std::ptrdiff_t v = y * n + x;
    __m256 e = load8f<St>(err + v);
    const __m512d zv = _mm512_cvtps_pd(load8f<St>(z + v));
    __m512d best = _mm512_setzero_pd();
    for (int k = 0; k < 4; ++k) {
      const std::ptrdiff_t w = v + ch.dw[k];
      e = _mm256_max_ps(e, load8f<St>(err + w));
      const __m512d dz = _mm512_sub_pd(_mm512_cvtps_pd(load8f<St>(z + w)), zv);
      best = _mm512_max_pd(best, _mm512_add_pd(_mm512_sqrt_pd(_mm512_add_pd(_mm512_set1_pd(ch.d2[k]), _mm512_mul_pd(dz, dz))),
                                               _mm512_cvtps_pd(load8f<St>(rad + w))));
    }
    // round_up() of the eight: one ulp up where the float is below the double.
    const __m256 f = _mm512_cvtpd_ps(best);
    const __mmask8 below = _mm512_cmp_pd_mask(_mm512_cvtps_pd(f), best, _CMP_LT_OQ);
    const __m256i r = _mm256_mask_add_epi32(_mm256_castps_si256(f), below, _mm256_castps_si256(f), _mm256_set1_epi32(1));
    alignas(32) float eo[8], ro[8];
    _mm256_store_ps(eo, e);
    _mm256_store_si256(reinterpret_cast<__m256i*>(ro), r);
    for (int j = 0; j < 8; ++j) err[v + St * j] = eo[j], rad[v + St * j] = ro[j];
  }
  return x;
}

// The fine levels' kernels with eight lanes (the lanes St = 2, 4 or 8 samples
// apart): Plane4, term4, rows4 and store4 lane by lane, so the same errors.
struct Plane8 {
  const float* a;
  __m512d za, gx, gy;
};
template <int St>
GEODS_TERRAIN_AVX512_INLINE Plane8 plane8(const float* v, std::int64_t n, P2 a, P2 b, P2 c) {
  Plane8 p;
  p.a = v + a.y * n + a.x;
  p.za = _mm512_cvtps_pd(load8f<St>(p.a));
  const __m512d zb = _mm512_cvtps_pd(load8f<St>(v + b.y * n + b.x)), zc = _mm512_cvtps_pd(load8f<St>(v + c.y * n + c.x));
  const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
  const __m512d inv = _mm512_set1_pd(1 / (ux * vy - uy * vx));
  const __m512d db = _mm512_sub_pd(zb, p.za), dc = _mm512_sub_pd(zc, p.za);
  p.gx = _mm512_mul_pd(_mm512_sub_pd(_mm512_mul_pd(db, _mm512_set1_pd(vy)), _mm512_mul_pd(dc, _mm512_set1_pd(uy))), inv);
  p.gy = _mm512_mul_pd(_mm512_sub_pd(_mm512_mul_pd(dc, _mm512_set1_pd(ux)), _mm512_mul_pd(db, _mm512_set1_pd(vx))), inv);
  return p;
}
GEODS_TERRAIN_AVX512_INLINE void term8(__m512d& m, const Plane8& p, __m512d base, __m256 h, std::int64_t dx) {
  const __m512d q = dx == 0 ? base : _mm512_add_pd(base, _mm512_mul_pd(p.gx, _mm512_set1_pd(double(dx))));
  m = _mm512_max_pd(_mm512_abs_pd(_mm512_sub_pd(_mm512_cvtps_pd(h), q)), m);
}
// Lanes 16 or more samples apart take rows of three or more samples eight at a
// time, by an 8 x 8 transposition of eight floats per lane (reads up to
// row + 7 St + hi + 7), as rows4 does for lanes 8 apart.
template <int St>
GEODS_TERRAIN_AVX512_INLINE void rows8(__m512d& m, std::int64_t n, const Plane8& p, std::int64_t r0, std::int64_t rows,
                                       std::int64_t lo0, std::int64_t dlo, std::int64_t hi0, std::int64_t dhi) {
  for (std::int64_t r = 0; r < rows; ++r) {
    const std::int64_t dy = r0 + r, lo = lo0 + dlo * r, hi = hi0 + dhi * r;
    const __m512d base = dy == 0 ? p.za : _mm512_add_pd(p.za, _mm512_mul_pd(p.gy, _mm512_set1_pd(double(dy))));
    const float* row = p.a + dy * n;
    if constexpr (St >= 16)
      if (hi - lo >= 2) {
        for (std::int64_t b = lo; b <= hi; b += 8) {
          const float* q = row + b;
          __m256 l[8], t[8];
          for (int j = 0; j < 8; ++j) l[j] = _mm256_loadu_ps(q + j * St);
          for (int j = 0; j < 8; j += 2)
            t[j] = _mm256_unpacklo_ps(l[j], l[j + 1]), t[j + 1] = _mm256_unpackhi_ps(l[j], l[j + 1]);
          // u[4 h + k]: sample b + k (low half) and b + k + 4 (high) of lanes 4 h .. 4 h + 3.
          __m256 u[8];
          for (int h = 0; h < 2; ++h) {
            const __m256 *a = t + 4 * h;
            u[4 * h] = _mm256_shuffle_ps(a[0], a[2], 0x44), u[4 * h + 1] = _mm256_shuffle_ps(a[0], a[2], 0xEE);
            u[4 * h + 2] = _mm256_shuffle_ps(a[1], a[3], 0x44), u[4 * h + 3] = _mm256_shuffle_ps(a[1], a[3], 0xEE);
          }
          for (int k = 0; k < 8 && b + k <= hi; ++k) {
            if (b + k == 0 && dy == 0) continue;  // the plane's origin: |d| = 0
            const int i = k & 3;
            const __m256 h = k < 4 ? _mm256_permute2f128_ps(u[i], u[4 + i], 0x20) : _mm256_permute2f128_ps(u[i], u[4 + i], 0x31);
            term8(m, p, base, h, b + k);
          }
        }
        continue;
      }
    for (std::int64_t dx = lo; dx <= hi; ++dx)
      if (dx != 0 || dy != 0) term8(m, p, base, load8f<St>(row + dx), dx);  // at the plane's origin |d| = 0
  }
}
template <int St>
GEODS_TERRAIN_AVX512_INLINE void store8(float* err, std::int64_t n, std::int64_t x, std::int64_t y, std::int64_t s, std::int64_t W,
                                        std::int64_t H, __m512d m) {
  const __m256 f = _mm512_cvtpd_ps(m);
  const __mmask8 below = _mm512_cmp_pd_mask(_mm512_cvtps_pd(f), m, _CMP_LT_OQ);  // round_up(): one ulp up
  const __m256 r = _mm256_castsi256_ps(_mm256_mask_add_epi32(_mm256_castps_si256(f), below, _mm256_castps_si256(f), _mm256_set1_epi32(1)));
  float* e = err + y * n + x;
  if (x + 7 * St + s <= W - 1 && y + s <= H - 1) {  // every diamond in the field
    store8f<St>(e, r);
    return;
  }
  alignas(32) float out[8];
  _mm256_store_ps(out, r);
  for (int j = 0; j < 8; ++j) e[St * j] = x + St * j + s > W - 1 || y + s > H - 1 ? kInf : out[j];
}

// red_row_avx2<S>() eight vertices at a time (N / S >= 32).
template <int S>
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) void red_row_avx512(const float* z, std::int64_t n, std::int64_t W,
                                                                              std::int64_t H, std::uint32_t t, std::int64_t y,
                                                                              float* err) {
  constexpr std::int64_t s = S;
  const std::int64_t N = n - 1;
  for (std::int64_t parity = 0; parity < 2; ++parity) {
    const bool main_parents = ((parity + ((y - s) >> (t + 1))) & 1) != 0;
    for (std::int64_t x = s + 2 * s * parity; x < N; x += 32 * s) {
      const float* v = z + y * n + x;
      __m512d m = _mm512_setzero_pd();
      if (main_parents) {
        const P2 a{-s, s}, b{s, -s};
        rows8<4 * S>(m, n, plane8<4 * S>(v, n, a, b, {-s, -s}), -2 * s, 2 * s + 1, 0, 0, 2 * s, -1);
        rows8<4 * S>(m, n, plane8<4 * S>(v, n, a, b, {s, s}), -2 * s, 2 * s + 1, 2 * s, -1, 2 * s, 0);
      } else {
        const P2 a{-s, -s}, b{s, s};
        rows8<4 * S>(m, n, plane8<4 * S>(v, n, a, b, {-s, s}), 0, 2 * s + 1, 0, 0, 0, 1);
        rows8<4 * S>(m, n, plane8<4 * S>(v, n, a, b, {s, -s}), 0, 2 * s + 1, 0, 1, 2 * s, 0);
      }
      store8<4 * S>(err, n, x, y, s, W, H, m);
    }
  }
}

// blue_h_row_avx2<S>() eight vertices at a time (N / S >= 32).
template <int S>
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) void blue_h_row_avx512(const float* z, std::int64_t n, std::int64_t W,
                                                                                std::int64_t H, std::int64_t y, float* err) {
  constexpr std::int64_t s = S;
  for (std::int64_t x = s; x < n - 1; x += 16 * s) {
    const float* v = z + y * n + x;
    __m512d m = _mm512_setzero_pd();
    rows8<2 * S>(m, n, plane8<2 * S>(v, n, {-s, 0}, {s, 0}, {0, -s}), -s, s + 1, s, -1, s, 1);
    rows8<2 * S>(m, n, plane8<2 * S>(v, n, {-s, 0}, {s, 0}, {0, s}), 0, s + 1, 0, 1, 2 * s, -1);
    store8<2 * S>(err, n, x, y, s, W, H, m);
  }
}

// blue_v_row_avx2<S>() eight vertices at a time from x = 2 S;
// returns the first x not done.
template <int S>
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) std::int64_t blue_v_row_avx512(const float* z, std::int64_t n, std::int64_t W,
                                                                                        std::int64_t H, std::int64_t y, float* err) {
  constexpr std::int64_t s = S;
  std::int64_t x = 2 * s;
  for (; x + 14 * s <= n - 1 - 2 * s; x += 16 * s) {
    const float* v = z + y * n + x;
    __m512d m = _mm512_setzero_pd();
    const Plane8 l = plane8<2 * S>(v, n, {0, -s}, {0, s}, {-s, 0}), r = plane8<2 * S>(v, n, {0, -s}, {0, s}, {s, 0});
    rows8<2 * S>(m, n, l, 0, s + 1, 0, -1, 0, 0);
    rows8<2 * S>(m, n, l, s + 1, s, 1 - s, 1, 0, 0);
    rows8<2 * S>(m, n, r, 0, s + 1, 0, 0, 0, 1);
    rows8<2 * S>(m, n, r, s + 1, s, 0, 0, s - 1, -1);
    store8<2 * S>(err, n, x, y, s, W, H, m);
  }
  return x;
}
#pragma GCC diagnostic pop
#undef GEODS_TERRAIN_AVX512_INLINE
#endif

// The own errors of the vertices of spacing s = 2^t (S = s when it is a small
// compile-time constant, else 0): red ones (square centres) split the two
// halves of their 2s-square, blue ones the quarters of 2s-squares on both
// sides of their edge. err[y n + x] = the largest error of the triangles,
// rounded up to a float; +inf when a corner of one lies outside W x H. With
// AVX2 (and N / S >= 16, so that groups of four fill the rows) the fine
// levels take the kernels above (eight vertices at a time with AVX-512 where
// N / S >= 32), but for the
// first and last rows of blue vertices on horizontal edges, the first and
// last few on vertical ones, and the rows whose triangles reach the grid's
// last row (the kernels load a few floats past the samples they use, and z
// may end there).
template <int S>
void level_errors(const float* z, std::int64_t n, std::int64_t W, std::int64_t H, std::uint32_t t, float* err) {
  const std::int64_t s = S ? S : std::int64_t(1) << t, N = n - 1, c = N / 2;
#if defined(__x86_64__) && defined(__GNUC__)
  const bool wide = S > 0 && N / s >= 16 && simd_level() >= SimdLevel::avx2;
  const bool wide8 = S > 0 && N / s >= 32 && simd_level() >= SimdLevel::avx512;
#endif
  auto in = [&](P2 p) { return p.x <= W - 1 && p.y <= H - 1; };
  // Red: rows y = s, 3s, ...; x = s, 3s, ... The parents (the apexes) are the
  // square's corners on the diagonal that is not the hypotenuse.
  parallel_for(0, std::size_t(N / (2 * s)), S ? 8 : 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t ry = b; ry < e; ++ry) {
      const std::int64_t y = (2 * std::int64_t(ry) + 1) * s;
#if defined(__x86_64__) && defined(__GNUC__)
      if constexpr (S > 0)
        if (wide && y + s < N) {
          if (wide8)
            red_row_avx512<S>(z, n, W, H, t, y, err);
          else
            red_row_avx2<S>(z, n, W, H, t, y, err);
          continue;
        }
#endif
      for (std::int64_t x = s; x < N; x += 2 * s) {
        if (x == c && y == c) continue;  // the centre is always in the mesh
        const bool main_parents = ((((x - s) >> (t + 1)) + ((y - s) >> (t + 1))) & 1) != 0;
        double worst;
        if (main_parents) {  // hypotenuse (x-s, y+s) - (x+s, y-s)
          const P2 a{x - s, y + s}, b{x + s, y - s}, c0{x - s, y - s}, c1{x + s, y + s};
          if (!in(a) || !in(b) || !in(c0) || !in(c1)) {
            worst = kInf;
          } else {
            worst = std::max(rows_error<S>(z, n, detail::Plane(z, std::uint64_t(n), a, b, c0), a, -2 * s, 2 * s + 1, 0, 0, 2 * s, -1),
                             rows_error<S>(z, n, detail::Plane(z, std::uint64_t(n), a, b, c1), a, -2 * s, 2 * s + 1, 2 * s, -1, 2 * s, 0));
          }
        } else {  // hypotenuse (x-s, y-s) - (x+s, y+s)
          const P2 a{x - s, y - s}, b{x + s, y + s}, c0{x - s, y + s}, c1{x + s, y - s};
          if (!in(a) || !in(b) || !in(c0) || !in(c1)) {
            worst = kInf;
          } else {
            worst = std::max(rows_error<S>(z, n, detail::Plane(z, std::uint64_t(n), a, b, c0), a, 0, 2 * s + 1, 0, 0, 0, 1),
                             rows_error<S>(z, n, detail::Plane(z, std::uint64_t(n), a, b, c1), a, 0, 2 * s + 1, 0, 1, 2 * s, 0));
          }
        }
        err[y * n + x] = round_up(worst);
      }
    }
  });
  // Blue on horizontal edges: rows y = 0, 2s, ..., N; x = s, 3s, ...; the
  // hypotenuse (x-s, y) - (x+s, y), apexes (x, y -+ s).
  parallel_for(0, std::size_t(N / (2 * s) + 1), S ? 8 : 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t ry = b; ry < e; ++ry) {
      const std::int64_t y = 2 * std::int64_t(ry) * s;
#if defined(__x86_64__) && defined(__GNUC__)
      if constexpr (S > 0)
        if (wide && y > 0 && y < N) {
          if (wide8)
            blue_h_row_avx512<S>(z, n, W, H, y, err);
          else
            blue_h_row_avx2<S>(z, n, W, H, y, err);
          continue;
        }
#endif
      for (std::int64_t x = s; x < N; x += 2 * s) {
        const P2 a{x - s, y}, bb{x + s, y};
        double worst = 0;
        if (!in(a) || !in(bb)) {
          worst = kInf;
        } else {
          if (y - s >= 0) {
            const P2 cc{x, y - s};
            worst = in(cc) ? std::max(worst, rows_error<S>(z, n, detail::Plane(z, std::uint64_t(n), a, bb, cc), a, -s, s + 1, s, -1, s, 1)) : kInf;
          }
          if (y + s <= N && worst != kInf) {
            const P2 cc{x, y + s};
            worst = in(cc) ? std::max(worst, rows_error<S>(z, n, detail::Plane(z, std::uint64_t(n), a, bb, cc), a, 0, s + 1, 0, 1, 2 * s, -1)) : kInf;
          }
        }
        err[y * n + x] = round_up(worst);
      }
    }
  });
  // Blue on vertical edges: rows y = s, 3s, ...; x = 0, 2s, ..., N; the
  // hypotenuse (x, y-s) - (x, y+s), apexes (x -+ s, y); each triangle's rows
  // in two runs (widening, then narrowing).
  parallel_for(0, std::size_t(N / (2 * s)), S ? 8 : 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t ry = b; ry < e; ++ry) {
      const std::int64_t y = (2 * std::int64_t(ry) + 1) * s;
      std::int64_t done = 2 * s;  // the vertices x in [2 s, done) are done
#if defined(__x86_64__) && defined(__GNUC__)
      if constexpr (S > 0)
        if (wide && y + s < N) done = wide8 ? blue_v_row_avx512<S>(z, n, W, H, y, err) : blue_v_row_avx2<S>(z, n, W, H, y, err);
#endif
      for (std::int64_t x = 0; x <= N; x = x == 0 ? done : x + 2 * s) {
        const P2 a{x, y - s}, bb{x, y + s};
        double worst = 0;
        if (!in(a) || !in(bb)) {
          worst = kInf;
        } else {
          if (x - s >= 0) {
            const P2 cc{x - s, y};
            if (in(cc)) {
              const detail::Plane p(z, std::uint64_t(n), a, bb, cc);
              worst = std::max({worst, rows_error<S>(z, n, p, a, 0, s + 1, 0, -1, 0, 0),
                                rows_error<S>(z, n, p, a, s + 1, s, 1 - s, 1, 0, 0)});
            } else {
              worst = kInf;
            }
          }
          if (x + s <= N && worst != kInf) {
            const P2 cc{x + s, y};
            if (in(cc)) {
              const detail::Plane p(z, std::uint64_t(n), a, bb, cc);
              worst = std::max({worst, rows_error<S>(z, n, p, a, 0, s + 1, 0, 0, 0, 1),
                                rows_error<S>(z, n, p, a, s + 1, s, 0, 0, s - 1, -1)});
            } else {
              worst = kInf;
            }
          }
        }
        err[y * n + x] = round_up(worst);
      }
    }
  });
}

// The own errors of every vertex but the corners and the centre (0 there).
// Spacings 1 to 32 as fixed stencils (the SIMD kernels; spacing 64 that way was slower).
void own_errors(const float* z, std::int64_t n, std::int64_t W, std::int64_t H, std::uint32_t K, float* err) {
  for (std::uint32_t t = 0; t < K; ++t) {
    if (t == 0)
      level_errors<1>(z, n, W, H, t, err);
    else if (t == 1)
      level_errors<2>(z, n, W, H, t, err);
    else if (t == 2)
      level_errors<4>(z, n, W, H, t, err);
    else if (t == 3)
      level_errors<8>(z, n, W, H, t, err);
    else if (t == 4)
      level_errors<16>(z, n, W, H, t, err);
    else if (t == 5)
      level_errors<32>(z, n, W, H, t, err);
    else
      level_errors<0>(z, n, W, H, t, err);
  }
}

// The matrix layout's records (slot = sample index) from the heights, errors
// and radii: four records by three 16-byte stores at a time (a third faster
// than assigning them one by one).
void fill_matrix(VertexRecord* records, const float* z, const float* err, const float* rad, std::size_t count) {
  static_assert(sizeof(VertexRecord) == 3 * sizeof(float));
  std::size_t done = 0;
#if defined(__SSE2__)
  done = count / 4 * 4;
  parallel_for(0, count / 4, 8192, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const __m128 h = _mm_loadu_ps(z + 4 * i), r = _mm_loadu_ps(err + 4 * i), d = _mm_loadu_ps(rad + 4 * i);
      const __m128 lo = _mm_unpacklo_ps(h, r), hi = _mm_unpackhi_ps(h, r);  // z0 e0 z1 e1, z2 e2 z3 e3
      float* out = reinterpret_cast<float*>(records + 4 * i);
      _mm_storeu_ps(out, _mm_shuffle_ps(lo, _mm_shuffle_ps(d, h, _MM_SHUFFLE(1, 1, 0, 0)), _MM_SHUFFLE(2, 0, 1, 0)));  // z0 e0 r0 z1
      _mm_storeu_ps(out + 4, _mm_shuffle_ps(_mm_unpacklo_ps(r, d), hi, _MM_SHUFFLE(1, 0, 3, 2)));                     // e1 r1 z2 e2
      _mm_storeu_ps(out + 8, _mm_shuffle_ps(_mm_shuffle_ps(d, hi, _MM_SHUFFLE(2, 2, 2, 2)), _mm_shuffle_ps(hi, d, _MM_SHUFFLE(3, 3, 3, 3)),
                                            _MM_SHUFFLE(2, 0, 2, 0)));  // r2 z3 e3 r3
    }
  });
#endif
  for (std::size_t g = done; g < count; ++g) records[g] = {z[g], err[g], rad[g]};
}

// The quarter turns R^-1 that take (dx, dy) (a red vertex relative to the
// centre) into the bottom quarter Q0 of interleaved_slot(); dx, dy turned.
int red_turns(std::int64_t& dx, std::int64_t& dy) {
  int q = 0;
  while (!(dy < 0 && (-dy > std::abs(dx) || (-dy == std::abs(dx) && dx < 0)))) {
    const std::int64_t t0 = dx;
    dx = dy, dy = -t0, ++q;  // R^-1
  }
  return q;
}

// put(slot, x, y) for every point (x, y) of the layout's n x n grid, in
// parallel: the interleaved slots by the level's Morton code stepped along the
// rows of the level (no interleaved_slot() per vertex).
template <class Put>
void for_each_slot(const LayoutIndex& index, Put&& put) {
  const std::uint32_t K = index.levels();
  const std::uint64_t n = index.n();
  const std::int64_t N = std::int64_t(n) - 1, c = N / 2;
  if (index.layout() == Layout::matrix) {
    parallel_for(0, n, 4, [&](std::size_t b, std::size_t e) {
      for (std::size_t y = b; y < e; ++y)
        for (std::size_t x = 0; x < n; ++x) put(y * n + x, std::int64_t(x), std::int64_t(y));
    });
  } else {
    // Row by row (each row of the heights read once), in each row the levels
    // whose rows it is; along a row of blue vertices of spacing s (step 2 s)
    // both coordinates of the level's Morton code grow by one.
    for (const P2 p : {P2{0, 0}, P2{N, 0}, P2{0, N}, P2{N, N}, P2{c, c}})
      put(index.interleaved_slot(std::uint32_t(p.x), std::uint32_t(p.y)), p.x, p.y);
    constexpr std::uint64_t kEven = 0x5555555555555555ull, kOdd = ~kEven;
    parallel_for(0, n, 4, [&](std::size_t b, std::size_t e) {
      for (std::size_t row = b; row < e; ++row) {
        const std::int64_t y = std::int64_t(row);
        // Rows k s of the level of spacing s: blue at x = s, 3s, ... (k even) or
        // x = 0, 2s, ... (k odd); red at x = s, 3s, ... (k odd).
        for (std::uint32_t t = 0; t < K && (y & ((std::int64_t(1) << t) - 1)) == 0; ++t) {
          const std::int64_t s = std::int64_t(1) << t, k = y >> t;
          const std::uint64_t base = index.level_base(t);
          const std::int64_t x0 = (k & 1) ? 0 : s;
          std::uint64_t m = index.interleaved_slot(std::uint32_t(x0), std::uint32_t(y)) - base;
          for (std::int64_t x = x0; x <= N; x += 2 * s) {
            put(base + m, x, y);
            m = (((m | kOdd) + 1) & kEven) | (((m | kEven) + 2) & kOdd);
          }
          // Red ones: within a run of the same quarter turns the ghost slot
          // moves by a reflection of the step, both Morton coordinates by +1
          // (an even number of turns) or -1 (odd).
          int run = -1;
          if (k & 1)
            for (std::int64_t x = s; x < N; x += 2 * s) {
              if (x == c && y == c) continue;
              std::int64_t dx = x - c, dy = y - c;
              const int q = red_turns(dx, dy);
              if (q != run) {
                m = index.interleaved_slot(std::uint32_t(x), std::uint32_t(y)) - base, run = q;
              } else if (q & 1) {
                m = (((m & kEven) - 1) & kEven) | (((m & kOdd) - 2) & kOdd);
              } else {
                m = (((m | kOdd) + 1) & kEven) | (((m | kEven) + 2) & kOdd);
              }
              put(base + m, x, y);
            }
        }
      }
    });
  }
}

}  // namespace

// ---------------------------------------------------------------- layout

LayoutIndex::LayoutIndex(Layout layout, std::uint32_t levels) : layout_(layout), levels_(levels) {
  if (levels < 1 || levels > 30) throw Error("terrain layout: levels must be in 1..30, got " + std::to_string(levels));
  if (layout == Layout::matrix) {
    slots_ = n() * n();
    return;
  }
  std::uint64_t next = 5;  // slot 0 the centre, 1..4 the corners
  for (std::int64_t t = std::int64_t(levels) - 1; t >= 0; --t) {
    const std::uint64_t m = std::uint64_t(1) << (levels - std::uint32_t(t));
    base_[std::size_t(t)] = next;
    next += m * m;
  }
  slots_ = next;
}

std::uint64_t LayoutIndex::interleaved_slot(std::uint32_t x, std::uint32_t y) const {
  const std::int64_t c = std::int64_t(1) << (levels_ - 1), N = 2 * c;
  if (x == c && y == c) return 0;
  if ((x == 0 || x == N) && (y == 0 || y == N)) return 1 + (x == N) + 2 * (y == N);
  const int t = std::countr_zero(x | y);
  const std::int64_t s = std::int64_t(1) << t;
  std::int64_t X = x, Y = y;
  if (((x >> t) & 1) && ((y >> t) & 1)) {
    // A red vertex (square centre, s < c): into a ghost slot of the blue level
    // of the same spacing. Rotate it into the bottom quarter Q0 (below both
    // diagonals; of the diagonal points the lower-left ones), map (x, y) ->
    // (x + s, -y), rotate back: the image is a blue-lattice point outside the
    // grid but inside the blue quadtree's root diamond, and distinct per vertex.
    std::int64_t dx = X - c, dy = Y - c;
    const int q = red_turns(dx, dy);
    std::int64_t ex = dx + s, ey = -2 * c - dy;
    for (int k = 0; k < q; ++k) {
      const std::int64_t t0 = ex;
      ex = -ey, ey = t0;  // R
    }
    X = c + ex, Y = c + ey;
  }
  const std::int64_t m = N >> t;
  const std::int64_t u = (X + Y) >> t, v = (X - Y) >> t;  // exact; odd, u in (0, 2m), v in (-m, m)
  const std::uint64_t i = std::uint64_t((u - 1) / 2), j = std::uint64_t((v + m - 1) / 2);
  return base_[std::size_t(t)] + morton2d_encode64(std::uint32_t(i), std::uint32_t(j));
}

// ---------------------------------------------------------------- build

Terrain::Terrain(HeightField field, TerrainOptions options) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t missing = check_height_field(field);
  if (!std::isfinite(options.z_scale) || options.z_scale == 0)
    throw Error("terrain: z_scale " + format_number(options.z_scale) + " is not finite and nonzero");
  filled_ = missing ? fill_missing(field) : 0;  // no second pass over a field without missing samples
  width_ = field.width;
  height_ = field.height;
  spacing_ = field.spacing;
  origin_ = field.origin;
  z_scale_ = options.z_scale;
  std::uint32_t K = 1;
  while ((std::uint64_t(1) << K) + 1 < std::max(width_, height_)) ++K;
  const std::uint64_t n = (std::uint64_t(1) << K) + 1;
  const std::int64_t W = std::int64_t(width_), H = std::int64_t(height_);
  index_ = LayoutIndex(options.layout, K);

  // Heights of the padded grid (the padding repeats the last row and column):
  // the field's own samples where it is n x n and unscaled, no copy (fresh
  // memory costs more than the copy on some machines: a page fault per page).
  std::vector<float, HugePageAllocator<float>> padded;
  const float* z = field.heights.data();
  if (width_ != n || height_ != n || z_scale_ != 1) {
    padded.resize(n * n);
    parallel_for(0, n, 16, [&](std::size_t b, std::size_t e) {
      bool finite = true;
      for (std::size_t y = b; y < e; ++y) {
        const float* src = field.heights.data() + std::min<std::size_t>(y, height_ - 1) * width_;
        float* dst = padded.data() + y * n;
        if (z_scale_ == 1) {
          std::copy(src, src + width_, dst);  // finite (checked, missing ones filled)
        } else {
          for (std::size_t x = 0; x < width_; ++x) {
            dst[x] = float(double(src[x]) * z_scale_);
            finite &= std::isfinite(dst[x]);
          }
        }
        std::fill(dst + width_, dst + n, dst[width_ - 1]);
      }
      if (!finite) throw Error("terrain: a height times z_scale overflows a float");
    });
    field.heights = {};
    z = padded.data();
  }

  const std::int64_t N = std::int64_t(n) - 1;
  // Own error of each vertex: the largest vertical distance between the grid and
  // the triangles it splits (its diamond); +inf where the diamond leaves the
  // field (the padding), so that those vertices are always refined and no
  // final triangle straddles the field's border. Level by level, every
  // triangle's rows as spans known by arithmetic (no point-in-triangle tests).
  // The errors and the radii (below) in one array: one allocation of fresh memory.
  // own_errors() writes every error but the roots' (the corners, the centre);
  // the radii of the leaves (and corners) stay 0.
  std::vector<float, DefaultInitAllocator<HugePageAllocator<float>>> err_rad(2 * n * n);
  float* err = err_rad.data();
  float* rad = err + n * n;
  std::fill(rad, rad + n * n, 0.0f);
  for (const std::uint64_t g : {std::uint64_t(0), n - 1, n * n - n, n * n - 1, n * n / 2}) err[g] = 0;
  own_errors(z, std::int64_t(n), W, H, K, err);

  // Nesting, finest level first: error = max(own, children's); radius = max over
  // children of (distance + child's radius), rounded up, so that a child's
  // sphere lies in its parent's.
#if defined(__x86_64__) && defined(__GNUC__)
  const bool avx2 = simd_level() >= SimdLevel::avx2, avx512 = simd_level() >= SimdLevel::avx512;
#endif
  const double sx = std::abs(spacing_[0]), sy = std::abs(spacing_[1]);
  // Vertex (x, y) from its children at offsets off[k] (skipped outside the
  // grid); the radius is rounded up once (rounding up is monotone).
  auto children = [&](const std::array<P2, 4>& off) {
    Children ch{off, {}, {}};
    for (int k = 0; k < 4; ++k) {
      const double dx = double(off[k].x) * sx, dy = double(off[k].y) * sy;
      ch.dw[k] = off[k].y * std::ptrdiff_t(n) + off[k].x, ch.d2[k] = dx * dx + dy * dy;
    }
    return ch;
  };
  auto nest = [&](std::int64_t x, std::int64_t y, const Children& ch, bool interior) {
    const std::size_t v = std::size_t(y * std::int64_t(n) + x);
    std::size_t w[4];
    double d2[4];
    int k = 0;
    if (interior) {
      for (; k < 4; ++k) w[k] = std::size_t(std::ptrdiff_t(v) + ch.dw[k]), d2[k] = ch.d2[k];
    } else {
      for (int j = 0; j < 4; ++j) {
        const P2 c{x + ch.off[j].x, y + ch.off[j].y};
        if (c.x < 0 || c.y < 0 || c.x > N || c.y > N) continue;
        w[k] = std::size_t(std::ptrdiff_t(v) + ch.dw[j]), d2[k++] = ch.d2[j];
      }
    }
    float e = err[v];
    for (int j = 0; j < k; ++j) e = std::max(e, err[w[j]]);
    err[v] = e;
    const double zv = z[v];
    double best = 0;
#if defined(__SSE2__)
    if (k == 4) {  // two square roots at a time
      const __m128d vz = _mm_set1_pd(zv);
      const __m128d a = _mm_sub_pd(_mm_set_pd(z[w[1]], z[w[0]]), vz), b = _mm_sub_pd(_mm_set_pd(z[w[3]], z[w[2]]), vz);
      const __m128d ra = _mm_add_pd(_mm_sqrt_pd(_mm_add_pd(_mm_set_pd(d2[1], d2[0]), _mm_mul_pd(a, a))),
                                    _mm_set_pd(rad[w[1]], rad[w[0]]));
      const __m128d rb = _mm_add_pd(_mm_sqrt_pd(_mm_add_pd(_mm_set_pd(d2[3], d2[2]), _mm_mul_pd(b, b))),
                                    _mm_set_pd(rad[w[3]], rad[w[2]]));
      const __m128d m = _mm_max_pd(ra, rb);
      best = std::max(_mm_cvtsd_f64(m), _mm_cvtsd_f64(_mm_unpackhi_pd(m, m)));
      k = 0;
    }
#endif
    for (int j = 0; j < k; ++j) {
      const double dz = double(z[w[j]]) - zv;
      best = std::max(best, std::sqrt(d2[j] + dz * dz) + double(rad[w[j]]));
    }
    rad[v] = round_up(best);
  };
  for (std::uint32_t t = 0; t < K; ++t) {
    const std::int64_t s = std::int64_t(1) << t;
#if defined(__x86_64__) && defined(__GNUC__)
    // The vertices x, x + 2 s, ... < N of row y with four children each, with
    // AVX2; returns the first x not done.
    auto nest_row = [&](std::int64_t y, std::int64_t x, const Children& ch) {
      if (y + s < N) {  // nest_row4 and nest_row8 load past its children: not in the grid's last row
        if (s == 1 && avx512) x = nest_row8<2>(z, err, rad, std::int64_t(n), y, x, N, ch);
        if (s == 2 && avx512) x = nest_row8<4>(z, err, rad, std::int64_t(n), y, x, N, ch);
        if (s == 1) x = nest_row4<2>(z, err, rad, std::int64_t(n), y, x, N, ch);
        if (s == 2) x = nest_row4<4>(z, err, rad, std::int64_t(n), y, x, N, ch);
      }
      return nest_row_avx2(z, err, rad, std::int64_t(n), y, x, N, 2 * s, ch);
    };
#endif
    // Blue vertices of spacing s >= 2: children are the red ones of spacing s / 2.
    if (s >= 2) {
      const std::int64_t h = s / 2;
      const Children ch = children({P2{-h, -h}, P2{h, -h}, P2{-h, h}, P2{h, h}});
      parallel_for(0, std::size_t(N / s + 1), 4, [&](std::size_t b, std::size_t e) {
        for (std::size_t r = b; r < e; ++r) {
          const std::int64_t y = std::int64_t(r) * s;
          const bool inner_row = y > 0 && y < N;
          std::int64_t x = (r & 1) ? 0 : s;
#if defined(__x86_64__) && defined(__GNUC__)
          if (inner_row && avx2) {
            if (x == 0) {  // on the border: not all four children
              nest(0, y, ch, false);
              x = 2 * s;
            }
            x = nest_row(y, x, ch);
          }
#endif
          for (; x <= N; x += 2 * s) nest(x, y, ch, inner_row && x > 0 && x < N);
        }
      });
    }
    // Red vertices of spacing s (square centres): children the blue ones of spacing s.
    const Children ch = children({P2{-s, 0}, P2{s, 0}, P2{0, -s}, P2{0, s}});
    parallel_for(0, std::size_t(N / (2 * s)), 4, [&](std::size_t b, std::size_t e) {
      for (std::size_t r = b; r < e; ++r) {
        const std::int64_t y = std::int64_t(2 * r + 1) * s;
#if defined(__x86_64__) && defined(__GNUC__)
        if (avx2) {
          nest_row(y, s, ch);
          continue;
        }
#endif
        for (std::int64_t x = s; x < N; x += 2 * s) nest(x, y, ch, true);
      }
    });
  }

  // Huge pages: 4 KiB pages cost a fault each (about 4 300 for 1025², 25-30 ms of CPU in this VM, more than the errors).
  // Not zeroed where the fill writes every slot (the matrix layout): the 12.6 MB of 1025² are written once.
  std::vector<VertexRecord, DefaultInitAllocator<HugePageAllocator<VertexRecord>>> records(index_.slots());
  if (index_.layout() != Layout::matrix) std::fill(records.begin(), records.end(), VertexRecord{});  // ghost slots
  if (index_.layout() == Layout::matrix)
    fill_matrix(records.data(), z, err, rad, n * n);
  else
    for_each_slot(index_, [&](std::uint64_t slot, std::int64_t x, std::int64_t y) {
      const std::uint64_t g = std::uint64_t(y) * n + std::uint64_t(x);
      records[slot] = {z[g], err[g], rad[g]};
    });
  records_ = FlatArray<VertexRecord>(std::move(records));
  build_s_ = seconds_since(t0);
}

TerrainStats Terrain::stats() const {
  TerrainStats s;
  s.width = width_;
  s.height = height_;
  s.grid = index_.n();
  s.levels = index_.levels();
  s.slots = index_.slots();
  s.unused_slots = s.slots - s.grid * s.grid;
  s.unused_slots_pct = s.slots ? 100.0 * double(s.unused_slots) / double(s.slots) : 0;
  s.filled_samples = filled_;
  s.bytes = records_.size() * sizeof(VertexRecord);
  s.mapped = records_.mapped();
  s.build_s = build_s_;
  return s;
}

// ---------------------------------------------------------------- refinement

namespace {

// The refinement of one square of the grid: L&P's submesh recursion in doubled
// coordinates (a split vertex of the finest triangles lies between samples).
// Id: the type of the grid ids y n + x (32 bits where they fit: half the memory).
template <class Id>
class Refiner {
 public:
  Refiner(const Terrain& t, const Refinement& r) : t_(t), r_(r) {
    if (!r.max_error && !r.view) throw Error("terrain refine: give a max_error or a view (camera)");
    if (r.max_error && !(*r.max_error >= 0)) throw Error("terrain refine: max_error must be >= 0");
    n_ = t.layout().n();
    if (r.view) {
      const TerrainView& v = *r.view;
      v.camera.check();
      if (v.width < 1 || v.height < 1) throw Error("terrain refine: the image size must be at least 1 x 1");
      if (!(r.pixel_error > 0) || !std::isfinite(r.pixel_error))
        throw Error("terrain refine: pixel_error must be > 0");
      eye_ = {v.camera.eye.x(), v.camera.eye.y(), v.camera.eye.z()};
      const Vec3d f = (v.camera.target - v.camera.eye).cast<double>().normalized();
      const Vec3d right = f.cross(v.camera.up.cast<double>()).normalized();
      const Vec3d up = right.cross(f);
      const double tv = std::tan(double(v.camera.vertical_fov_deg) * M_PI / 360.0);
      const double th = tv * double(v.width) / double(v.height);
      planes_[0] = (th * f + right).normalized();
      planes_[1] = (th * f - right).normalized();
      planes_[2] = (tv * f + up).normalized();
      planes_[3] = (tv * f - up).normalized();
      planes_[4] = f;
      lambda_ = double(v.height) / (2 * tv);
    }
  }

  static constexpr unsigned kAllPlanes = 31;

  // Whether the vertex at doubled coordinates (x2, y2) is in the mesh;
  // `planes` are the frustum planes its sphere still straddles (updated).
  bool active(std::int64_t x2, std::int64_t y2, unsigned& planes) const {
    const std::uint32_t x = std::uint32_t(x2 / 2), y = std::uint32_t(y2 / 2);
    const VertexRecord& v = t_.record(x, y);
    if (std::isinf(v.error)) return true;  // the padding
    if (r_.max_error && double(v.error) > *r_.max_error) return true;
    if (!r_.view || v.error <= 0) return false;
    const Vec3d p(t_.origin()[0] + double(x) * t_.spacing()[0], t_.origin()[1] + double(y) * t_.spacing()[1], double(v.z));
    const Vec3d d = p - eye_;
    for (unsigned k = 0; k < 5; ++k) {
      if (!(planes & (1u << k))) continue;
      const double dist = planes_[k].dot(d);
      if (dist < -double(v.radius)) return false;  // outside the frustum
      if (dist > double(v.radius)) planes &= ~(1u << k);  // completely inside this plane
    }
    const double dd = d.norm() - double(v.radius);
    if (dd <= 0) return true;
    return lambda_ * double(v.error) > r_.pixel_error * dd;
  }

  // The mesh of the square [x0, x0 + L] x [y0, y0 + L] (L a power of two >= 2)
  // as a strip of grid ids, appended to strip_; its non-degenerate triangles are the mesh.
  void square(std::int64_t x0, std::int64_t y0, std::int64_t L, std::uint32_t depth) {
    const std::int64_t X0 = 2 * x0, Y0 = 2 * y0, X1 = 2 * (x0 + L), Y1 = 2 * (y0 + L), C = X0 + L, CY = Y0 + L;
    const P2 corners[4] = {{X1, Y0}, {X1, Y1}, {X0, Y1}, {X0, Y0}};
    const P2 mids[4] = {{C, Y0}, {X1, CY}, {C, Y1}, {X0, CY}};
    const std::size_t first = strip_.size();
    strip_.push_back(id(X0, Y0));
    strip_.push_back(id(X0, Y0));
    parity_ = 0;
    for (int q = 0; q < 4; ++q) {
      submesh(C, CY, mids[q].x, mids[q].y, 2 * depth, kAllPlanes);  // the centre: always in the mesh
      append(corners[q], 1);
    }
    strip_begin_.push_back(first);
  }

  std::vector<Id, HugePageAllocator<Id>> strip_;  // huge pages: fewer page faults
  std::vector<std::size_t> strip_begin_;  // where each square's strip starts

 private:
  Id id(std::int64_t x2, std::int64_t y2) const { return Id(std::uint64_t(y2 / 2) * n_ + std::uint64_t(x2 / 2)); }

  // L&P's submesh-refine(i, j, l) for an active i (`planes` updated by its
  // test): the triangle of apex i and split vertex j; its halves, the
  // triangles of apex j, exist when j is active (one test for both). The
  // coordinates as scalars: pairs were packed into vector registers through
  // the stack, a stalled load (store forwarding) per call.
  void submesh(std::int64_t ix, std::int64_t iy, std::int64_t jx, std::int64_t jy, std::uint32_t l, unsigned planes) {
    if (l > 1 && active(jx, jy, planes)) {
      // The children of j: the split vertices of the halves, in the order the
      // strip walks them (L&P's c_l, c_r): for an axis-aligned i - j the one
      // counter-clockwise from i - j first, for a diagonal one the clockwise
      // one (the walk turns at every level).
      const std::int64_t dx = ix - jx, dy = iy - jy, sx = ix + jx, sy = iy + jy;
      const std::int64_t ccw_x = (sx - dy) / 2, ccw_y = (sy + dx) / 2, cw_x = (sx + dy) / 2, cw_y = (sy - dx) / 2;
      const bool axis = dx == 0 || dy == 0;
      submesh(jx, jy, axis ? ccw_x : cw_x, axis ? ccw_y : cw_y, l - 1, planes);
      append({ix, iy}, l & 1);
      submesh(jx, jy, axis ? cw_x : ccw_x, axis ? cw_y : ccw_y, l - 1, planes);
    } else {
      append({ix, iy}, l & 1);
    }
  }

  void append(P2 v, unsigned p) {
    const Id w = id(v.x, v.y);
    const std::size_t k = strip_.size();
    if (w == strip_[k - 1] || w == strip_[k - 2]) return;
    if (p != parity_)
      parity_ = p;
    else
      strip_.push_back(strip_[k - 2]);  // a turn
    strip_.push_back(w);
  }

  const Terrain& t_;
  const Refinement& r_;
  std::uint64_t n_ = 0;
  unsigned parity_ = 0;
  Vec3d eye_ = Vec3d::Zero();
  Vec3d planes_[5];
  double lambda_ = 1;
};

// The strip of `refiner` restricted to the field (the padding dropped: every
// leaf triangle lies wholly inside or outside it): put(g) for each of its grid
// ids in order. The triangles inside are kept (degenerate ones too, they turn
// the strip); runs of kept triangles are joined by degenerate triangles that
// keep each triangle's parity, so the winding is what the submesh recursion made.
template <class Id, class Inside, class Put>
void clip_strip(const Refiner<Id>& refiner, Inside inside, Put&& put) {
  const auto& s = refiner.strip_;
  const std::vector<std::size_t>& begins = refiner.strip_begin_;
  std::size_t size = 0;  // of the clipped strip
  std::uint64_t last = 0;
  auto push = [&](std::uint64_t g) {
    put(g);
    last = g, ++size;
  };
  for (std::size_t part = 0; part < begins.size(); ++part) {
    const std::size_t b = begins[part], e = part + 1 < begins.size() ? begins[part + 1] : s.size();
    std::size_t k = b;
    while (k + 2 < e) {
      if (!(inside(s[k]) && inside(s[k + 1]) && inside(s[k + 2]))) {
        ++k;
        continue;
      }
      std::size_t end = k;  // [k, end] kept triangles
      while (end + 3 < e && inside(s[end + 3])) ++end;
      // Join: ..., last, last, s[k], s[k] (degenerate triangles), one more
      // s[k] when needed so that the run's triangles keep their parity.
      if (size == 0) {  // no leading degenerate triangles
        while (k < end && (s[k] == s[k + 1] || s[k + 1] == s[k + 2] || s[k] == s[k + 2])) ++k;
      } else {
        push(last);
        push(s[k]);
      }
      // The recursion's strip starts with its first corner twice: its
      // triangle k is counter-clockwise when k - b is odd.
      if (size % 2 != (k - b + 1) % 2) push(s[k]);
      for (std::size_t q = k; q <= end + 2; ++q) push(s[q]);
      k = end + 1;
    }
  }
}

// The output mesh: the clipped strip, its non-degenerate triangles (made
// counter-clockwise), vertices numbered in grid order. Every output array is
// sized once: a counting pass over the strip first.
template <class Id>
TerrainMesh assemble(const Terrain& t, const Refiner<Id>& refiner) {
  const std::uint64_t n = t.layout().n(), W = t.width(), H = t.height();
  TerrainMesh mesh;
  auto clip = [&](auto&& put) {
    if (W == n && H == n)  // no padding: every triangle is inside
      clip_strip(refiner, [](std::uint64_t) { return true; }, put);
    else
      clip_strip(refiner, [&](std::uint64_t g) { return g % n < W && g / n < H; }, put);
  };
  std::size_t size = 0, triangles = 0;  // of the clipped strip; its non-degenerate triangles
  std::uint64_t last[2] = {};
  clip([&](std::uint64_t g) {
    triangles += size >= 2 && g != last[0] && g != last[1] && last[0] != last[1];
    last[1] = last[0], last[0] = g, ++size;
  });
  // The output arrays in huge pages where they are large (their first touch is most of their cost).
  mesh.strip.reserve(size);
  advise_huge_pages(mesh.strip);
  const auto reserve_vertices = [&](std::size_t count) {
    mesh.samples.reserve(count);
    mesh.vertices.reserve(count);
    advise_huge_pages(mesh.samples);
    advise_huge_pages(mesh.vertices);
  };
  const auto place = [&](std::uint32_t x, std::uint32_t y) {
    mesh.samples.push_back({x, y});
    mesh.vertices.emplace_back(float(t.origin()[0] + double(x) * t.spacing()[0]),
                               float(t.origin()[1] + double(y) * t.spacing()[1]), t.sample(x, y));
  };
  // Vertices numbered in grid order: by a dense table up to 2^24 samples, else by sorting.
  if (n * n <= (std::uint64_t(1) << 24)) {
    clip([&](std::uint64_t g) { mesh.strip.push_back(std::uint32_t(g)); });  // grid ids, numbered below
    constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t, HugePageAllocator<std::uint32_t>> dense(n * n, kUnused);
    std::size_t vertices = 0;
    for (const std::uint32_t g : mesh.strip) {
      vertices += dense[g] == kUnused;
      dense[g] = 0;
    }
    reserve_vertices(vertices);
    for (std::uint32_t y = 0, g = 0; y < n; ++y)
      for (std::uint32_t x = 0; x < n; ++x, ++g)
        if (dense[g] == 0) {
          dense[g] = std::uint32_t(mesh.samples.size());
          place(x, y);
        }
    for (std::uint32_t& g : mesh.strip) g = dense[g];
  } else {
    std::vector<std::uint64_t> strip;  // grid ids
    strip.reserve(size);
    clip([&](std::uint64_t g) { strip.push_back(g); });
    std::vector<std::uint64_t> unique = strip;
    std::sort(unique.begin(), unique.end());
    unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
    reserve_vertices(unique.size());
    for (const std::uint64_t g : unique) place(std::uint32_t(g % n), std::uint32_t(g / n));
    for (const std::uint64_t g : strip)
      mesh.strip.push_back(std::uint32_t(std::lower_bound(unique.begin(), unique.end(), g) - unique.begin()));
  }
  // The triangles: the strip's non-degenerate ones (the joins are all
  // degenerate), counter-clockwise in grid coordinates: the strip's triangle k
  // is when k is even, its mirror image when k is odd.
  mesh.triangles.reserve(triangles);
  advise_huge_pages(mesh.triangles);
  for (std::size_t k = 0; k + 2 < mesh.strip.size(); ++k) {
    const std::uint32_t a = mesh.strip[k], b = mesh.strip[k + 1], c = mesh.strip[k + 2];
    if (a == b || b == c || a == c) continue;
    mesh.triangles.push_back(k % 2 ? std::array{a, c, b} : std::array{a, b, c});
  }
  return mesh;
}

}  // namespace

TerrainMesh Terrain::refine(const Refinement& refinement) const { return refine_tiles(refinement, 1); }

TerrainMesh Terrain::refine_tiles(const Refinement& refinement, std::uint32_t tiles) const {
  if (records_.empty()) throw Error("terrain refine: an empty terrain");
  const std::uint32_t K = index_.levels();
  if (tiles < 1 || !std::has_single_bit(tiles) || tiles > (1u << (K - 1)))
    throw Error("terrain refine: tiles must be a power of two from 1 to " + std::to_string(1u << (K - 1)) +
                " for this grid, got " + std::to_string(tiles));
  const std::int64_t L = (std::int64_t(1) << K) / tiles;
  const std::uint32_t depth = std::uint32_t(std::countr_zero(std::uint64_t(L)));
  const auto run = [&]<class Id>(Id) {
    Refiner<Id> refiner(*this, refinement);
    for (std::uint32_t ty = 0; ty < tiles; ++ty)
      for (std::uint32_t tx = 0; tx < tiles; ++tx) {
        const std::int64_t x0 = std::int64_t(tx) * L, y0 = std::int64_t(ty) * L;
        if (std::uint64_t(x0) >= width_ - 1 || std::uint64_t(y0) >= height_ - 1) continue;  // all padding
        refiner.square(x0, y0, L, depth);
      }
    return assemble(*this, refiner);
  };
  const std::uint64_t n = index_.n();
  return n * n <= (std::uint64_t(1) << 32) ? run(std::uint32_t()) : run(std::uint64_t());
}

std::vector<float, HugePageAllocator<float>> Terrain::heights_matrix() const {
  std::vector<float, HugePageAllocator<float>> z(width_ * height_);
  for_each_slot(index_, [&](std::uint64_t slot, std::int64_t x, std::int64_t y) {
    if (std::uint64_t(x) < width_ && std::uint64_t(y) < height_) z[std::uint64_t(y) * width_ + std::uint64_t(x)] = records_[slot].z;
  });
  return z;
}

double Terrain::measure_error(const TerrainMesh& mesh) const {
  for (const auto& tri : mesh.triangles)
    for (const std::uint32_t v : tri)
      if (mesh.samples.size() <= v || mesh.samples[v][0] >= width_ || mesh.samples[v][1] >= height_)
        throw Error("terrain measure_error: a vertex without a sample of the field");
  const auto z = heights_matrix();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.triangles.size(), 256), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double worst) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          const auto& t = mesh.triangles[k];
          const auto p = [&](std::uint32_t v) { return P2{mesh.samples[v][0], mesh.samples[v][1]}; };
          const P2 a = p(t[0]), b = p(t[1]), c = p(t[2]);
          if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) == 0) continue;  // degenerate: no area
          worst = std::max(worst, triangle_error(z.data(), width_, a, b, c));
        }
        return worst;
      },
      [](double a, double b) { return std::max(a, b); });
}

// ---------------------------------------------------------------- file

void Terrain::save(const std::filesystem::path& path) const {
  // Files are interleaved (for terrains larger than RAM: a mapped view reads the
  // pages of the coarse levels and of the fine vertices it visits); a matrix
  // terrain's records are rearranged, the unused slots zero as a build leaves them.
  const LayoutIndex file(Layout::interleaved, index_.levels());
  std::vector<VertexRecord, HugePageAllocator<VertexRecord>> rearranged;
  std::span<const VertexRecord> records = records_.span();
  if (index_.layout() != Layout::interleaved) {
    rearranged.resize(file.slots());
    for_each_slot(file, [&](std::uint64_t slot, std::int64_t x, std::int64_t y) {
      rearranged[slot] = record(std::uint32_t(x), std::uint32_t(y));
    });
    records = rearranged;
  }
  ArchiveWriter w(std::string(kTerrainArchiveKind), kTerrainArchiveVersion);
  w.add_value("width", width_);
  w.add_value("height", height_);
  w.add_value("levels", std::uint64_t(index_.levels()));
  w.add_value("layout", std::uint32_t(file.layout()));
  w.add_value("spacing", spacing_);
  w.add_value("origin", origin_);
  w.add_value("z_scale", z_scale_);
  w.add_value("filled", filled_);
  w.add("records", records);
  w.write(path);
}

Terrain Terrain::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kTerrainArchiveKind, kTerrainArchiveVersion, verify);
  Terrain t;
  t.width_ = a.value<std::uint64_t>("width");
  t.height_ = a.value<std::uint64_t>("height");
  const std::uint64_t levels = a.value<std::uint64_t>("levels");
  const std::uint32_t layout = a.value<std::uint32_t>("layout");
  t.spacing_ = a.value<std::array<double, 2>>("spacing");
  t.origin_ = a.value<std::array<double, 2>>("origin");
  t.z_scale_ = a.value<double>("z_scale");
  t.filled_ = a.value<std::uint64_t>("filled");
  a.check([&] {
    if (layout > 1) throw Error("unknown layout " + std::to_string(layout));
    if (levels < 1 || levels > 30) throw Error("levels " + std::to_string(levels) + " outside 1..30");
    const std::uint64_t n = (std::uint64_t(1) << levels) + 1;
    std::uint64_t expected = 1;
    while ((std::uint64_t(1) << expected) + 1 < std::max(t.width_, t.height_)) ++expected;
    if (t.width_ < 2 || t.height_ < 2 || t.width_ > n || t.height_ > n || expected != levels)
      throw Error("a " + std::to_string(t.width_) + " x " + std::to_string(t.height_) + " field in a grid of " +
                  std::to_string(n));
    for (const double v : {t.spacing_[0], t.spacing_[1], t.origin_[0], t.origin_[1], t.z_scale_})
      if (!std::isfinite(v)) throw Error("a spacing, origin or z_scale that is not finite");
    if (t.spacing_[0] == 0 || t.spacing_[1] == 0 || t.z_scale_ == 0) throw Error("a zero spacing or z_scale");
    t.index_ = LayoutIndex(Layout(layout), std::uint32_t(levels));
  });
  t.records_ = a.array<VertexRecord>("records", t.index_.slots());
  return t;
}

}  // namespace geods::terrain
