// Bounding volumes against sampling oracles, in float and double.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "geods/bvh/aabb_bv.hpp"
#include "geods/bvh/kdop.hpp"
#include "geods/bvh/obb.hpp"
#include "geods/bvh/rss.hpp"
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
  check_volume<float>([](const auto& p) { return fit_obb<float>(p, ObbFit::hull); }, true);
  check_volume<double>([](const auto& p) { return fit_obb<double>(p, ObbFit::hull); }, true);
}
TEST(BoundingVolumes, Rss) {
  check_volume<float>([](const auto& p) { return fit_rss<float>(p); }, true);
  check_volume<double>([](const auto& p) { return fit_rss<double>(p); }, true);
  // Flat, linear and single-point sets.
  const std::vector<Vec3d> flat = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, {1, 0.5, 0}};
  const Rss3d f = fit_rss<double>(flat);
  for (const Vec3d& p : flat) EXPECT_TRUE(contains(f, p));
  EXPECT_LT(f.radius, 1e-5);
  EXPECT_NEAR(surface_area(f), 4.0, 1e-3);  // both sides of the 2 x 1 rectangle
  const std::vector<Vec3d> line = {{0, 0, 0}, {1, 2, 3}, {2, 4, 6}};
  for (const Vec3d& p : line) EXPECT_TRUE(contains(fit_rss<double>(line), p));
  EXPECT_TRUE(contains(fit_rss<double>(std::vector<Vec3d>{{5, 5, 5}}), Vec3d(5, 5, 5)));
}

// Distance from p to the rectangle {c + u e0 + v e1 : |u| <= h0, |v| <= h1} (projection, clamped).
double point_rectangle(const Vec3d& p, const Vec3d& c, const Vec3d& e0, const Vec3d& e1, double h0, double h1) {
  const Vec3d d = p - c;
  const double u = std::clamp(d.dot(e0), -h0, h0), v = std::clamp(d.dot(e1), -h1, h1);
  return (d - u * e0 - v * e1).norm();
}

// Oracle: the least distance from points sampled densely along each
// rectangle's edges to the other rectangle (exact projection), and whether
// a dense sample of one rectangle crosses the other's plane inside it. The
// sampled distance is never below the true one and at most a sample step above.
TEST(BoundingVolumes, RectangleDistanceMatchesSampling) {
  Rng rng(17);
  int touching = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const double a0 = rng.uniform(0, 1), a1 = rng.uniform(0, 1), b0 = rng.uniform(0, 1), b1 = rng.uniform(0, 1);
    Eigen::Matrix3d r = Eigen::Quaterniond(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
                            .normalized()
                            .toRotationMatrix();
    if (trial % 10 == 0) r = Eigen::AngleAxisd(rng.uniform(0, 3), Vec3d::UnitZ()).toRotationMatrix();  // parallel planes
    Vec3d c(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-1, 1));
    if (trial % 10 == 0 && trial % 20 == 0) c[2] = 0;  // coplanar
    const double got = rectangle_distance<double>(r, c, a0, a1, b0, b1);
    const int n = 400;
    double sampled = std::numeric_limits<double>::infinity();
    const Vec3d ex = Vec3d::UnitX(), ey = Vec3d::UnitY(), o = Vec3d::Zero();
    auto edges = [&](const Vec3d& cen, const Vec3d& e0, const Vec3d& e1, double h0, double h1, auto&& other) {
      for (int k = 0; k <= n; ++k) {
        const double t = -1 + 2.0 * k / n;
        for (double s : {-1.0, 1.0}) {
          sampled = std::min(sampled, other(cen + s * h0 * e0 + t * h1 * e1));
          sampled = std::min(sampled, other(cen + t * h0 * e0 + s * h1 * e1));
        }
      }
    };
    edges(o, ex, ey, a0, a1, [&](const Vec3d& p) { return point_rectangle(p, c, r.col(0), r.col(1), b0, b1); });
    edges(c, r.col(0), r.col(1), b0, b1, [&](const Vec3d& p) { return point_rectangle(p, o, ex, ey, a0, a1); });
    const double step = 2.0 * std::max({a0, a1, b0, b1}) / n;
    ASSERT_LE(got, sampled + 1e-12) << trial;
    ASSERT_GE(got, sampled - step) << trial;
    touching += got == 0;
    // The volumes' overlap agrees: the swept spheres meet iff the distance is below both radii.
    Rss3d A, B;
    A.half = Vec2d(a0, a1);
    A.radius = 0.1;
    B.axes = r;
    B.center = c;
    B.half = Vec2d(b0, b1);
    B.radius = 0.2;
    EXPECT_EQ(overlaps(A, B), got <= 0.3) << trial;
    EXPECT_NEAR(rectangle_distance(A, B), got, 1e-12);
  }
  EXPECT_GT(touching, 10);
}

// Volume of the box along the points' principal axes (the classic fit,
// computed here independently as the oracle the hull fit must not exceed).
double pca_box_volume(const std::vector<Vec3d>& pts) {
  Vec3d mean = Vec3d::Zero();
  for (const Vec3d& p : pts) mean += p;
  mean /= double(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3d& p : pts) cov += (p - mean) * (p - mean).transpose();
  const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
  Vec3d lo = Vec3d::Constant(1e300), hi = -lo;
  for (const Vec3d& p : pts) {
    lo = lo.cwiseMin(axes.transpose() * p);
    hi = hi.cwiseMax(axes.transpose() * p);
  }
  return (hi - lo).prod();
}

TEST(BoundingVolumes, ObbFitIsTighterThanPrincipalAxes) {
  Rng rng(8);
  const Eigen::Matrix3d rot = (Eigen::AngleAxisd(0.4, Vec3d(1, 2, 3).normalized()) *
                               Eigen::AngleAxisd(1.1, Vec3d::UnitZ())).toRotationMatrix();
  for (int trial = 0; trial < 30; ++trial) {
    // A rotated box with its corners, points on its faces and a dense cluster
    // near one corner, which tilts the principal axes away from the box.
    const Vec3d ext(rng.uniform(0.5, 3), rng.uniform(0.5, 3), rng.uniform(0.5, 3));
    std::vector<Vec3d> local;
    for (int c = 0; c < 8; ++c) local.emplace_back(c & 1 ? ext[0] : 0, c & 2 ? ext[1] : 0, c & 4 ? ext[2] : 0);
    for (int i = 0; i < 40; ++i) {
      Vec3d q(rng.uniform(0, 1), rng.uniform(0, 1), rng.uniform(0, 1));
      q[i % 3] = double(i % 2);
      local.push_back(q.cwiseProduct(ext));
    }
    for (int i = 0; i < 200; ++i) local.push_back(Vec3d(rng.uniform(0, 0.2), rng.uniform(0, 0.2), rng.uniform(0, 0.2)).cwiseProduct(ext));
    std::vector<Vec3d> pts;
    for (const Vec3d& q : local) pts.push_back(rot * q + Vec3d(1, -2, 0.5));
    const Obb3d box = fit_obb<double>(pts, ObbFit::hull);
    for (const Vec3d& p : pts) ASSERT_TRUE(contains(box, p));
    const double exact = ext.prod();
    EXPECT_LE(volume(box), exact * (1 + 1e-4)) << "the hull-face-flush candidate finds the box";
    EXPECT_LE(volume(box), pca_box_volume(pts) * (1 + 1e-4));
    EXPECT_GT(volume(fit_obb<double>(pts)), exact * 1.05) << "the cluster tilts the principal axes";
    // Random blobs: never worse than the principal axes.
    const auto blob = cloud<double>(rng, 50, Vec3d::Zero(), 1.0);
    EXPECT_LE(volume(fit_obb<double>(blob, ObbFit::hull)), pca_box_volume(blob) * (1 + 1e-4));
  }
}

TEST(BoundingVolumes, ObbOfFlatAndDegenerateSets) {
  // A single triangle: a flat box around it, containing its corners.
  const std::vector<Vec3f> tri{{0, 0, 0}, {2, 1, 0.5f}, {0.3f, 1.7f, -1}};
  const Obb3f t = fit_obb<float>(tri, ObbFit::hull);
  for (const auto& p : tri) EXPECT_TRUE(contains(t, p));
  EXPECT_LT(volume(t), 1e-4f);
  // The minimum-area rectangle of a rotated flat rectangle is that rectangle.
  std::vector<Vec3d> rect;
  const Vec3d u = Vec3d(1, 1, 0).normalized(), w = Vec3d(-1, 1, 1).normalized().cross(u).normalized();
  Rng rng(9);
  for (int i = 0; i < 100; ++i) rect.push_back(rng.uniform(0, 4) * u + rng.uniform(0, 1) * w);
  for (int c = 0; c < 4; ++c) rect.push_back((c & 1 ? 4.0 : 0.0) * u + (c & 2 ? 1.0 : 0.0) * w);
  const Obb3d r = fit_obb<double>(rect, ObbFit::hull);
  const Vec3d e = 2 * r.half;
  std::vector<double> sorted{e[0], e[1], e[2]};
  std::sort(sorted.begin(), sorted.end());
  EXPECT_NEAR(sorted[1] * sorted[2], 4.0, 1e-3);
  // Collinear points and a single point.
  const Obb3d line = fit_obb<double>(std::vector<Vec3d>{{0, 0, 0}, {1, 2, 3}, {2, 4, 6}}, ObbFit::hull);
  EXPECT_TRUE(contains(line, Vec3d(2, 4, 6)));
  EXPECT_TRUE(contains(fit_obb<double>(std::vector<Vec3d>{{5, 5, 5}}, ObbFit::hull), Vec3d(5, 5, 5)));
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
