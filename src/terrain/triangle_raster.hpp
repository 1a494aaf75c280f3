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
    if (d > m) m = d;
  }
  return m;
}

// Calls f(y, lo, hi, base, gx) for every row y of the closed triangle (a, b, c)
// (integer grid coordinates) with samples lo..hi inside it; the plane through
// the three heights is z = base + gx (x - a.x) on that row. Triangles of at
// most 3 x 3 samples (most of the 4-8 hierarchy's) test each sample.
template <class F>
inline void for_each_triangle_row(const float* z, std::uint64_t n, P2 a, P2 b, P2 c, F&& f) {
  const double za = z[a.y * n + a.x], zb = z[b.y * n + b.x], zc = z[c.y * n + c.x];
  // Plane z = za + gx (x - ax) + gy (y - ay).
  const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
  const double det = ux * vy - uy * vx;
  const double gx = ((zb - za) * vy - (zc - za) * uy) / det;
  const double gy = ((zc - za) * ux - (zb - za) * vx) / det;
  // Edge functions, made >= 0 inside: E(x, y) = (q.x - p.x) (y - p.y) - (q.y - p.y) (x - p.x)
  // >= 0, i.e. A x <= B(y) with A = q.y - p.y, B(y) = (q.x - p.x) (y - p.y) + A p.x.
  P2 v[3] = {a, b, c};
  if (det < 0) std::swap(v[1], v[2]);
  const std::int64_t y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
  const std::int64_t xmin = std::min({a.x, b.x, c.x}), xmax = std::max({a.x, b.x, c.x});
  if (xmax - xmin <= 2 && y1 - y0 <= 2) {
    // At most 3 x 3 samples (most of the 4-8 triangles): each one tested.
    auto inside = [&](std::int64_t x, std::int64_t y) {
      for (int e = 0; e < 3; ++e) {
        const P2 p = v[e], q = v[(e + 1) % 3];
        if ((q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x) < 0) return false;
      }
      return true;
    };
    for (std::int64_t y = y0; y <= y1; ++y) {
      std::int64_t lo = xmin;
      while (lo <= xmax && !inside(lo, y)) ++lo;
      if (lo > xmax) continue;
      std::int64_t hi = lo;
      while (hi < xmax && inside(hi + 1, y)) ++hi;
      f(y, lo, hi, za + gy * double(y - a.y), gx);
    }
    return;
  }
  for (std::int64_t y = y0; y <= y1; ++y) {
    std::int64_t lo = xmin, hi = xmax;
    for (int e = 0; e < 3; ++e) {
      const P2 p = v[e], q = v[(e + 1) % 3];
      // E(x, y) = (q.x - p.x) (y - p.y) - (q.y - p.y) (x - p.x) >= 0, i.e. A x <= B.
      const std::int64_t A = q.y - p.y, B = (q.x - p.x) * (y - p.y) + (q.y - p.y) * p.x;
      if (A > 0)
        hi = std::min(hi, B >= 0 ? B / A : -((-B + A - 1) / A));
      else if (A < 0)
        lo = std::max(lo, (-B) >= 0 ? ((-B) + (-A) - 1) / (-A) : -((B) / (-A)));
      else if (B < 0)
        lo = hi + 1;
    }
    if (lo > hi) continue;
    // Relative to a: the same rounding wherever the triangle lies (tin_tile() of a block equals the tile of tin()).
    f(y, lo, hi, za + gy * double(y - a.y), gx);
  }
}

// The largest |z(sample) - plane(sample)| over the grid samples in the closed
// triangle (a, b, c) (integer grid coordinates) of an n-wide matrix of heights,
// and the sample where it is (the first such in row order). One scalar pass per
// row: for the greedy TIN's triangles of every shape this measured faster than
// the SIMD row maxima of triangle_error() followed by a search.
inline Worst triangle_worst(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  const double za = z[a.y * n + a.x], zb = z[b.y * n + b.x], zc = z[c.y * n + c.x];
  const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
  const double det = ux * vy - uy * vx;
  const double gx = ((zb - za) * vy - (zc - za) * uy) / det;
  const double gy = ((zc - za) * ux - (zb - za) * vx) / det;
  P2 v[3] = {a, b, c};
  if (det < 0) std::swap(v[1], v[2]);
  const std::int64_t y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
  const std::int64_t xmin = std::min({a.x, b.x, c.x}), xmax = std::max({a.x, b.x, c.x});
  Worst worst;
  for (std::int64_t y = y0; y <= y1; ++y) {
    std::int64_t lo = xmin, hi = xmax;
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
    const float* row = z + y * std::int64_t(n);
    const double base = za + gy * double(y - a.y);
    for (std::int64_t x = lo; x <= hi; ++x) {
      const double d = std::abs(double(row[x]) - (base + gx * double(x - a.x)));
      if (d > worst.error) worst = {d, {x, y}};
    }
  }
  return worst;
}

inline double triangle_error(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  double worst = 0;
  for_each_triangle_row(z, n, a, b, c, [&](std::int64_t y, std::int64_t lo, std::int64_t hi, double base, double gx) {
    worst = std::max(worst, row_max(z + y * std::int64_t(n), lo, hi, base, gx, a.x));
  });
  return worst;
}

}  // namespace geods::terrain::detail
