// Grid3, Image, Rng, DType, Progress and the parallel helpers.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <numeric>
#include <set>

#include "geods/core/dtype.hpp"
#include "geods/core/error.hpp"
#include "geods/core/grid3.hpp"
#include "geods/core/image.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/progress.hpp"
#include "geods/core/rng.hpp"

namespace geods {
namespace {

TEST(Grid3, IndexingIsXFastestAndPositionsUseOriginAndSpacing) {
  Grid3<float> g(4, 3, 2, 0.5f);
  EXPECT_EQ(g.size(), 24u);
  EXPECT_EQ(g.index(1, 0, 0), 1u);
  EXPECT_EQ(g.index(0, 1, 0), 4u);
  EXPECT_EQ(g.index(0, 0, 1), 12u);
  g(3, 2, 1) = 7;
  EXPECT_EQ(g.data.back(), 7);
  g.origin = Vec3f(1, 2, 3);
  g.spacing = Vec3f(0.5f, 1, 2);
  EXPECT_EQ(g.position(2, 1, 1), Vec3f(2, 3, 5));
  EXPECT_EQ(g.bounds(), AABB3f(Vec3f(1, 2, 3), Vec3f(2.5f, 4, 5)));
  EXPECT_TRUE(Grid3<float>().bounds().empty());
}

TEST(Grid3, ViewReadsTheSamplesInPlaceWithTheSameGeometry) {
  for (const std::array<std::size_t, 3> dims : {std::array<std::size_t, 3>{4, 3, 2}, {1, 1, 1}, {0, 0, 0}, {0, 2, 3}}) {
    Grid3<int> g(dims[0], dims[1], dims[2]);
    std::iota(g.data.begin(), g.data.end(), 1);
    g.origin = Vec3f(1, 2, 3);
    g.spacing = Vec3f(0.5f, -1, 2);
    const Grid3View<int> v = g.view();
    EXPECT_EQ(v.data.data(), g.data.data());  // no copy
    EXPECT_EQ(v.size(), g.size());
    EXPECT_EQ(v.dims, g.dims);
    EXPECT_EQ(v.bounds(), g.bounds());
    if (g.size() == 0) {
      EXPECT_TRUE(v.bounds().empty());
    }
    std::size_t n = 0;
    for (std::size_t k = 0; k < dims[2]; ++k)
      for (std::size_t j = 0; j < dims[1]; ++j)
        for (std::size_t i = 0; i < dims[0]; ++i, ++n) {
          EXPECT_EQ(v.index(i, j, k), n);  // x fastest, as Grid3
          EXPECT_EQ(&v(i, j, k), &g(i, j, k));
          EXPECT_EQ(v.position(i, j, k), g.position(i, j, k));
        }
  }
}

TEST(Grid3, OverflowingDimensionsThrow) {
  EXPECT_THROW(Grid3<double>(std::size_t(1) << 40, std::size_t(1) << 40, 16), Error);
}

TEST(Grid3, PaddedKeepsEverySampleInPlaceInsideABorder) {
  for (const std::array<std::size_t, 3> dims : {std::array<std::size_t, 3>{4, 3, 2}, {1, 1, 1}, {0, 0, 0}, {0, 2, 3}}) {
    Grid3<int> g(dims[0], dims[1], dims[2]);
    std::iota(g.data.begin(), g.data.end(), 1);
    g.origin = Vec3f(1, 2, 3);
    g.spacing = Vec3f(0.5f, 1, 2);
    const Grid3<int> p = padded(g, -7);
    ASSERT_EQ(p.dims, (std::array<std::size_t, 3>{dims[0] + 2, dims[1] + 2, dims[2] + 2}));
    EXPECT_EQ(p.spacing, g.spacing);
    // Each sample: g's sample one step in from p's, at the same position, or the border.
    for (std::size_t k = 0; k < p.dims[2]; ++k)
      for (std::size_t j = 0; j < p.dims[1]; ++j)
        for (std::size_t i = 0; i < p.dims[0]; ++i) {
          const bool inside = i >= 1 && i <= dims[0] && j >= 1 && j <= dims[1] && k >= 1 && k <= dims[2];
          EXPECT_EQ(p(i, j, k), inside ? g(i - 1, j - 1, k - 1) : -7) << i << " " << j << " " << k;
          if (inside) {
            EXPECT_EQ(p.position(i, j, k), g.position(i - 1, j - 1, k - 1));
          }
        }
  }
}

TEST(Image, ChannelsInterleaved) {
  Image<std::uint8_t> img(3, 2, 4);
  img(2, 1, 3) = 9;
  EXPECT_EQ(img.data[(1 * 3 + 2) * 4 + 3], 9);
  EXPECT_THROW(Image<float>(std::size_t(1) << 62, 4, 1), Error);
}

TEST(Rng, DeterministicAndWellSpread) {
  Rng a(42), b(42), c(43);
  for (int i = 0; i < 100; ++i) {
    const auto x = a();
    EXPECT_EQ(x, b());
    EXPECT_NE(x, c());
  }
  Rng r(1);
  double sum = 0, sum2 = 0;
  std::set<std::uint64_t> small;
  constexpr int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    const double g = r.normal();
    sum2 += g * g;
    small.insert(r.below(10));
  }
  EXPECT_NEAR(sum / n, 0.5, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.02);
  EXPECT_EQ(small.size(), 10u);
  EXPECT_EQ(*small.rbegin(), 9u);
}

TEST(DType, NamesRoundTripAndUnknownThrows) {
  for (DType t : {DType::u8, DType::i16, DType::f32, DType::f64, DType::u64}) EXPECT_EQ(parse_dtype(dtype_name(t)), t);
  EXPECT_EQ(dtype_size(DType::i16), 2u);
  EXPECT_THROW(parse_dtype("float128"), Error);
}

TEST(Progress, ReportsFractionsAndCancels) {
  std::vector<double> seen;
  ProgressCallback cb = [&](std::string_view stage, double f) {
    EXPECT_EQ(stage, "work");
    seen.push_back(f);
    return true;
  };
  Progress p(cb, "work", 1000);
  for (int i = 0; i <= 1000; ++i) p.update(i);
  p.finish();
  ASSERT_GE(seen.size(), 3u);
  EXPECT_LE(seen.size(), 210u);  // throttled
  EXPECT_EQ(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));

  ProgressCallback cancel = [](std::string_view, double f) { return f < 0.5; };
  Progress q(cancel, "build", 10);
  EXPECT_THROW(
      {
        for (int i = 0; i <= 10; ++i) q.update(i);
      },
      Error);
  Progress silent({}, "nothing", 5);  // no callback: no-op
  silent.update(3);
}

TEST(Parallel, CoversEveryIndexOnceAndHonoursThreadLimit) {
  std::vector<std::atomic<int>> hits(100000);
  parallel_for(0, hits.size(), 1000, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) hits[i]++;
  });
  for (const auto& h : hits) ASSERT_EQ(h.load(), 1);
  set_num_threads(1);
  EXPECT_EQ(num_threads(), 1);
  std::atomic<long> sum = 0;
  parallel_for_each_index(0, 1000, [&](std::size_t i) { sum += long(i); });
  EXPECT_EQ(sum.load(), 999 * 1000 / 2);
  set_num_threads(0);
  EXPECT_GE(num_threads(), 1);
  parallel_for(5, 5, 1, [](std::size_t, std::size_t) { FAIL() << "empty range must not call the body"; });
}

}  // namespace
}  // namespace geods
