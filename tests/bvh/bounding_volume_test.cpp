// Bounding volumes against sampling oracles, in float and double.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "geods/bvh/aabb_bv.hpp"
#include "geods/bvh/kdop.hpp"
#include "geods/bvh/obb.hpp"
#include "geods/bvh/sphere.hpp"
#include "geods/core/rng.hpp"

namespace geods::bvh {
namespace {

template <typename T>
std::vector<Vec<T, 3>> cloud(Rng& rng, int n, const Vec<T, 3>& center, T scale) {
  // A flattened, rotated blob: the volumes differ in tightness on it.
  std::vector<Vec<T, 3>> pts;
  const T c = T(std::cos(0.7)), s = T(std::sin(0.7));
  for (int i = 0; i < n; ++i) {
    const Vec<T, 3> p(T(rng.uniform(-1, 1)), T(rng.uniform(-0.3, 0.3)), T(rng.uniform(-0.6, 0.6)));
    pts.push_back(center + scale * Vec<T, 3>(c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]));
  }
  return pts;
}

template <typename T, typename Fit>
void check_volume(Fit fit, bool exact_overlap) {
  Rng rng(5);
  for (int trial = 0; trial < 40; ++trial) {
    const auto pa = cloud<T>(rng, 30, Vec<T, 3>(T(rng.uniform(-1, 1)), T(rng.uniform(-1, 1)), T(0)), T(1));
    const auto pb = cloud<T>(rng, 30, Vec<T, 3>(T(rng.uniform(-1, 1)), T(0), T(rng.uniform(-1, 1))), T(0.5));
    const auto a = fit(pa), b = fit(pb);
    for (const auto& p : pa) ASSERT_TRUE(contains(a, p));
    const auto m = merge(a, b);
    for (const auto& p : pa) ASSERT_TRUE(contains(m, p));
    for (const auto& p : pb) ASSERT_TRUE(contains(m, p));
    // Sample the bounding box: estimates volume, checks overlap, distances and rays.
    const AABB<T, 3> box = bounds(a);
    for (const auto& p : pa) ASSERT_TRUE(box.contains(p));
    int inside = 0, common = 0;
    const int samples = 4000;
    for (int k = 0; k < samples; ++k) {
      const Vec<T, 3> q = box.lo + Vec<T, 3>(T(rng.uniform()), T(rng.uniform()), T(rng.uniform())).cwiseProduct(box.hi - box.lo);
      const bool in_a = contains(a, q);
      inside += in_a;
      if (in_a && contains(b, q)) ++common;
      // The distance bound never exceeds the distance to a point inside.
      const Vec<T, 3> far(T(3), T(-2), T(1));
      if (in_a) {
        ASSERT_LE(std::sqrt(double(squared_distance(a, far))), (far - q).norm() * (1 + 1e-5));
      }
      // A ray through an inside point has that point in its interval.
      if (in_a && k % 10 == 0) {
        Ray<T> ray;
        ray.origin = q - T(3) * Vec<T, 3>(T(0.6), T(0.48), T(0.64));
        ray.direction = Vec<T, 3>(T(0.6), T(0.48), T(0.64));
        const Vec<T, 3> inv = ray.direction.cwiseInverse();
        const auto iv = ray_interval(a, ray, inv);
        ASSERT_LE(iv.first, T(3) * (1 + T(1e-4)));
        ASSERT_GE(iv.second, T(3) * (1 - T(1e-4)));
      }
    }
    if (common > 0) {
      ASSERT_TRUE(overlaps(a, b));
    }
    if (exact_overlap && !overlaps(a, b)) {
      ASSERT_EQ(common, 0);
    }
    const double estimate = double(inside) / samples * double(box.volume());
    EXPECT_NEAR(double(volume(a)), estimate, 0.06 * double(box.volume()) + 1e-9);
    EXPECT_TRUE(contains(m, a));
    EXPECT_GE(double(surface_area(m)), 0.0);
  }
}

TEST(BoundingVolumes, Aabb) {
  check_volume<float>([](const auto& p) { return fit_aabb<float>(p); }, true);
  check_volume<double>([](const auto& p) { return fit_aabb<double>(p); }, true);
}
TEST(BoundingVolumes, Sphere) {
  check_volume<float>([](const auto& p) { return fit_sphere<float>(p); }, true);
  check_volume<double>([](const auto& p) { return fit_sphere<double>(p); }, true);
}
TEST(BoundingVolumes, Obb) {
  check_volume<float>([](const auto& p) { return fit_obb<float>(p); }, true);
  check_volume<double>([](const auto& p) { return fit_obb<double>(p); }, true);
}
TEST(BoundingVolumes, Kdops) {
  check_volume<float>([](const auto& p) { return fit_kdop<float, 6>(p); }, true);
  check_volume<float>([](const auto& p) { return fit_kdop<float, 14>(p); }, false);
  check_volume<double>([](const auto& p) { return fit_kdop<double, 18>(p); }, false);
  check_volume<double>([](const auto& p) { return fit_kdop<double, 26>(p); }, false);
}

TEST(BoundingVolumes, KdopMeasuresOfKnownShapes) {
  // The 6-DOP of a box is the box; the 14-DOP of a cube's corners is the cube;
  // the 26-DOP of the octahedron's vertices is the octahedron (volume 4/3).
  const std::vector<Vec3d> cube = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {2, 2, 0}, {2, 0, 2}, {0, 2, 2}, {2, 2, 2}};
  const auto k6 = fit_kdop<double, 6>(cube);
  EXPECT_NEAR(volume(k6), 8.0, 1e-9);
  EXPECT_NEAR(surface_area(k6), 24.0, 1e-9);
  EXPECT_NEAR(volume(fit_kdop<double, 14>(cube)), 8.0, 1e-9);
  const std::vector<Vec3d> octa = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const auto k26 = fit_kdop<double, 26>(octa);
  EXPECT_NEAR(volume(k26), 4.0 / 3.0, 1e-9);
  EXPECT_NEAR(surface_area(k26), 8 * std::sqrt(3.0) / 2, 1e-9);  // 8 equilateral faces of side sqrt(2)
  const auto k14 = fit_kdop<double, 14>(octa);
  EXPECT_NEAR(volume(k14), 4.0 / 3.0, 1e-9);
  // A sphere's volume and area.
  Sphere3d s;
  s.radius = 2;
  EXPECT_NEAR(volume(s), 32.0 / 3.0 * std::numbers::pi, 1e-9);
  EXPECT_NEAR(surface_area(s), 16 * std::numbers::pi, 1e-9);
}

TEST(BoundingVolumes, SeparatedObbsDoNotOverlap) {
  Obb3d a, b;
  a.half = Vec3d(1, 1, 1);
  b.half = Vec3d(1, 1, 1);
  b.axes = Eigen::AngleAxisd(std::numbers::pi / 4, Vec3d::UnitZ()).toRotationMatrix();
  b.center = Vec3d(1 + std::sqrt(2.0) + 1e-4, 0, 0);
  EXPECT_FALSE(overlaps(a, b));
  b.center[0] -= 2e-3;
  EXPECT_TRUE(overlaps(a, b));
  EXPECT_FALSE(contains(a, b));
}

TEST(BoundingVolumes, PlaneSides) {
  const Plane3d plane{Vec3d(0, 0, 1), 1.0};  // z = 1, positive above
  EXPECT_TRUE(above(AABB3d(Vec3d(0, 0, 1.5), Vec3d(1, 1, 2)), plane));
  EXPECT_FALSE(above(AABB3d(Vec3d(0, 0, 0.5), Vec3d(1, 1, 2)), plane));
  Sphere3d s;
  s.center = Vec3d(0, 0, 3);
  s.radius = 1.5;
  EXPECT_TRUE(above(s, plane));
  s.radius = 2.5;
  EXPECT_FALSE(above(s, plane));
}

}  // namespace
}  // namespace geods::bvh
