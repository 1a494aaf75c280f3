// The watertight ray-triangle test against a double-precision reference, and
// its defining property: rays through shared edges and vertices never miss.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "common/collinear_triangles.hpp"
#include "geods/core/ray_triangle.hpp"
#include "geods/core/rng.hpp"

namespace geods {
namespace {

// Reference: solve o + t d = (1-u-v) a + u b + v c by Cramer's rule in long double.
bool reference_hit(const Ray3f& r, const Vec3f& a, const Vec3f& b, const Vec3f& c, long double& t) {
  using L = long double;
  const L e1[3] = {L(b[0]) - a[0], L(b[1]) - a[1], L(b[2]) - a[2]};
  const L e2[3] = {L(c[0]) - a[0], L(c[1]) - a[1], L(c[2]) - a[2]};
  const L s[3] = {L(r.origin[0]) - a[0], L(r.origin[1]) - a[1], L(r.origin[2]) - a[2]};
  const L d[3] = {r.direction[0], r.direction[1], r.direction[2]};
  auto det3 = [](const L* x, const L* y, const L* z) {
    return x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) +
           x[2] * (y[0] * z[1] - y[1] * z[0]);
  };
  const L md[3] = {-d[0], -d[1], -d[2]};
  const L den = det3(md, e1, e2);
  if (den == 0) return false;
  t = det3(s, e1, e2) / den;
  const L u = det3(md, s, e2) / den, v = det3(md, e1, s) / den;
  return u >= 0 && v >= 0 && u + v <= 1 && t >= r.tmin && t <= r.tmax;
}

Vec3f random_vec(Rng& rng, float lo, float hi) {
  return {float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi))};
}

TEST(RayTriangle, AgreesWithReferenceAwayFromEdges) {
  Rng rng(7);
  int checked = 0, hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f a = random_vec(rng, -1, 1), b = random_vec(rng, -1, 1), c = random_vec(rng, -1, 1);
    Ray3f r;
    r.origin = random_vec(rng, -3, 3);
    r.direction = (random_vec(rng, -0.5f, 0.5f) - r.origin).normalized();
    long double t_ref = 0;
    const bool ref = reference_hit(r, a, b, c, t_ref);
    float t, u, v;
    const bool got = RayTriangleTest<float>(r).intersect(a, b, c, r.tmin, r.tmax, t, u, v);
    if (got != ref) {
      // Only rays grazing an edge may disagree: check the margin of the reference.
      const Vec3f p = r.at(got ? t : float(t_ref));
      const Vec3f n = (b - a).cross(c - a);
      const float edge_dist = std::min({(p - a).cross(b - a).norm() / (b - a).norm(),
                                        (p - b).cross(c - b).norm() / (c - b).norm(),
                                        (p - c).cross(a - c).norm() / (a - c).norm()});
      EXPECT_LT(edge_dist, 1e-4f) << "disagreement far from an edge, i=" << i << " |n|=" << n.norm();
      continue;
    }
    ++checked;
    if (got) {
      ++hits;
      EXPECT_NEAR(t, double(t_ref), 1e-4 * (1 + double(t_ref)));
      const Vec3f p = (1 - u - v) * a + u * b + v * c;
      EXPECT_LT((p - r.at(t)).norm(), 1e-3f);
    }
  }
  EXPECT_GT(checked, 19900);
  EXPECT_GT(hits, 1000);
}

TEST(RayTriangle, RejectsDegenerateInputs) {
  const Vec3f a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);  // collinear
  Ray3f r;
  r.origin = {0.5f, 0.0f, -1.0f};
  r.direction = {0, 0, 1};
  float t, u, v;
  EXPECT_FALSE(RayTriangleTest<float>(r).intersect(a, b, c, 0, 10, t, u, v));
  r.direction = {0, 0, 0};
  EXPECT_FALSE(RayTriangleTest<float>(r).intersect(a, b, Vec3f(0, 1, 0), 0, 10, t, u, v));
  // A direction infinite or NaN on any axis: no hit (sheared by an infinite
  // component, the triangle around the origin's projection came out at t = 0).
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  r.origin = {0.2f, 0.2f, -1.0f};
  for (const Vec3f& d : {Vec3f(0, 0, inf), Vec3f(0.1f, 0, -inf), Vec3f(inf, 0, 1), Vec3f(0, -inf, 1),
                         Vec3f(inf, inf, inf), Vec3f(0, 0, nan), Vec3f(nan, 0, 1), Vec3f(0, nan, 1)}) {
    r.direction = d;
    EXPECT_FALSE(RayTriangleTest<float>(r).intersect(a, b, Vec3f(0, 1, 0), 0, 10, t, u, v))
        << d[0] << " " << d[1] << " " << d[2];
    EXPECT_FALSE(RayTriangleTest<float>(r).intersect(a, b, Vec3f(0, 1, 0), -inf, inf, t, u, v));
  }
  // A ray in the triangle's plane does not hit it (zero determinant).
  r.origin = {-1, 0.1f, 0};
  r.direction = {1, 0, 0};
  EXPECT_FALSE(RayTriangleTest<float>(r).intersect(a, b, Vec3f(0, 1, 0), 0, 10, t, u, v));
}

TEST(RayTriangle, TrianglesOfZeroAreaAreNeverHit) {
  // Rounded, about one in twelve of these rays "hit" its collinear triangle
  // at a point off it; the ordinary ones, aimed at on an edge, are hit often.
  const TriMesh soup = test::collinear_soup(4000, 7);
  const auto rays = test::rays_along_triangles(soup, 40000, 8);
  int zero_area = 0, ordinary_hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const auto& f = soup.triangles[i % soup.num_triangles()];
    const Vec3f &a = soup.vertices[f[0]], &b = soup.vertices[f[1]], &c = soup.vertices[f[2]];
    float t, u, v;
    const bool hit = RayTriangleTest<float>(rays[i]).intersect(a, b, c, 0, 1e30f, t, u, v);
    if (has_zero_area(a, b, c)) {
      ++zero_area;
      EXPECT_FALSE(hit) << "ray " << i << " hits a triangle of zero area at t = " << t;
    } else {
      ordinary_hits += hit;
    }
  }
  EXPECT_GE(zero_area, 20000);  // the collinear half, and a few ordinary ones by chance
  EXPECT_GT(ordinary_hits, (40000 - zero_area) / 3);  // aimed at an edge: rounded inside about half the time
}

// A closed cube whose faces are n x n grids of triangle pairs with shared vertices.
struct GridCube {
  std::vector<Vec3f> v;
  std::vector<std::array<int, 3>> f;
  explicit GridCube(int n) {
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int base = int(v.size());
        for (int i = 0; i <= n; ++i)
          for (int j = 0; j <= n; ++j) {
            Vec3f p;
            p[axis] = side ? 1.0f : -1.0f;
            p[(axis + 1) % 3] = -1.0f + 2.0f * float(i) / float(n);
            p[(axis + 2) % 3] = -1.0f + 2.0f * float(j) / float(n);
            v.push_back(p);
          }
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            const int q = base + i * (n + 1) + j;
            f.push_back({q, q + n + 1, q + n + 2});
            f.push_back({q, q + n + 2, q + 1});
          }
      }
  }
  int hits(const Ray3f& r) const {
    RayTriangleTest<float> test(r);
    int count = 0;
    float t, u, w;
    for (const auto& t3 : f) count += test.intersect(v[t3[0]], v[t3[1]], v[t3[2]], r.tmin, r.tmax, t, u, w);
    return count;
  }
};

TEST(RayTriangle, RaysThroughSharedEdgesAndVerticesNeverSlipThrough) {
  const GridCube cube(5);
  Rng rng(11);
  int rays = 0;
  for (std::size_t i = 0; i < cube.f.size(); ++i) {
    const auto& t3 = cube.f[i];
    // Aim at each vertex and each edge midpoint of the face, from random inner points.
    for (int k = 0; k < 3; ++k) {
      const Vec3f targets[2] = {cube.v[t3[k]], 0.5f * (cube.v[t3[k]] + cube.v[t3[(k + 1) % 3]])};
      for (const Vec3f& target : targets) {
        Ray3f r;
        r.origin = random_vec(rng, -0.9f, 0.9f);
        r.direction = target - r.origin;
        EXPECT_GE(cube.hits(r), 1) << "ray slipped through at " << target.transpose();
        ++rays;
      }
    }
  }
  EXPECT_EQ(rays, int(cube.f.size()) * 6);
}

}  // namespace
}  // namespace geods
