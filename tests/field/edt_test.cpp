// The Euclidean distance transform against brute force (every background
// sample, in double, the same sum order), on random and degenerate masks.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/edt.hpp"

namespace geods::field {
namespace {

Grid3<std::uint8_t> random_labelled_mask(std::size_t nx, std::size_t ny, std::size_t nz, double foreground,
                                         std::uint64_t seed) {
  Rng rng(seed);
  Grid3<std::uint8_t> m(nx, ny, nz);
  for (auto& v : m.data) v = rng.uniform() < foreground ? std::uint8_t(1 + rng.below(255)) : 0;
  return m;
}

struct BruteTransform {
  std::vector<double> squared;
  std::vector<std::uint64_t> feature;
};

// The oracle: for each sample, the nearest background sample by
// ((sx dx)^2 + (sy dy)^2) + (sz dz)^2; ties to the smallest flat index.
BruteTransform brute_force(const Grid3<std::uint8_t>& m, std::array<double, 3> s) {
  const auto [nx, ny, nz] = m.dims;
  BruteTransform b{std::vector<double>(m.size(), std::numeric_limits<double>::infinity()),
                   std::vector<std::uint64_t>(m.size(), EdtResult::kNoFeature)};
  std::vector<std::size_t> background;
  for (std::size_t i = 0; i < m.size(); ++i)
    if (!m.data[i]) background.push_back(i);
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t q = m.index(i, j, k);
        for (const std::size_t f : background) {
          const double dx = s[0] * (double(i) - double(f % nx)), dy = s[1] * (double(j) - double(f / nx % ny)),
                       dz = s[2] * (double(k) - double(f / (nx * ny)));
          const double d = (dx * dx + dy * dy) + dz * dz;
          if (d < b.squared[q]) b.squared[q] = d, b.feature[q] = f;
        }
      }
  return b;
}

void expect_exact(const Grid3<std::uint8_t>& m, std::array<double, 3> s, const std::string& what) {
  const BruteTransform b = brute_force(m, s);
  const EdtResult squared = edt(m.view(), {s, true, true});
  const EdtResult plain = edt(m.view(), {s, false, false});
  ASSERT_EQ(squared.distance.size(), m.size()) << what;
  ASSERT_TRUE(plain.features.empty());
  for (std::size_t q = 0; q < m.size(); ++q) {
    ASSERT_EQ(squared.distance.data[q], b.squared[q]) << what << " sample " << q;
    ASSERT_EQ(squared.features[q], b.feature[q]) << what << " sample " << q;
    ASSERT_EQ(plain.distance.data[q], std::sqrt(b.squared[q])) << what << " sample " << q;
  }
}

TEST(Edt, EqualsBruteForceBitForBitWithIntegerSpacings) {
  std::uint64_t seed = 1;
  for (const double foreground : {0.02, 0.3, 0.7, 0.97})
    for (const auto& dims : {std::array<std::size_t, 3>{13, 11, 9}, {1, 1, 40}, {37, 1, 1}, {24, 19, 1}, {2, 3, 17}})
      for (const auto& s : {std::array<double, 3>{1, 1, 1}, {1, 2, 3}, {5, 1, 2}}) {
        const auto m = random_labelled_mask(dims[0], dims[1], dims[2], foreground, seed++);
        expect_exact(m, s, "mask " + std::to_string(seed));
      }
}

TEST(Edt, DegenerateMasks) {
  // All background: zeros, each sample its own feature.
  Grid3<std::uint8_t> zeros(6, 5, 4, 0);
  expect_exact(zeros, {1, 1, 1}, "all background");
  // One background sample in a corner, another in the middle; a single sample; rows of ties.
  Grid3<std::uint8_t> ones(9, 8, 7, 1);
  ones(0, 0, 0) = 0;
  expect_exact(ones, {1, 1, 1}, "one corner background");
  ones(4, 4, 3) = 0;
  expect_exact(ones, {2, 2, 2}, "two background samples");
  Grid3<std::uint8_t> stripes(16, 16, 1, 1);
  for (std::size_t j = 0; j < 16; j += 4)
    for (std::size_t i = 0; i < 16; ++i) stripes(i, j, 0) = 0;
  expect_exact(stripes, {1, 1, 1}, "stripes (ties between two rows)");
  Grid3<std::uint8_t> one(1, 1, 1, 0);
  expect_exact(one, {1, 1, 1}, "one sample");
  // No background at all: +infinity and no feature, the mask's foreground counted.
  const EdtResult r = edt(Grid3<std::uint8_t>(5, 4, 3, 7).view(), {std::nullopt, false, true});
  EXPECT_EQ(r.foreground, 60u);
  for (std::size_t q = 0; q < 60; ++q) {
    EXPECT_TRUE(std::isinf(r.distance.data[q]));
    EXPECT_EQ(r.features[q], EdtResult::kNoFeature);
  }
  // Empty grids give empty results.
  EXPECT_EQ(edt(Grid3<std::uint8_t>(0, 4, 3).view()).distance.size(), 0u);
}

TEST(Edt, OtherSpacingsAgreeWithBruteForceWithinRounding) {
  std::uint64_t seed = 100;
  for (const double foreground : {0.1, 0.6, 0.95})
    for (const auto& s : {std::array<double, 3>{0.7, 1.3, 2.1}, {0.1, 0.1, 0.35}, {3.7, 0.2, 1}}) {
      const auto m = random_labelled_mask(12, 10, 8, foreground, seed++);
      const BruteTransform b = brute_force(m, s);
      const EdtResult r = edt(m.view(), {s, true, true});
      for (std::size_t q = 0; q < m.size(); ++q) {
        ASSERT_NEAR(r.distance.data[q], b.squared[q], 1e-14 * b.squared[q]) << "sample " << q;
        ASSERT_FALSE(m.data[r.features[q]]) << "the feature is a background sample";
      }
    }
}

TEST(Edt, UsesTheMaskSpacingUnlessTheRequestSetsOne) {
  auto m = random_labelled_mask(10, 9, 8, 0.8, 7);
  m.spacing = Vec3f(2, 1, 3);
  m.origin = Vec3f(-1, 5, 2);
  const EdtResult own = edt(m.view());
  const EdtResult given = edt(m.view(), {std::array<double, 3>{2, 1, 3}});
  EXPECT_EQ(own.distance.data, given.distance.data);
  EXPECT_EQ(own.distance.origin, m.origin);
  EXPECT_EQ(own.distance.spacing, m.spacing);
  const BruteTransform b = brute_force(m, {2, 1, 3});
  for (std::size_t q = 0; q < m.size(); ++q) ASSERT_EQ(own.distance.data[q], std::sqrt(b.squared[q]));
}

TEST(Edt, SameResultOnAnyThreadCount) {
  const auto m = random_labelled_mask(70, 60, 50, 0.9, 11);
  const EdtResult all = edt(m.view(), {std::array<double, 3>{0.9, 1.1, 1.7}, false, true});
  set_num_threads(1);
  const EdtResult one = edt(m.view(), {std::array<double, 3>{0.9, 1.1, 1.7}, false, true});
  set_num_threads(0);
  EXPECT_EQ(all.distance.data, one.distance.data);
  EXPECT_EQ(all.features, one.features);
}

TEST(Edt, RefusesBadSpacingsAndInconsistentViews) {
  const auto m = random_labelled_mask(4, 4, 4, 0.5, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const auto& s : {std::array<double, 3>{0, 1, 1}, {1, -1, 1}, {1, 1, nan}, {inf, 1, 1}, {1e200, 1, 1}, {1, 1e-200, 1}})
    EXPECT_THROW(edt(m.view(), {s}), Error);
  Grid3View<std::uint8_t> short_view(m, std::span<const std::uint8_t>(m.data).first(10));
  EXPECT_THROW(edt(short_view), Error);
}

// edt_pass along every axis in any order from 0 / inf equals edt's squared
// distances bit for bit with integer spacings, also on lines of one sample.
TEST(Edt, PassesInAnyAxisOrderEqualTheTransform) {
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& dims : {std::array<std::size_t, 3>{9, 7, 6}, {1, 8, 5}, {6, 1, 1}}) {
    const auto m = random_labelled_mask(dims[0], dims[1], dims[2], 0.8, 21);
    const std::array<double, 3> s{1, 2, 3};
    const EdtResult r = edt(m.view(), {s, true, false});
    for (const auto& order : {std::array<int, 3>{0, 1, 2}, {2, 1, 0}, {1, 2, 0}}) {
      std::vector<double> g(m.size());
      for (std::size_t i = 0; i < g.size(); ++i) g[i] = m.data[i] ? inf : 0.0;
      for (const int axis : order) edt_pass(g, m.dims, axis, s[std::size_t(axis)]);
      EXPECT_EQ(g, r.distance.data);
    }
  }
  std::vector<double> g(8, 1.0);
  EXPECT_THROW(edt_pass(g, {2, 2, 2}, 3, 1.0), Error);
  EXPECT_THROW(edt_pass(g, {2, 2, 2}, 0, 0.0), Error);
  EXPECT_THROW(edt_pass(g, {2, 2, 3}, 0, 1.0), Error);
}

}  // namespace
}  // namespace geods::field
