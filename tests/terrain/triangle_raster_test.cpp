// The terrain module's triangle rasterizers (the per-sample path of small
// triangles, SIMD row maxima, the scalar worst-sample scan) against brute force: every sample of the bounding box tested with
// exact integer edge functions, the same plane; the largest distance and the
// first sample (row order) holding it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "../../src/terrain/triangle_raster.hpp"
#include "geods/core/simd_level.hpp"

namespace geods::terrain::detail {
namespace {

Worst brute_worst(const std::vector<float>& z, std::int64_t n, P2 a, P2 b, P2 c) {
  auto edge = [](P2 p, P2 q, std::int64_t x, std::int64_t y) { return (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x); };
  const double za = z[a.y * n + a.x], zb = z[b.y * n + b.x], zc = z[c.y * n + c.x];
  const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
  const double det = ux * vy - uy * vx;
  const double gx = ((zb - za) * vy - (zc - za) * uy) / det, gy = ((zc - za) * ux - (zb - za) * vx) / det;
  const double s = det < 0 ? -1 : 1;
  Worst w;
  for (std::int64_t y = std::min({a.y, b.y, c.y}); y <= std::max({a.y, b.y, c.y}); ++y)
    for (std::int64_t x = std::min({a.x, b.x, c.x}); x <= std::max({a.x, b.x, c.x}); ++x) {
      if (s * double(edge(a, b, x, y)) < 0 || s * double(edge(b, c, x, y)) < 0 || s * double(edge(c, a, x, y)) < 0) continue;
      const double d = std::abs(double(z[y * n + x]) - ((za + gy * double(y - a.y)) + gx * double(x - a.x)));
      if (d > w.error) w = {d, {x, y}};
    }
  return w;
}

TEST(TriangleRaster, WorstSampleEqualsBruteForce) {
  std::mt19937_64 rng(11);
  const std::int64_t n = 80;
  std::vector<float> z(std::size_t(n * n));
  for (float& v : z) v = float(rng() % 40);  // integer heights: many exact ties
  int checked = 0;
  const bool avx2 = simd_level() >= SimdLevel::avx2;
  const bool avx512 = simd_level() >= SimdLevel::avx512;
  for (int it = 0; it < 20000; ++it) {
    const std::int64_t span = it % 4 == 0 ? 3 : it % 4 == 1 ? 8 : it % 4 == 2 ? 15 : n - 1;
    auto r = [&] { return std::int64_t(rng() % std::uint64_t(span + 1)); };
    const std::int64_t ox = std::int64_t(rng() % std::uint64_t(n - span)), oy = std::int64_t(rng() % std::uint64_t(n - span));
    P2 a{ox + r(), oy + r()}, b{ox + r(), oy + r()}, c{ox + r(), oy + r()};
    if (it % 3 == 0) b = {a.x + span / 2 + 1, a.y}, c = {a.x, a.y + span / 2 + 1};  // axis-aligned legs (4-8 triangles)
    if (b.x >= n || c.y >= n || (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) == 0) continue;
    const Worst want = brute_worst(z, n, a, b, c), got = triangle_worst(z.data(), std::uint64_t(n), a, b, c);
    ASSERT_EQ(got.error, want.error) << it;
    ASSERT_EQ(got.at.x, want.at.x) << it;
    ASSERT_EQ(got.at.y, want.at.y) << it;
#if defined(__x86_64__) && defined(__GNUC__)
    if (avx2) {  // AVX2 rows (blocks of four ending at each row's end): the same value and sample
      const Worst got2 = triangle_worst_avx2(z.data(), std::uint64_t(n), a, b, c);
      ASSERT_EQ(got2.error, want.error) << it;
      ASSERT_EQ(got2.at.x, want.at.x) << it;
      ASSERT_EQ(got2.at.y, want.at.y) << it;
    }
    if (avx512) {  // AVX-512 blocks of eight, masked, per-lane maxima and first indices
      const Worst got3 = triangle_worst_avx512(z.data(), std::uint64_t(n), a, b, c);
      ASSERT_EQ(got3.error, want.error) << it;
      ASSERT_EQ(got3.at.x, want.at.x) << it;
      ASSERT_EQ(got3.at.y, want.at.y) << it;
    }
#endif
    ASSERT_EQ(triangle_error(z.data(), std::uint64_t(n), a, b, c), want.error) << it;
    ++checked;
  }
  EXPECT_GT(checked, 15000);
}

// The rows walked by additions (RowWalk) are the rows of GridTriangle::row()
// (exact integer divisions), on thin, steep and long triangles too.
TEST(TriangleRaster, RowWalkEqualsRowDivisions) {
  std::mt19937_64 rng(5);
  const std::vector<float> z(std::size_t(1) << 20, 0.0f);
  const std::uint64_t n = 1024;
  for (int it = 0; it < 20000; ++it) {
    const std::int64_t span = it % 3 == 0 ? 4 : it % 3 == 1 ? 40 : 1000;
    auto r = [&] { return std::int64_t(rng() % std::uint64_t(span + 1)); };
    const P2 a{r(), r()}, b{r(), r()}, c{r(), r()};
    if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) == 0) continue;
    const GridTriangle t(z.data(), n, a, b, c);
    RowWalk walk(t);
    for (std::int64_t y = t.y0; y <= t.y1; ++y, walk.next()) {
      std::int64_t lo, hi, wlo, whi;
      t.row(y, lo, hi);
      walk.span(wlo, whi);
      if (lo > hi) {
        ASSERT_GT(wlo, whi) << it << " " << y;
      } else {
        ASSERT_EQ(wlo, lo) << it << " " << y;
        ASSERT_EQ(whi, hi) << it << " " << y;
      }
    }
  }
}

}  // namespace
}  // namespace geods::terrain::detail
