#include "geods/core/morton.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "geods/core/rng.hpp"

namespace geods {
namespace {

// Bit-by-bit interleaving: the oracle for the magic-number implementations.
std::uint64_t interleave(const std::uint32_t* coords, int dims, int bits) {
  std::uint64_t code = 0;
  for (int b = 0; b < bits; ++b)
    for (int d = 0; d < dims; ++d) code |= std::uint64_t((coords[d] >> b) & 1u) << (b * dims + d);
  return code;
}

TEST(Morton, EncodeMatchesBitInterleavingAndDecodeInverts) {
  Rng rng(7);
  for (int i = 0; i < 20000; ++i) {
    const std::uint32_t r[3] = {std::uint32_t(rng()), std::uint32_t(rng()), std::uint32_t(rng())};
    {
      const std::uint32_t c[2] = {r[0] & 0xffffu, r[1] & 0xffffu};
      const std::uint32_t code = morton2d_encode32(c[0], c[1]);
      EXPECT_EQ(code, interleave(c, 2, 16));
      EXPECT_EQ(morton2d_decode32(code), (Vec<std::uint32_t, 2>(c[0], c[1])));
    }
    {
      const std::uint32_t c[2] = {r[0], r[1]};
      const std::uint64_t code = morton2d_encode64(c[0], c[1]);
      EXPECT_EQ(code, interleave(c, 2, 32));
      EXPECT_EQ(morton2d_decode64(code), (Vec<std::uint32_t, 2>(c[0], c[1])));
    }
    {
      const std::uint32_t c[3] = {r[0] & 0x3ffu, r[1] & 0x3ffu, r[2] & 0x3ffu};
      const std::uint32_t code = morton3d_encode32(c[0], c[1], c[2]);
      EXPECT_EQ(code, interleave(c, 3, 10));
      EXPECT_EQ(morton3d_decode32(code), Vec3u(c[0], c[1], c[2]));
    }
    {
      const std::uint32_t c[3] = {r[0] & 0x1fffffu, r[1] & 0x1fffffu, r[2] & 0x1fffffu};
      const std::uint64_t code = morton3d_encode64(c[0], c[1], c[2]);
      EXPECT_EQ(code, interleave(c, 3, 21));
      EXPECT_EQ(morton3d_decode64(code), Vec3u(c[0], c[1], c[2]));
    }
  }
}

TEST(Morton, ExtremeValues) {
  EXPECT_EQ(morton2d_encode32(0xffff, 0xffff), 0xffffffffu);
  EXPECT_EQ(morton3d_encode32(0x3ff, 0x3ff, 0x3ff), 0x3fffffffu);
  EXPECT_EQ(morton3d_encode64(0x1fffff, 0x1fffff, 0x1fffff), 0x7fffffffffffffffull);
  EXPECT_EQ(morton2d_encode64(0xffffffffu, 0), 0x5555555555555555ull);
  // Bits beyond capacity are ignored.
  EXPECT_EQ(morton3d_encode32(0x400, 0, 0), 0u);
}

TEST(Morton, OrderVisitsQuadrantsInZOrder) {
  // Four points, one per quadrant of the unit square: Z order is (0,0), (1,0), (0,1), (1,1).
  const std::vector<Vec2d> points = {{0.9, 0.9}, {0.1, 0.9}, {0.9, 0.1}, {0.1, 0.1}};
  EXPECT_EQ(morton_order(points), (std::vector<std::uint32_t>{3, 2, 1, 0}));
}

TEST(Morton, OrderIsAPermutationAndSortsCodes) {
  Rng rng(3);
  std::vector<Vec3d> points(5000);
  for (auto& p : points) p = {rng.uniform(), rng.uniform(-5, 5), rng.uniform(1e-3, 2e-3)};
  points[10] = points[20];  // a duplicate keeps both indices
  const std::vector<std::uint32_t> order = morton_order(points);
  std::vector<std::uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (std::uint32_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);
  const auto codes = morton_codes(points, bounds_of<double, 3>(points));
  for (std::size_t i = 1; i < order.size(); ++i) ASSERT_LE(codes[order[i - 1]], codes[order[i]]);
}

TEST(Morton, EmptyAndSinglePoint) {
  EXPECT_TRUE(morton_order(std::vector<Vec2d>{}).empty());
  EXPECT_EQ(morton_order(std::vector<Vec2d>{{1, 2}}), (std::vector<std::uint32_t>{0}));
}

}  // namespace
}  // namespace geods
