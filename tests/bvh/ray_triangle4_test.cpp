// RayTriangle4Test against the scalar watertight test it vectorizes: the
// same hit decisions and bit-identical t, u, v, lane by lane, 4 and 8 wide.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "bvh_test_util.hpp"
#include "common/collinear_triangles.hpp"
#include "geods/bvh/ray_triangle4.hpp"

namespace geods::bvh {
namespace {

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TriangleGroup group_of(const TriMesh& mesh, const std::size_t (&tri)[4]) {
  TriangleGroup g;
  for (int lane = 0; lane < 4; ++lane)
    set_lane(g, lane, test::corner(mesh, tri[lane], 0), test::corner(mesh, tri[lane], 1),
             test::corner(mesh, tri[lane], 2), std::uint32_t(tri[lane]));
  return g;
}

// Returns the number of lanes hit, for the callers to check the inputs hit at all.
int expect_lanes_match_scalar(const TriMesh& mesh, const Ray3f& ray, const std::size_t (&tri)[4], float tmin,
                              float tmax, const std::string& what) {
  const RayTriangleTest<float> scalar(ray);
  const RayTriangle4Test wide(ray);
  RayTriangle4Test::vf t, u, v;
  const int mask = wide.intersect(group_of(mesh, tri), tmin, tmax, t, u, v);
  int hits = 0;
  for (int lane = 0; lane < 4; ++lane) {
    float st = 0, su = 0, sv = 0;
    const bool hit = scalar.intersect(test::corner(mesh, tri[lane], 0), test::corner(mesh, tri[lane], 1),
                                      test::corner(mesh, tri[lane], 2), tmin, tmax, st, su, sv);
    EXPECT_EQ(bool(mask >> lane & 1), hit) << what << " lane " << lane;
    if (!hit || !(mask >> lane & 1)) continue;
    ++hits;
    EXPECT_TRUE(same_bits(t[lane], st) && same_bits(u[lane], su) && same_bits(v[lane], sv))
        << what << " lane " << lane << ": " << t[lane] << " " << u[lane] << " " << v[lane] << " vs " << st << " "
        << su << " " << sv;
  }
  // The two-group form: lanes 0-3 the group above, lanes 4-7 its lanes in
  // reverse; and with lanes 4-7 masked off, as a leaf's last group alone.
  const std::size_t reversed[4] = {tri[3], tri[2], tri[1], tri[0]};
  const TriangleGroup g0 = group_of(mesh, tri), g1 = group_of(mesh, reversed);
  const auto bits = [](const auto& m) {
    int b = 0;
    for (int lane = 0; lane < 8; ++lane) b |= (m[lane] & 1) << lane;
    return b;
  };
  for (int lanes : {0xFF, 0x0F}) {
    RayTriangle4Test::vf8 t8, u8, v8;
    const int mask8 = wide.intersect(g0, g1, lanes, tmin, tmax, t8, u8, v8, bits);
    EXPECT_EQ(mask8 & ~lanes, 0) << what;
    for (int lane = 0; lane < 8; ++lane) {
      const int k = lane < 4 ? lane : 7 - lane;  // the lane of the 4-wide test with the same triangle
      EXPECT_EQ(bool(mask8 >> lane & 1), (lanes >> lane & 1) && (mask >> k & 1)) << what << " lane " << lane;
      if (!(mask8 >> lane & 1) || !(mask >> k & 1)) continue;
      EXPECT_TRUE(same_bits(t8[lane], t[k]) && same_bits(u8[lane], u[k]) && same_bits(v8[lane], v[k]))
          << what << " 8-wide lane " << lane;
    }
  }
  return hits;
}

TEST(RayTriangle4, BitIdenticalToTheScalarTestOnSoupsAndTheirHardRays) {
  // Ordinary, tiny, huge, axis-aligned and degenerate triangles; rays at
  // vertices and edges (edge functions exactly 0), along faces, from the surface.
  const TriMesh soup = test::random_soup(400, 11);
  const auto rays = test::test_rays(soup, 700, 12);
  Rng rng(13);
  int hits = 0;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    // The triangle the ray was aimed at in one lane, random others (repeats too).
    const std::size_t aimed = r % soup.num_triangles();
    std::size_t tri[4];
    for (int lane = 0; lane < 4; ++lane) tri[lane] = rng.below(soup.num_triangles());
    tri[r % 4] = aimed;
    hits += expect_lanes_match_scalar(soup, rays[r], tri, rays[r].tmin, rays[r].tmax, "soup ray " + std::to_string(r));
    hits += expect_lanes_match_scalar(soup, rays[r], tri, 0.5f, 2.0f, "bounded soup ray " + std::to_string(r));
  }
  EXPECT_GT(hits, 100);
}

TEST(RayTriangle4, ZeroAreaLanesAreNeverHitAsInTheScalarTest) {
  // Collinear triangles (set_lane gives them NaN corners) beside ordinary
  // ones, rays aimed along them: rounded, about one in twelve used to hit.
  const TriMesh soup = geods::test::collinear_soup(400, 31);
  const auto rays = geods::test::rays_along_triangles(soup, 4000, 32);
  int hits = 0;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    const std::size_t first = std::min(r % soup.num_triangles(), soup.num_triangles() - 4);  // with the aimed one
    const std::size_t tri[4] = {first, first + 1, first + 2, first + 3};
    hits += expect_lanes_match_scalar(soup, rays[r], tri, rays[r].tmin, rays[r].tmax, "ray " + std::to_string(r));
  }
  EXPECT_GT(hits, 1000);
}

TEST(RayTriangle4, BitIdenticalOnTheSharedEdgesAndVerticesOfAClosedMesh) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const auto rays = test::test_rays(bunny, 1400, 21);
  int hits = 0;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    // Consecutive triangles of the mesh often share edges and vertices.
    const std::size_t first = (r * 37) % (bunny.num_triangles() - 4);
    const std::size_t tri[4] = {first, first + 1, first + 2, first + 3};
    hits += expect_lanes_match_scalar(bunny, rays[r], tri, rays[r].tmin, rays[r].tmax, "bunny ray " + std::to_string(r));
  }
  // Rays aimed exactly at each corner and edge midpoint of a fan around a vertex.
  for (std::size_t f = 0; f + 4 <= bunny.num_triangles(); f += 97) {
    const std::size_t tri[4] = {f, f + 1, f + 2, f + 3};
    for (int k = 0; k < 3; ++k) {
      Ray3f ray;
      ray.origin = Vec3f(0.1f, 2.0f, 3.0f);
      ray.direction = test::corner(bunny, f, k) - ray.origin;
      hits += expect_lanes_match_scalar(bunny, ray, tri, ray.tmin, ray.tmax, "corner of " + std::to_string(f));
      ray.direction = 0.5f * (test::corner(bunny, f, k) + test::corner(bunny, f, (k + 1) % 3)) - ray.origin;
      hits += expect_lanes_match_scalar(bunny, ray, tri, ray.tmin, ray.tmax, "edge of " + std::to_string(f));
    }
  }
  EXPECT_GT(hits, 100);
}

TEST(RayTriangle4, AxisParallelRaysAndZeroDirections) {
  TriMesh mesh;
  // Axis-aligned unit squares (two triangles each) on the three coordinate planes.
  for (int axis = 0; axis < 3; ++axis) {
    const auto base = std::uint32_t(mesh.vertices.size());
    for (int k = 0; k < 4; ++k) {
      Vec3f p = Vec3f::Zero();
      p[(axis + 1) % 3] = float(k & 1);
      p[(axis + 2) % 3] = float(k >> 1);
      mesh.vertices.push_back(p);
    }
    mesh.triangles.push_back({base, base + 1, base + 3});
    mesh.triangles.push_back({base, base + 3, base + 2});
  }
  const std::size_t tri[4] = {0, 1, 2, 3};
  const std::size_t tri2[4] = {2, 3, 4, 5};
  int hits = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (float s : {0.0f, 0.25f, 0.5f, 1.0f})
      for (float sign : {1.0f, -1.0f}) {
        Ray3f ray;
        ray.origin = Vec3f::Constant(s);
        ray.origin[axis] = -sign;
        ray.direction = Vec3f::Zero();
        ray.direction[axis] = sign;
        const std::string what = "axis " + std::to_string(axis) + " at " + std::to_string(s);
        hits += expect_lanes_match_scalar(mesh, ray, tri, ray.tmin, ray.tmax, what);
        hits += expect_lanes_match_scalar(mesh, ray, tri2, ray.tmin, ray.tmax, what);
      }
  Ray3f zero;
  zero.origin = Vec3f(0.5f, 0.5f, -1.0f);
  zero.direction = Vec3f::Zero();
  EXPECT_EQ(expect_lanes_match_scalar(mesh, zero, tri, zero.tmin, zero.tmax, "zero direction"), 0);
  EXPECT_GT(hits, 10);
}

}  // namespace
}  // namespace geods::bvh
