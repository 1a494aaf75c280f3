#pragma once
// Internal to the terrain module: the samples of a grid triangle and their
// vertical distance to the triangle's plane.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace geods::terrain::detail {

struct P2 {
  std::int64_t x, y;
};

struct Worst {
  double error = 0;
  P2 at{0, 0};
};

// max(0, max over x in [lo, hi] of |row[x] - (base + gx (x - ax))|), every term
// rounded as written (so the same value as the scalar loop; NaN terms ignored).
inline double row_max(const float* row, std::int64_t lo, std::int64_t hi, double base, double gx, std::int64_t ax) {
  double m = 0;
  std::int64_t x = lo;
#if defined(__SSE2__)
  if (hi - lo >= 3) {
    const __m128d vg = _mm_set1_pd(gx), vb = _mm_set1_pd(base), sign = _mm_set1_pd(-0.0), four = _mm_set1_pd(4.0);
    __m128d x0 = _mm_set_pd(double(lo + 1 - ax), double(lo - ax)), x1 = _mm_set_pd(double(lo + 3 - ax), double(lo + 2 - ax));
    __m128d m0 = _mm_setzero_pd(), m1 = _mm_setzero_pd();
    for (; x + 3 <= hi; x += 4) {
      const __m128d z0 = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + x))));
      const __m128d z1 = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + x + 2))));
      m0 = _mm_max_pd(_mm_andnot_pd(sign, _mm_sub_pd(z0, _mm_add_pd(vb, _mm_mul_pd(vg, x0)))), m0);
      m1 = _mm_max_pd(_mm_andnot_pd(sign, _mm_sub_pd(z1, _mm_add_pd(vb, _mm_mul_pd(vg, x1)))), m1);
      x0 = _mm_add_pd(x0, four), x1 = _mm_add_pd(x1, four);
    }
    m0 = _mm_max_pd(m0, m1);
    m = std::max(_mm_cvtsd_f64(m0), _mm_cvtsd_f64(_mm_unpackhi_pd(m0, m0)));
  }
#endif
  for (; x <= hi; ++x) {
    const double d = std::abs(double(row[x]) - (base + gx * double(x - ax)));
    m = std::max(m, d);  // maxsd, no branch
  }
  return m;
}

// The plane through the heights of the grid points a, b, c (not collinear) of
// an n-wide matrix of heights: z = za + gx (x - a.x) + gy (y - a.y).
struct Plane {
  double za, gx, gy;

  [[gnu::always_inline]] Plane(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
    za = z[a.y * n + a.x];
    const double zb = z[b.y * n + b.x], zc = z[c.y * n + c.x];
    const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
    const double det = ux * vy - uy * vx;
    gx = ((zb - za) * vy - (zc - za) * uy) / det;
    gy = ((zc - za) * ux - (zb - za) * vx) / det;
  }
  // The plane on the row dy = y - a.y is base(dy) + gx (x - a.x).
  double base(std::int64_t dy) const { return za + gy * double(dy); }
};

#if defined(__x86_64__) && defined(__GNUC__)
// row_max() four doubles at a time where the CPU has AVX2 (the same terms, the
// same rounding: no FMA), for rows of at least 4 samples (hi - lo >= 3), when
// simd_level() (core/simd_level.hpp) is avx2 or above. The last samples are
// taken as one more block of four ending at hi, overlapping the ones before
// (a maximum does not mind seeing a term twice): no scalar tail.
__attribute__((target("avx2"))) inline double row_max_avx2(const float* row, std::int64_t lo, std::int64_t hi, double base,
                                                           double gx, std::int64_t ax) {
  const __m256d vg = _mm256_set1_pd(gx), vb = _mm256_set1_pd(base), sign = _mm256_set1_pd(-0.0), eight = _mm256_set1_pd(8.0);
  const __m256d iota = _mm256_set_pd(3, 2, 1, 0);
  __m256d x0 = _mm256_add_pd(_mm256_set1_pd(double(lo - ax)), iota), x1 = _mm256_add_pd(x0, _mm256_set1_pd(4.0));
  __m256d m0 = _mm256_setzero_pd(), m1 = _mm256_setzero_pd();
  std::int64_t i = lo;
  for (; i + 7 <= hi; i += 8) {
    const __m256d z0 = _mm256_cvtps_pd(_mm_loadu_ps(row + i)), z1 = _mm256_cvtps_pd(_mm_loadu_ps(row + i + 4));
    m0 = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(z0, _mm256_add_pd(vb, _mm256_mul_pd(vg, x0)))), m0);
    m1 = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(z1, _mm256_add_pd(vb, _mm256_mul_pd(vg, x1)))), m1);
    x0 = _mm256_add_pd(x0, eight), x1 = _mm256_add_pd(x1, eight);
  }
  if (i + 3 < hi) {  // 5..7 left: one block at i, the last block at hi - 3
    const __m256d z0 = _mm256_cvtps_pd(_mm_loadu_ps(row + i));
    m0 = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(z0, _mm256_add_pd(vb, _mm256_mul_pd(vg, x0)))), m0);
  }
  if (i <= hi) {  // the last block of four, ending at hi
    const __m256d x = _mm256_add_pd(_mm256_set1_pd(double(hi - 3 - ax)), iota);
    const __m256d z1 = _mm256_cvtps_pd(_mm_loadu_ps(row + hi - 3));
    m1 = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(z1, _mm256_add_pd(vb, _mm256_mul_pd(vg, x)))), m1);
  }
  const __m256d mm = _mm256_max_pd(m0, m1);
  const __m128d m2 = _mm_max_pd(_mm256_castpd256_pd128(mm), _mm256_extractf128_pd(mm, 1));
  return std::max(_mm_cvtsd_f64(m2), _mm_cvtsd_f64(_mm_unpackhi_pd(m2, m2)));
}

// row_max_avx2() eight doubles at a time, the last samples as one masked
// block (masked loads do not fault), when simd_level() is avx512: the same
// terms lane by lane, taken into the lanes of m0 and m1 (rows of any length,
// none where lo > hi) so that the rows of a triangle are reduced once.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"), always_inline)) inline void row_max8(const float* row, std::int64_t lo,
                                                                                            std::int64_t hi, double base, double gx,
                                                                                            std::int64_t ax, __m512d& m0, __m512d& m1) {
  const __m512d vg = _mm512_set1_pd(gx), vb = _mm512_set1_pd(base), eight = _mm512_set1_pd(8.0);
  __m512d x0 = _mm512_add_pd(_mm512_set1_pd(double(lo - ax)), _mm512_set_pd(7, 6, 5, 4, 3, 2, 1, 0));
  std::int64_t i = lo;
  for (; i + 15 <= hi; i += 16) {
    const __m512d x1 = _mm512_add_pd(x0, eight);
    const __m512d z0 = _mm512_cvtps_pd(_mm256_loadu_ps(row + i)), z1 = _mm512_cvtps_pd(_mm256_loadu_ps(row + i + 8));
    m0 = _mm512_max_pd(_mm512_abs_pd(_mm512_sub_pd(z0, _mm512_add_pd(vb, _mm512_mul_pd(vg, x0)))), m0);
    m1 = _mm512_max_pd(_mm512_abs_pd(_mm512_sub_pd(z1, _mm512_add_pd(vb, _mm512_mul_pd(vg, x1)))), m1);
    x0 = _mm512_add_pd(x1, eight);
  }
  for (; i <= hi; i += 8) {
    const __mmask8 k = hi - i >= 7 ? __mmask8(0xFF) : __mmask8((1u << unsigned(hi - i + 1)) - 1);
    const __m512d z0 = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(k, row + i));
    m1 = _mm512_mask_max_pd(m1, k, _mm512_abs_pd(_mm512_sub_pd(z0, _mm512_add_pd(vb, _mm512_mul_pd(vg, x0)))), m1);
    x0 = _mm512_add_pd(x0, eight);
  }
}
#endif

// A grid triangle (a, b, c): its plane and the samples of each of its rows.
struct GridTriangle : Plane {
  P2 v[3];  // counter-clockwise
  std::int64_t y0, y1, xmin, xmax;

  GridTriangle(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) : Plane(z, n, a, b, c) {
    v[0] = a, v[1] = b, v[2] = c;
    if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) < 0) std::swap(v[1], v[2]);
    y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
    xmin = std::min({a.x, b.x, c.x}), xmax = std::max({a.x, b.x, c.x});
  }
  // The samples lo..hi of row y inside the closed triangle (lo > hi: none):
  // every edge function E(x, y) = (q.x - p.x) (y - p.y) - (q.y - p.y) (x - p.x)
  // >= 0, i.e. A x <= B with A = q.y - p.y, in exact integer division.
  void row(std::int64_t y, std::int64_t& lo, std::int64_t& hi) const {
    lo = xmin, hi = xmax;
    for (int e = 0; e < 3; ++e) {
      const P2 p = v[e], q = v[(e + 1) % 3];
      const std::int64_t A = q.y - p.y, B = (q.x - p.x) * (y - p.y) + (q.y - p.y) * p.x;
      if (A > 0)
        hi = std::min(hi, B >= 0 ? B / A : -((-B + A - 1) / A));
      else if (A < 0)
        lo = std::max(lo, (-B) >= 0 ? ((-B) + (-A) - 1) / (-A) : -((B) / (-A)));
      else if (B < 0)
        lo = hi + 1;
    }
  }
  bool inside(std::int64_t x, std::int64_t y) const {
    for (int e = 0; e < 3; ++e) {
      const P2 p = v[e], q = v[(e + 1) % 3];
      if ((q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x) < 0) return false;
    }
    return true;
  }
  // The plane on row y is base(y) + gx (x - a.x); relative to a, the same
  // rounding wherever the triangle lies (tin_tile() of a block equals the tile of tin()).
  double base(std::int64_t y, std::int64_t ay) const { return Plane::base(y - ay); }
};

// floor(B(y) / a) for B(y) = B(y0) + D (y - y0) and a > 0, stepped y -> y + 1
// with additions only (exact; the quotient and remainder carried along).
struct FloorWalk {
  std::int64_t q = 0, r = 0, dq = 0, dr = 0, a = 1;

  static std::int64_t floor_div(std::int64_t b, std::int64_t a) { return b / a - std::int64_t(b % a != 0 && b < 0); }
  void start(std::int64_t b, std::int64_t d, std::int64_t divisor) {
    a = divisor, q = floor_div(b, a), r = b - q * a, dq = floor_div(d, a), dr = d - dq * a;
  }
  void step() {
    q += dq, r += dr;
    const bool carry = r >= a;
    q += std::int64_t(carry), r -= carry ? a : 0;
  }
};

// The rows of a GridTriangle from y0 to y1: the same lo..hi as GridTriangle::row()
// (the edge with A > 0 bounds hi by floor(B / A), one with A < 0 bounds lo by
// -floor(B / |A|), a horizontal one holds on every row of the triangle), each
// edge's quotient walked from row to row instead of divided.
struct RowWalk {
  FloorWalk lo_edge[2], hi_edge[2];
  int lo_edges = 0, hi_edges = 0;
  std::int64_t xmin, xmax;

  explicit RowWalk(const GridTriangle& t) : RowWalk(t.v, t.y0) {}
  // From the corners counter-clockwise and the first row.
  RowWalk(const P2 (&v)[3], std::int64_t y0) : xmin(std::min({v[0].x, v[1].x, v[2].x})), xmax(std::max({v[0].x, v[1].x, v[2].x})) {
    for (int e = 0; e < 3; ++e) {
      const P2 p = v[e], q = v[(e + 1) % 3];
      const std::int64_t A = q.y - p.y, D = q.x - p.x, B = D * (y0 - p.y) + A * p.x;
      if (A > 0) hi_edge[hi_edges++].start(B, D, A);
      if (A < 0) lo_edge[lo_edges++].start(B, D, -A);
    }
  }
  // The span of the current row; then on to the next row.
  [[gnu::always_inline]] void span(std::int64_t& lo, std::int64_t& hi) const {
    lo = xmin, hi = xmax;
    for (int k = 0; k < lo_edges; ++k) lo = std::max(lo, -lo_edge[k].q);
    for (int k = 0; k < hi_edges; ++k) hi = std::min(hi, hi_edge[k].q);
  }
  [[gnu::always_inline]] void next() {
    for (int k = 0; k < lo_edges; ++k) lo_edge[k].step();
    for (int k = 0; k < hi_edges; ++k) hi_edge[k].step();
  }
};

// The largest |z(sample) - plane(sample)| over the grid samples in the closed
// triangle (a, b, c) (integer grid coordinates) of an n-wide matrix of heights,
// and the sample where it is (the first such in row order): the maximum of
// each row (row_max_avx2() for rows of 4 or more samples when Avx2, else
// row_max()), then the first sample of the first row holding the largest one
// (the same terms, so the same value). Scalar loops per sample with a branch on
// every improvement measured slower for the greedy TIN's large triangles; small
// ones (a bounding box of at most 4 x 4 samples) take triangle_worst_small().
// Triangles whose bounding box is at most kSmallSpan + 1 samples wide and
// high (most of a fine TIN's) are scanned sample by sample instead:
// triangle_worst_small().
inline constexpr std::int64_t kSmallSpan = 3;

// triangle_worst() of a small triangle: every sample of the bounding box,
// tested by the three edge functions stepped by additions (no division, no
// row set-up), the same plane terms as the rows.
[[gnu::always_inline]] inline Worst triangle_worst_small(const float* z, std::uint64_t n, const GridTriangle& t, P2 a) {
  std::int64_t edge[3], step[3];  // at (xmin, y); the change per sample to the right
  for (int e = 0; e < 3; ++e) {
    const P2 p = t.v[e], q = t.v[(e + 1) % 3];
    edge[e] = (q.x - p.x) * (t.y0 - p.y) - (q.y - p.y) * (t.xmin - p.x);
    step[e] = q.y - p.y;
  }
  Worst w;
  for (std::int64_t y = t.y0; y <= t.y1; ++y) {
    const float* row = z + y * std::int64_t(n);
    const double base = t.base(y, a.y);
    std::int64_t e0 = edge[0], e1 = edge[1], e2 = edge[2];
    for (std::int64_t x = t.xmin; x <= t.xmax; ++x, e0 -= step[0], e1 -= step[1], e2 -= step[2]) {
      if ((e0 | e1 | e2) < 0) continue;  // outside: some edge function is negative
      const double d = std::abs(double(row[x]) - (base + t.gx * double(x - a.x)));
      if (d > w.error) w = {d, {x, y}};
    }
    for (int e = 0; e < 3; ++e) edge[e] += t.v[(e + 1) % 3].x - t.v[e].x;
  }
  return w;
}

// row_max() by the kernel the scans use: AVX2 for rows of 4 or more samples
// when `avx2` (simd_level() avx2 or above), else row_max() itself.
[[gnu::always_inline]] inline double row_max_picked(bool avx2, const float* row, std::int64_t lo, std::int64_t hi,
                                                    double base, double gx, std::int64_t ax) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (avx2 && hi - lo >= 3) return row_max_avx2(row, lo, hi, base, gx, ax);
#endif
  return row_max(row, lo, hi, base, gx, ax);
}

template <bool Avx2>
[[gnu::always_inline]] inline Worst triangle_worst_rows(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  const GridTriangle t(z, n, a, b, c);
  if (t.xmax - t.xmin <= kSmallSpan && t.y1 - t.y0 <= kSmallSpan) return triangle_worst_small(z, n, t, a);
  RowWalk walk(t);
  double worst = 0;
  std::int64_t wy = 0, wlo = 0;
  for (std::int64_t y = t.y0; y <= t.y1; ++y, walk.next()) {
    std::int64_t lo, hi;
    walk.span(lo, hi);
    if (lo > hi) continue;
    const float* row = z + y * std::int64_t(n);
    const double base = t.base(y, a.y);
    const double m = row_max_picked(Avx2, row, lo, hi, base, t.gx, a.x);
    if (m > worst) worst = m, wy = y, wlo = lo;
  }
  Worst w;
  if (!(worst > 0)) return w;
  const float* row = z + wy * std::int64_t(n);
  const double base = t.base(wy, a.y);
  std::int64_t x = wlo;
  while (std::abs(double(row[x]) - (base + t.gx * double(x - a.x))) != worst) ++x;
  return {worst, {x, wy}};
}

// triangle_worst() for the portable build (and CPUs without AVX2).
inline Worst triangle_worst(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  return triangle_worst_rows<false>(z, n, a, b, c);
}

#if defined(__x86_64__) && defined(__GNUC__)
// triangle_worst() with AVX2 rows: call it only when simd_level() >= avx2.
__attribute__((target("avx2"))) inline Worst triangle_worst_avx2(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  return triangle_worst_rows<true>(z, n, a, b, c);
}
#endif

#if defined(__x86_64__) && defined(__GNUC__)
#define GEODS_TERRAIN_AVX512_INLINE __attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2"), always_inline)) inline
// The AVX-512 scan (simd_level() avx512): eight samples a block, the lanes past
// a row's end masked off (masked loads do not fault), and per lane the largest
// error and the row-major index where it first occurs, so that no row needs a
// reduction of its own or a second search: at the end, the largest lane value
// and, among the lanes holding it, the least index, the first worst sample in
// row order. The same terms, rounded as written (the file is compiled without
// FMA contraction), so the same error and sample as triangle_worst().
// GCC 12 warns about the undefined pass-through operand inside its own
// intrinsics (_mm512_reduce_max_pd, _mm512_mask_reduce_min_pd) once inlined.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
struct Worst512 {
  __m512d best, at;
};

// The samples x .. x + 7 of row y (at `row`) selected by k into the lanes' maxima.
GEODS_TERRAIN_AVX512_INLINE void worst_block512(Worst512& w, const float* row, std::int64_t x, __mmask8 k, __m512d base,
                                                __m512d gx, std::int64_t ax, double row_index) {
  const __m512d xr = _mm512_add_pd(_mm512_set1_pd(double(x - ax)), _mm512_set_pd(7, 6, 5, 4, 3, 2, 1, 0));
  const __m512d z = _mm512_cvtps_pd(_mm256_maskz_loadu_ps(k, row + x));
  const __m512d d = _mm512_abs_pd(_mm512_sub_pd(z, _mm512_add_pd(base, _mm512_mul_pd(gx, xr))));
  const __mmask8 gt = _mm512_mask_cmp_pd_mask(k, d, w.best, _CMP_GT_OQ);
  w.best = _mm512_mask_mov_pd(w.best, gt, d);
  w.at = _mm512_mask_mov_pd(w.at, gt, _mm512_add_pd(xr, _mm512_set1_pd(row_index)));
}

// The samples of a triangle at most 8 Blocks wide into w: per row Blocks
// blocks from xmin, a lane inside where the three edge functions at
// (xmin + lane, y), stepped by rows, are >= 0 (no division, no row set-up, no
// branch per row).
template <int Blocks>
GEODS_TERRAIN_AVX512_INLINE void worst_narrow512(Worst512& w, const float* z, std::uint64_t n, const GridTriangle& t, P2 a,
                                                 __m512d gx) {
  const __m512i iota = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0), zero = _mm512_setzero_si512();
  __m512i edge[3][Blocks], down[3];
  for (int e = 0; e < 3; ++e) {
    const P2 p = t.v[e], q = t.v[(e + 1) % 3];
    const __m512i right = _mm512_set1_epi64(q.y - p.y);  // an edge function falls by q.y - p.y per sample to the right
    edge[e][0] = _mm512_sub_epi64(_mm512_set1_epi64((q.x - p.x) * (t.y0 - p.y) - (q.y - p.y) * (t.xmin - p.x)),
                                  _mm512_mullo_epi64(right, iota));
    for (int b = 1; b < Blocks; ++b) edge[e][b] = _mm512_sub_epi64(edge[e][b - 1], _mm512_slli_epi64(right, 3));
    down[e] = _mm512_set1_epi64(q.x - p.x);
  }
  const unsigned width = unsigned(t.xmax - t.xmin + 1);
  __mmask8 box[Blocks];
  for (int b = 0; b < Blocks; ++b) box[b] = __mmask8(_bzhi_u32(0xFF, width > 8u * unsigned(b) ? width - 8u * unsigned(b) : 0u));
  for (std::int64_t y = t.y0; y <= t.y1; ++y) {
    const float* row = z + y * std::int64_t(n);
    const __m512d base = _mm512_set1_pd(t.base(y, a.y));
    const double index = double(y * std::int64_t(n) + a.x);
    for (int b = 0; b < Blocks; ++b) {
      const __mmask8 k = _mm512_mask_cmpge_epi64_mask(
          _mm512_mask_cmpge_epi64_mask(_mm512_mask_cmpge_epi64_mask(box[b], edge[0][b], zero), edge[1][b], zero), edge[2][b], zero);
      worst_block512(w, row, t.xmin + 8 * b, k, base, gx, a.x, index);
      for (int e = 0; e < 3; ++e) edge[e][b] = _mm512_add_epi64(edge[e][b], down[e]);
    }
  }
}

// triangle_worst() with AVX-512: call it only when simd_level() is avx512.
// Triangles at most 16 samples wide take worst_narrow512(); wider ones walk
// the rows (RowWalk), blocks of eight from each row's first sample.
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2"))) inline Worst triangle_worst_avx512(
    const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  const GridTriangle t(z, n, a, b, c);
  Worst512 w{_mm512_setzero_pd(), _mm512_setzero_pd()};
  const __m512d gx = _mm512_set1_pd(t.gx);
  if (t.xmax - t.xmin < 8) {
    worst_narrow512<1>(w, z, n, t, a, gx);
  } else if (t.xmax - t.xmin < 16) {
    worst_narrow512<2>(w, z, n, t, a, gx);
  } else {
    RowWalk walk(t);
    for (std::int64_t y = t.y0; y <= t.y1; ++y, walk.next()) {
      std::int64_t lo, hi;
      walk.span(lo, hi);
      const float* row = z + y * std::int64_t(n);
      const __m512d base = _mm512_set1_pd(t.base(y, a.y));
      const double index = double(y * std::int64_t(n) + a.x);  // the row-major index of (a.x, y)
      for (std::int64_t x = lo; x <= hi; x += 8)
        worst_block512(w, row, x, __mmask8(_bzhi_u32(0xFF, unsigned(std::min<std::int64_t>(hi - x + 1, 8)))), base, gx,
                       a.x, index);
    }
  }
  const double worst = _mm512_reduce_max_pd(w.best);
  if (!(worst > 0)) return {};
  const __mmask8 holding = _mm512_cmp_pd_mask(w.best, _mm512_set1_pd(worst), _CMP_EQ_OQ);
  const std::int64_t at = std::int64_t(_mm512_mask_reduce_min_pd(holding, w.at));
  return {worst, {at % std::int64_t(n), at / std::int64_t(n)}};
}
#pragma GCC diagnostic pop
#undef GEODS_TERRAIN_AVX512_INLINE
#endif

// The same largest distance alone (equal to triangle_worst().error): triangles
// of at most 3 x 3 samples (most of the 4-8 hierarchy's) test each sample,
// larger ones take row maxima two doubles at a time.
inline double triangle_error(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  const GridTriangle t(z, n, a, b, c);
  double worst = 0;
  const bool small = t.xmax - t.xmin <= 2 && t.y1 - t.y0 <= 2;
  for (std::int64_t y = t.y0; y <= t.y1; ++y) {
    std::int64_t lo, hi;
    if (small) {
      for (lo = t.xmin; lo <= t.xmax && !t.inside(lo, y);) ++lo;
      for (hi = lo; hi < t.xmax && t.inside(hi + 1, y);) ++hi;
    } else {
      t.row(y, lo, hi);
    }
    if (lo <= hi) worst = std::max(worst, row_max(z + y * std::int64_t(n), lo, hi, t.base(y, a.y), t.gx, a.x));
  }
  return worst;
}

}  // namespace geods::terrain::detail
