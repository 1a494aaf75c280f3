// AABB, Ray, Plane and the triangle helpers.
#include <gtest/gtest.h>

#include <limits>

#include "geods/core/aabb.hpp"
#include "geods/core/plane.hpp"
#include "geods/core/ray.hpp"
#include "geods/core/rng.hpp"
#include "geods/core/triangle.hpp"

namespace geods {
namespace {

TEST(AABB, EmptyExtendContainsOverlaps) {
  AABB3f box;
  EXPECT_TRUE(box.empty());
  EXPECT_EQ(box.volume(), 0.0f);
  EXPECT_EQ(box.surface_area(), 0.0f);
  box.extend(Vec3f(1, 2, 3)).extend(Vec3f(-1, 0, 5));
  EXPECT_FALSE(box.empty());
  EXPECT_EQ(box.lo, Vec3f(-1, 0, 3));
  EXPECT_EQ(box.hi, Vec3f(1, 2, 5));
  EXPECT_EQ(box.volume(), 8.0f);
  EXPECT_EQ(box.surface_area(), 24.0f);
  EXPECT_EQ(box.longest_axis(), 0);
  EXPECT_TRUE(box.contains(Vec3f(1, 2, 5)));  // closed
  EXPECT_FALSE(box.contains(Vec3f(1, 2, 5.001f)));
  const AABB3f touching(Vec3f(1, 2, 5), Vec3f(3, 3, 6));
  EXPECT_TRUE(box.overlaps(touching));
  EXPECT_FALSE(box.overlaps(AABB3f(Vec3f(1.5f, 0, 0), Vec3f(2, 1, 1))));
  EXPECT_FALSE(box.overlaps(AABB3f()));
  EXPECT_TRUE(box.contains(AABB3f(Vec3f(0, 1, 4), Vec3f(0.5f, 1, 4))));
  EXPECT_EQ(box.squared_distance(Vec3f(3, 2, 5)), 4.0f);
  EXPECT_EQ(box.squared_distance(Vec3f(0, 1, 4)), 0.0f);
}

TEST(AABB, TwoDimensionalDouble) {
  AABB2d box(Vec2d(0, 0), Vec2d(2, 1));
  EXPECT_EQ(box.volume(), 2.0);
  EXPECT_EQ(box.surface_area(), 6.0);  // perimeter
  EXPECT_EQ(box.center(), Vec2d(1, 0.5));
  EXPECT_EQ(box.intersection(AABB2d(Vec2d(1, -1), Vec2d(3, 0.5))), AABB2d(Vec2d(1, 0), Vec2d(2, 0.5)));
}

TEST(Ray, SlabIntervalIncludingAxisParallelRays) {
  const AABB3f box(Vec3f(0, 0, 0), Vec3f(1, 1, 1));
  Ray3f ray{Vec3f(-1, 0.5f, 0.5f), Vec3f(1, 0, 0)};
  const Vec3f inv = ray.direction.cwiseInverse();
  auto [t0, t1] = ray_box_interval(ray, inv, box);
  EXPECT_FLOAT_EQ(t0, 1);
  EXPECT_FLOAT_EQ(t1, 2);
  // Exactly on the y = 0 slab boundary, parallel to it: 0 * inf = NaN must not reject.
  ray.origin = Vec3f(-1, 0, 0.5f);
  std::tie(t0, t1) = ray_box_interval(ray, Vec3f(ray.direction.cwiseInverse()), box);
  EXPECT_LE(t0, t1);
  // Parallel and outside.
  ray.origin = Vec3f(-1, 2, 0.5f);
  std::tie(t0, t1) = ray_box_interval(ray, Vec3f(ray.direction.cwiseInverse()), box);
  EXPECT_GT(t0, t1);
  EXPECT_EQ(ray.at(2), Vec3f(1, 2, 0.5f));
}

TEST(Plane, FromPointsSignedDistanceProjection) {
  const auto plane = Plane3d::from_points(Vec3d(0, 0, 1), Vec3d(1, 0, 1), Vec3d(0, 1, 1));
  EXPECT_NEAR((plane.normal - Vec3d(0, 0, 1)).norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(plane.signed_distance(Vec3d(5, 5, 3)), 2);
  EXPECT_DOUBLE_EQ(plane.flipped().signed_distance(Vec3d(5, 5, 3)), -2);
  EXPECT_EQ(plane.project(Vec3d(5, 5, 3)), Vec3d(5, 5, 1));
}

TEST(Triangle, AreaNormalBarycentric) {
  const Vec3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  EXPECT_DOUBLE_EQ(triangle_area(a, b, c), 2);
  EXPECT_EQ(triangle_normal(a, b, c), Vec3d(0, 0, 4));
  const Vec3d bc = barycentric(Vec3d(0.5, 0.5, 7), a, b, c);
  EXPECT_NEAR((bc - Vec3d(0.5, 0.25, 0.25)).norm(), 0, 1e-15);
  EXPECT_EQ(triangle_bounds(a, b, c), AABB3d(Vec3d(0, 0, 0), Vec3d(2, 2, 0)));
}

TEST(Triangle, HasZeroAreaIsExact) {
  // Corners on a lattice of step 2^-20 (exact in float): collinear ones
  // (a + j d, a + k d) and ones with c moved off the line by one step, against
  // the cross product in integers; scaled by 2^-100 and 2^100 alike.
  Rng rng(5);
  const auto lattice = [&](std::int64_t range) { return std::int64_t(rng.below(std::uint64_t(2 * range + 1))) - range; };
  int zero = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::int64_t p[3][3], d[3];
    for (int x = 0; x < 3; ++x) {
      p[0][x] = lattice(1 << 20);
      d[x] = lattice(7) << 12;
    }
    const std::int64_t j = lattice(8), k = lattice(8);
    for (int x = 0; x < 3; ++x) {
      p[1][x] = p[0][x] + j * d[x];
      p[2][x] = p[0][x] + k * d[x];
    }
    if (rng.below(2)) p[2][rng.below(3)] += rng.below(2) ? 1 : -1;
    std::int64_t e[2][3];
    for (int x = 0; x < 3; ++x) {
      e[0][x] = p[1][x] - p[0][x];
      e[1][x] = p[2][x] - p[0][x];
    }
    bool expected = true;
    for (int x = 0; x < 3; ++x)
      expected &= e[0][(x + 1) % 3] * e[1][(x + 2) % 3] == e[0][(x + 2) % 3] * e[1][(x + 1) % 3];
    zero += expected;
    for (float scale : {0x1p-20f, 0x1p-120f, 0x1p80f}) {
      Vec3f c[3];
      for (int i = 0; i < 3; ++i)
        for (int x = 0; x < 3; ++x) c[i][x] = float(p[i][x]) * scale;
      ASSERT_EQ(has_zero_area(c[0], c[1], c[2]), expected) << "trial " << trial << " scale " << scale;
      ASSERT_EQ(has_zero_area<double>(c[0].cast<double>(), c[1].cast<double>(), c[2].cast<double>()), expected);
    }
  }
  EXPECT_GT(zero, 10000);  // the collinear half, and moves along d's own line
  EXPECT_LT(zero, 15000);
}

// Brute force: the closest of many sampled points of the triangle.
Vec3d sampled_closest(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Vec3d best = a;
  constexpr int n = 120;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const Vec3d q = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
      if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    }
  return best;
}

TEST(Triangle, ClosestPointMatchesSamplingIncludingDegenerate) {
  Rng rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    Vec3d a(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    Vec3d b(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    Vec3d c(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (trial % 10 == 0) c = a + 0.3 * (b - a);  // collinear
    if (trial % 10 == 1) b = c = a;             // a point
    const Vec3d p(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
    const Vec3d q = closest_point_on_triangle(p, a, b, c);
    const double d = (q - p).norm(), d_sampled = (sampled_closest(p, a, b, c) - p).norm();
    EXPECT_LE(d, d_sampled + 1e-12) << "trial " << trial;
    EXPECT_GE(d, d_sampled - 0.05) << "trial " << trial;
  }
}

}  // namespace
}  // namespace geods
