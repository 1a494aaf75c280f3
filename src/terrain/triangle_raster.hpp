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
// same rounding: no FMA): for long rows, when simd_level() (core/simd_level.hpp)
// is avx2 or above.
__attribute__((target("avx2"))) inline double row_max_avx2(const float* row, std::int64_t lo, std::int64_t hi, double base,
                                                           double gx, std::int64_t ax) {
  const __m256d vg = _mm256_set1_pd(gx), vb = _mm256_set1_pd(base), sign = _mm256_set1_pd(-0.0), eight = _mm256_set1_pd(8.0);
  const double x = double(lo - ax);
  __m256d x0 = _mm256_set_pd(x + 3, x + 2, x + 1, x), x1 = _mm256_set_pd(x + 7, x + 6, x + 5, x + 4);
  __m256d m0 = _mm256_setzero_pd(), m1 = _mm256_setzero_pd();
  std::int64_t i = lo;
  for (; i + 7 <= hi; i += 8) {
    const __m256d z0 = _mm256_cvtps_pd(_mm_loadu_ps(row + i)), z1 = _mm256_cvtps_pd(_mm_loadu_ps(row + i + 4));
    m0 = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(z0, _mm256_add_pd(vb, _mm256_mul_pd(vg, x0)))), m0);
    m1 = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_sub_pd(z1, _mm256_add_pd(vb, _mm256_mul_pd(vg, x1)))), m1);
    x0 = _mm256_add_pd(x0, eight), x1 = _mm256_add_pd(x1, eight);
  }
  const __m256d mm = _mm256_max_pd(m0, m1);
  const __m128d m2 = _mm_max_pd(_mm256_castpd256_pd128(mm), _mm256_extractf128_pd(mm, 1));
  double m = std::max(_mm_cvtsd_f64(m2), _mm_cvtsd_f64(_mm_unpackhi_pd(m2, m2)));
  for (; i <= hi; ++i) m = std::max(m, std::abs(double(row[i]) - (base + gx * double(i - ax))));
  return m;
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

// The largest |z(sample) - plane(sample)| over the grid samples in the closed
// triangle (a, b, c) (integer grid coordinates) of an n-wide matrix of heights,
// and the sample where it is (the first such in row order). One scalar pass per
// row: for the greedy TIN's triangles of every shape this measured faster than
// SIMD row maxima followed by a search.
inline Worst triangle_worst(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  const GridTriangle t(z, n, a, b, c);
  Worst worst;
  for (std::int64_t y = t.y0; y <= t.y1; ++y) {
    std::int64_t lo, hi;
    t.row(y, lo, hi);
    const float* row = z + y * std::int64_t(n);
    const double base = t.base(y, a.y), gx = t.gx;
    for (std::int64_t x = lo; x <= hi; ++x) {
      const double d = std::abs(double(row[x]) - (base + gx * double(x - a.x)));
      if (d > worst.error) worst = {d, {x, y}};
    }
  }
  return worst;
}

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
