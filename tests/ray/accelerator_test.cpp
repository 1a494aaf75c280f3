// Every accelerator against brute force (all triangles with the watertight
// RayTriangleTest): the same closest t and triangle (ties: the smallest index,
// which brute force in index order also keeps), the same any-hit answer, on the
// meshes of data/ and on random soups with degenerate, tiny, huge and
// axis-aligned triangles, for random, axis-parallel, grazing and on-surface rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "common/data_files.hpp"
#include "bvh/bvh_test_util.hpp"
#include "common/archive_files.hpp"
#include "common/collinear_triangles.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/ray/accelerator.hpp"
#include "geods/ray/bvh_accelerator.hpp"
#include "geods/ray/ray_classifier.hpp"
#include "geods/ray/ray_octree.hpp"
#include "geods/ray/uniform_grid.hpp"

namespace geods::ray {
namespace {

RayHit brute_closest(const TriMesh& mesh, const Ray3f& ray) {
  RayHit best;
  best.t = ray.tmax;
  const RayTriangleTest<float> test(ray);
  for (std::uint32_t i = 0; i < mesh.num_triangles(); ++i) {
    const auto& t = mesh.triangles[i];
    float th, u, v;
    if (test.intersect(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], ray.tmin, best.t, th, u, v) &&
        (th < best.t || !best.hit()))
      best = {th, i, u, v};
  }
  return best.hit() ? best : RayHit{};
}

bool brute_any(const TriMesh& mesh, const Ray3f& ray) {
  const RayTriangleTest<float> test(ray);
  for (const auto& t : mesh.triangles) {
    float th, u, v;
    if (test.intersect(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], ray.tmin, ray.tmax, th, u, v))
      return true;
  }
  return false;
}

// The same closest hit: the same t and the same triangle (grid, octree and 5D
// classification keep the smallest index on ties, as brute force does).
//
// The BVH (bvh::TriangleBvh) is held to less: it prunes boxes in float with a
// slack of a few ulps, and on grazing rays through a shared vertex (the flat
// mesh) the float t of the triangles there differ by more than that, so it may
// report another of them: its t is checked to 1e-6 relative and its triangle
// to be hit at the t it reports.
bool same_hit(const TriMesh& mesh, const Ray3f& ray, const RayHit& expected, const RayHit& got, AcceleratorKind kind) {
  if (kind != AcceleratorKind::bvh)
    return got.t == expected.t && got.prim == expected.prim && got.u == expected.u && got.v == expected.v;
  if (got.hit() != expected.hit()) return false;
  if (!got.hit()) return true;
  if (got.prim >= mesh.num_triangles() || std::abs(got.t - expected.t) > 1e-6f * std::max(1.0f, std::abs(expected.t)))
    return false;
  const auto& t = mesh.triangles[got.prim];
  float th, u, v;
  return RayTriangleTest<float>(ray).intersect(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], ray.tmin,
                                               ray.tmax, th, u, v) &&
         th == got.t;
}

Vec3f random_vec(Rng& rng, const Vec3f& lo, const Vec3f& hi) {
  Vec3f p;
  for (int a = 0; a < 3; ++a) p[a] = float(rng.uniform(lo[a], hi[a]));
  return p;
}

Vec3f random_direction(Rng& rng) {
  for (;;) {
    const Vec3f d = random_vec(rng, Vec3f::Constant(-1), Vec3f::Constant(1));
    if (d.squaredNorm() > 1e-4f && d.squaredNorm() <= 1) return d.normalized();
  }
}

// Rays of many kinds around the mesh's bounds.
std::vector<Ray3f> test_rays(const TriMesh& mesh, std::uint64_t seed, int count) {
  Rng rng(seed);
  const AABB3f box = mesh.bounds();
  const Vec3f c = box.center(), e = box.extent().cwiseMax(Vec3f::Constant(1e-3f));
  const Vec3f lo = c - e, hi = c + e;
  std::vector<Ray3f> rays;
  auto vertex = [&]() {
    return mesh.vertices[mesh.triangles[rng() % mesh.num_triangles()][rng() % 3]];
  };
  for (int i = 0; i < count; ++i) {
    Ray3f r;
    switch (i % 9) {
      case 0:  // from outside towards a random point inside
        r.origin = random_vec(rng, lo, hi);
        r.direction = random_vec(rng, box.lo, box.hi) - r.origin;
        break;
      case 1:  // through a vertex
        r.origin = random_vec(rng, lo, hi);
        r.direction = vertex() - r.origin;
        break;
      case 2: {  // through the middle of an edge
        const auto& t = mesh.triangles[rng() % mesh.num_triangles()];
        r.origin = random_vec(rng, lo, hi);
        r.direction = 0.5f * (mesh.vertices[t[0]] + mesh.vertices[t[1]]) - r.origin;
        break;
      }
      case 3: {  // parallel to an axis (zero components), either sign
        r.origin = random_vec(rng, lo, hi);
        r.direction = Vec3f::Zero();
        r.direction[int(rng() % 3)] = rng() % 2 ? 1.0f : -1.0f;
        break;
      }
      case 4: {  // starting on the surface, leaving in a random direction
        const auto& t = mesh.triangles[rng() % mesh.num_triangles()];
        const float u = float(rng.uniform()), v = float(rng.uniform()) * (1 - u);
        r.origin = (1 - u - v) * mesh.vertices[t[0]] + u * mesh.vertices[t[1]] + v * mesh.vertices[t[2]];
        r.direction = random_direction(rng);
        break;
      }
      case 5: {  // in the plane of an axis through a vertex: one zero component
        const Vec3f p = vertex();
        r.origin = random_vec(rng, lo, hi);
        const int a = int(rng() % 3);
        r.origin[a] = p[a];
        r.direction = p - r.origin;
        r.direction[a] = 0;
        break;
      }
      case 6:  // from inside, random direction, bounded interval
        r.origin = random_vec(rng, box.lo, box.hi);
        r.direction = random_direction(rng);
        r.tmin = float(rng.uniform(0, 0.3)) * e.norm();
        r.tmax = r.tmin + float(rng.uniform(0, 1)) * e.norm();
        break;
      case 7:  // far away, unnormalized direction
        r.origin = c + 20 * e.norm() * random_direction(rng);
        r.direction = (random_vec(rng, box.lo, box.hi) - r.origin) * float(rng.uniform(0.01, 100));
        break;
      default:  // from a vertex along an axis: exactly on the mesh
        r.origin = vertex();
        r.direction = Vec3f::Zero();
        r.direction[int(rng() % 3)] = rng() % 2 ? 1.0f : -1.0f;
        break;
    }
    if (r.direction.isZero(0)) r.direction = Vec3f::UnitX();
    rays.push_back(r);
  }
  return rays;
}

void expect_same_as_brute_force(const TriMesh& mesh, const std::vector<Ray3f>& rays, const std::string& what,
                                const AcceleratorOptions& options = {}) {
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    SCOPED_TRACE(what + " / " + std::string(to_string(kind)));
    const auto accel = make_accelerator(mesh, kind, options);
    ASSERT_EQ(accel->kind(), kind);
    std::size_t hits = 0, mismatches = 0;
    RayCache cache;  // shared by all rays: must not change any answer
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const RayHit expected = brute_closest(mesh, rays[i]);
      const RayHit got = accel->intersect(rays[i]);
      const RayHit cached = accel->intersect(rays[i], cache);
      hits += expected.hit();
      if (!same_hit(mesh, rays[i], expected, got, kind) || !same_hit(mesh, rays[i], expected, cached, kind)) {
        if (++mismatches <= 5)
          ADD_FAILURE() << "ray " << i << " o=" << rays[i].origin.transpose() << " d=" << rays[i].direction.transpose()
                        << ": expected prim " << expected.prim << " t " << expected.t << ", got " << got.prim << " t "
                        << got.t << " (cached " << cached.prim << ")";
        continue;
      }
      const bool any = brute_any(mesh, rays[i]);
      EXPECT_EQ(accel->occluded(rays[i]), any) << "ray " << i;
      EXPECT_EQ(accel->occluded(rays[i], cache), any) << "ray " << i << " with the occluder cache";
    }
    EXPECT_EQ(mismatches, 0u);
    EXPECT_GT(hits, rays.size() / 10) << "the rays should hit the mesh often";
    EXPECT_NO_THROW(accel->validate());
  }
}

TEST(Accelerators, BunnyMatchesBruteForce) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  expect_same_as_brute_force(mesh, test_rays(mesh, 1, 1800), "bunny");
}

TEST(Accelerators, TeapotMatchesBruteForce) {
  const TriMesh mesh = test::data_mesh("teapot.obj");
  expect_same_as_brute_force(mesh, test_rays(mesh, 2, 1800), "teapot");
}

// A soup of random triangles mixed with degenerate (repeated corner, collinear),
// tiny, huge and axis-aligned ones, and exact duplicates (ties in t).
TriMesh ugly_soup(std::uint64_t seed, int count) {
  Rng rng(seed);
  TriMesh mesh;
  auto add = [&](const Vec3f& a, const Vec3f& b, const Vec3f& c) {
    const auto base = std::uint32_t(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
    mesh.triangles.push_back({base, base + 1, base + 2});
  };
  const Vec3f lo = Vec3f::Constant(-1), hi = Vec3f::Constant(1);
  for (int i = 0; i < count; ++i) {
    const Vec3f p = random_vec(rng, lo, hi);
    switch (i % 8) {
      case 0: add(p, random_vec(rng, lo, hi), random_vec(rng, lo, hi)); break;  // large random
      case 1: add(p, p + 0.1f * random_direction(rng), p + 0.1f * random_direction(rng)); break;
      case 2: add(p, p + 1e-5f * random_direction(rng), p + 1e-5f * random_direction(rng)); break;  // tiny
      case 3: add(p, p, p + 0.2f * random_direction(rng)); break;                                  // degenerate
      case 4: add(p, p + Vec3f(0.1f, 0.1f, 0.1f), p + Vec3f(0.2f, 0.2f, 0.2f)); break;            // collinear
      case 5: {  // axis-aligned
        const int a = int(rng() % 3);
        Vec3f q = p + 0.3f * random_direction(rng), r = p + 0.3f * random_direction(rng);
        q[a] = r[a] = p[a];
        add(p, q, r);
        break;
      }
      case 6: add(10 * p, 10 * random_vec(rng, lo, hi), -10 * p); break;  // huge, crosses everything
      default: {  // a duplicate of an earlier triangle, corners rotated: the same t
        const auto& t = mesh.triangles[rng() % mesh.triangles.size()];
        add(mesh.vertices[t[1]], mesh.vertices[t[2]], mesh.vertices[t[0]]);
        break;
      }
    }
  }
  return mesh;
}

TEST(Accelerators, UglySoupMatchesBruteForce) {
  for (std::uint64_t seed : {3u, 4u}) {
    const TriMesh mesh = ugly_soup(seed, 600);
    expect_same_as_brute_force(mesh, test_rays(mesh, seed + 10, 1800), "soup " + std::to_string(seed));
  }
}

TEST(Accelerators, TrianglesOfZeroAreaAreNeverHit) {
  // Exactly collinear triangles among ordinary ones, rays aimed along them:
  // rounded, the triangle test "hit" some off the triangle, and the BVH's
  // tight volumes skipped a few of those hits.
  const TriMesh mesh = test::collinear_soup(600, 51);
  const auto rays = test::rays_along_triangles(mesh, 1800, 52);
  expect_same_as_brute_force(mesh, rays, "collinear soup");
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    const auto accel = make_accelerator(mesh, kind);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const RayHit hit = accel->intersect(rays[i]);
      if (!hit.hit()) continue;
      const auto& t = mesh.triangles[hit.prim];
      ASSERT_FALSE(has_zero_area(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]))
          << to_string(kind) << " ray " << i;
    }
  }
}

TEST(Accelerators, LinesWithNegativeTminMatchBruteForce) {
  // Lines (tmin < 0): the hits behind the origin count too, on a soup and on
  // a grid of flat squares in the plane z = 0.5 (flat boxes, whose entry and
  // exit distances are equal).
  TriMesh mesh = ugly_soup(5, 40);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const auto base = std::uint32_t(mesh.vertices.size());
      for (int k = 0; k < 4; ++k) mesh.vertices.push_back({0.25f * float(i + k % 2) - 1, 0.25f * float(j + k / 2) - 1, 0.5f});
      mesh.triangles.push_back({base, base + 1, base + 3});
      mesh.triangles.push_back({base, base + 3, base + 2});
    }
  std::vector<Ray3f> rays = test_rays(mesh, 15, 900);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Ray3f& r = rays[i];  // from the line's point nearest the mesh's centre: hits on both sides
    r.origin += r.direction * ((mesh.bounds().center() - r.origin).dot(r.direction) / r.direction.squaredNorm());
    r.tmin = i % 2 ? -50.0f : -std::numeric_limits<float>::infinity();
  }
  expect_same_as_brute_force(mesh, rays, "lines");
}

TEST(Accelerators, RaysWithInfiniteDirectionsOrNaNOriginsMatchBruteForce) {
  // Slab and cell distances that are NaN on every axis, and directions
  // infinite on one axis: no accelerator may walk outside its structure or
  // hang on them, and none of these rays hits.
  const TriMesh mesh = ugly_soup(6, 500);
  std::vector<Ray3f> rays = test_rays(mesh, 16, 1500);
  bvh::test::make_non_finite_rays(rays, 4);
  expect_same_as_brute_force(mesh, rays, "infinite and NaN rays");
}

// A closed cube of 2 x 2 quads per face on a grid, shot through its shared edges
// and vertices along the axes and diagonals: watertight, so every ray from
// outside through the cube's interior hits.
TEST(Accelerators, ClosedGridCubeNeverLeaks) {
  TriMesh mesh;
  auto vertex = [&](Vec3f p) {
    mesh.vertices.push_back(p);
    return std::uint32_t(mesh.vertices.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {0.0f, 2.0f})
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          auto at = [&](int a, int b) {
            Vec3f p;
            p[axis] = side;
            p[(axis + 1) % 3] = float(i + a);
            p[(axis + 2) % 3] = float(j + b);
            return vertex(p);
          };
          const std::uint32_t v00 = at(0, 0), v10 = at(1, 0), v01 = at(0, 1), v11 = at(1, 1);
          mesh.triangles.push_back({v00, v10, v11});
          mesh.triangles.push_back({v00, v11, v01});
        }
  std::vector<Ray3f> rays;
  for (int a = 0; a < 3; ++a)
    for (float x : {0.5f, 1.0f, 1.5f})
      for (float y : {0.5f, 1.0f, 1.5f})
        for (float sign : {1.0f, -1.0f}) {
          Ray3f r;
          r.origin[a] = sign > 0 ? -1.0f : 3.0f;
          r.origin[(a + 1) % 3] = x;
          r.origin[(a + 2) % 3] = y;
          r.direction = Vec3f::Zero();
          r.direction[a] = sign;
          rays.push_back(r);
          Ray3f diagonal = r;  // through the same point of the near face, at 45 degrees
          diagonal.direction[(a + 1) % 3] = 0.5f;
          diagonal.origin[(a + 1) % 3] -= 0.5f * (sign > 0 ? 1.0f : 3.0f);
          rays.push_back(diagonal);
        }
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    const auto accel = make_accelerator(mesh, kind);
    for (const Ray3f& r : rays) {
      EXPECT_TRUE(accel->intersect(r).hit()) << to_string(kind) << " o=" << r.origin.transpose();
      EXPECT_EQ(accel->intersect(r).t, brute_closest(mesh, r).t) << to_string(kind);
    }
  }
  expect_same_as_brute_force(mesh, rays, "grid cube");
}

TEST(Accelerators, SmallLeavesDeepTreesAndCutoffMatchBruteForce) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  AcceleratorOptions options;
  options.grid_density = 0.3f;  // coarse grid: many triangles per cell
  options.octree_leaf_size = 1;
  options.octree_max_depth = 10;
  options.rays5d_leaf_size = 1;
  options.rays5d_max_depth = 6;
  options.rays5d_max_references = 4000000;
  options.rays5d_cutoff = 0.01f;  // restarts often
  expect_same_as_brute_force(mesh, test_rays(mesh, 5, 450), "bunny, extreme options", options);
  options.rays5d_cutoff = 0;  // no cut-off
  options.rays5d_max_references = 20000;  // the budget runs out early
  options.grid_max_resolution = 3;
  expect_same_as_brute_force(mesh, test_rays(mesh, 6, 450), "bunny, small budgets", options);
}

TEST(Accelerators, EmptyFlatAndBadInput) {
  TriMesh empty;
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    const auto accel = make_accelerator(empty, kind);
    Ray3f r;
    EXPECT_FALSE(accel->intersect(r).hit());
    EXPECT_FALSE(accel->occluded(r));
    EXPECT_NO_THROW(accel->validate());
    EXPECT_EQ(accel->stats().triangles, 0u);
  }
  // All triangles in the plane z = 0: a flat scene box.
  TriMesh flat;
  Rng rng(9);
  for (int i = 0; i < 200; ++i) {
    const auto base = std::uint32_t(flat.vertices.size());
    for (int k = 0; k < 3; ++k) flat.vertices.push_back({float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), 0.0f});
    flat.triangles.push_back({base, base + 1, base + 2});
  }
  expect_same_as_brute_force(flat, test_rays(flat, 11, 900), "flat");

  TriMesh bad = flat;
  bad.vertices[3][1] = std::numeric_limits<float>::quiet_NaN();
  TriMesh out_of_range = flat;
  out_of_range.triangles[5][2] = 100000;
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    EXPECT_THROW(make_accelerator(bad, kind), Error);
    EXPECT_THROW(make_accelerator(out_of_range, kind), Error);
  }
  EXPECT_THROW(parse_accelerator_kind("kdtree"), Error);
  for (AcceleratorKind kind : all_accelerator_kinds()) EXPECT_EQ(parse_accelerator_kind(to_string(kind)), kind);
  AcceleratorOptions options;
  options.grid_density = 0;
  EXPECT_THROW(make_accelerator(flat, AcceleratorKind::grid, options), Error);
  options = {};
  options.octree_leaf_size = 0;
  EXPECT_THROW(make_accelerator(flat, AcceleratorKind::octree, options), Error);

  // Rays that cannot hit: zero or NaN direction, empty interval.
  const auto grid = make_accelerator(flat, AcceleratorKind::rays5d);
  Ray3f r;
  r.origin = {0, 0, 1};
  r.direction = Vec3f::Zero();
  EXPECT_FALSE(grid->intersect(r).hit());
  r.direction = {0, std::numeric_limits<float>::quiet_NaN(), -1};
  EXPECT_FALSE(grid->intersect(r).hit());
  r.direction = {0, 0, -1};
  r.tmin = 2;
  r.tmax = 1;
  EXPECT_FALSE(grid->occluded(r));
}

// Every kind refuses what the float ray-triangle test cannot answer
// (core/ray_triangle.hpp): a mesh beyond +-2^35 or spanning less than 2^-34,
// and rays from beyond +-2^35, in single and packet queries alike.
TEST(Accelerators, MeshesAndRaysBeyondTheTriangleTestsRangeAreRefused) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  for (int e : {40, -40}) {
    TriMesh m = bunny;
    for (Vec3f& v : m.vertices) v = Vec3f(std::ldexp(v[0], e), std::ldexp(v[1], e), std::ldexp(v[2], e));
    Ray3f r;
    r.origin = Vec3f(0, std::ldexp(20.0f, e), 0);
    r.direction = {0, -1, 0};
    for (AcceleratorKind kind : all_accelerator_kinds()) {
      const auto accel = make_accelerator(m, kind);
      RayCache cache;
      bvh::RayPacket packet;
      packet.rays[0] = r;
      packet.active = 1;
      EXPECT_THROW(accel->intersect(r), Error) << to_string(kind) << " 2^" << e;
      EXPECT_THROW(accel->occluded(r), Error) << to_string(kind);
      EXPECT_THROW(accel->intersect(packet, cache), Error) << to_string(kind);
      EXPECT_THROW(accel->occluded(packet, cache), Error) << to_string(kind);
    }
  }
  Ray3f far, near;
  far.origin = {0, std::ldexp(1.0f, 36), 0};
  far.direction = {0, -1, 0};
  near.origin = {0, 30, 0};  // towards the centre of triangle 0: answered
  near.direction = (bvh::test::corner(bunny, 0, 0) + bvh::test::corner(bunny, 0, 1) + bvh::test::corner(bunny, 0, 2)) / 3 - near.origin;
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    const auto accel = make_accelerator(bunny, kind);
    EXPECT_THROW(accel->intersect(far), Error) << to_string(kind);
    EXPECT_THROW(accel->occluded(far), Error) << to_string(kind);
    EXPECT_TRUE(accel->intersect(near).hit()) << to_string(kind);
  }
}

TEST(Accelerators, ParallelQueriesGiveTheSameAnswers) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  const std::vector<Ray3f> rays = test_rays(mesh, 21, 2000);
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    const auto accel = make_accelerator(mesh, kind);
    std::vector<RayHit> serial(rays.size()), parallel(rays.size());
    std::vector<char> blocked(rays.size()), parallel_blocked(rays.size());
    // In parallel first, so the 5D classifier subdivides concurrently.
    parallel_for(0, rays.size(), 64, [&](std::size_t b, std::size_t e) {
      RayCache cache;
      for (std::size_t i = b; i < e; ++i) {
        parallel[i] = accel->intersect(rays[i], cache);
        parallel_blocked[i] = accel->occluded(rays[i], cache);
      }
    });
    for (std::size_t i = 0; i < rays.size(); ++i) {
      serial[i] = brute_closest(mesh, rays[i]);
      blocked[i] = brute_any(mesh, rays[i]);
      EXPECT_TRUE(same_hit(mesh, rays[i], serial[i], parallel[i], kind)) << to_string(kind) << " ray " << i;
      EXPECT_EQ(parallel_blocked[i], blocked[i]) << to_string(kind) << " ray " << i;
    }
    EXPECT_NO_THROW(accel->validate());
  }
}

// The builds split their work by thread (the grid's cell ranges) and by fixed
// chunks (the octree's large nodes); the arrays must not depend on either.
TEST(Accelerators, GridAndOctreeBuildsAreTheSameOnAnyThreadCount) {
  TriMesh mesh = ugly_soup(41, 800);  // small triangles, then ugly ones
  Rng rng(42);
  for (int i = 0; i < 40000; ++i) {
    const Vec3f p = random_vec(rng, Vec3f::Constant(-1), Vec3f::Constant(1));
    const auto base = std::uint32_t(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {p, p + 0.02f * random_direction(rng), p + 0.02f * random_direction(rng)});
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  ASSERT_GT(mesh.num_triangles(), 32768u);  // two chunks at the octree's root
  set_num_threads(1);
  const auto grid1 = UniformGrid::build(mesh);
  const auto octree1 = RayOctree::build(mesh);
  set_num_threads(2);
  const auto grid2 = UniformGrid::build(mesh);
  const auto octree2 = RayOctree::build(mesh);
  set_num_threads(0);
  ASSERT_EQ(grid1->resolution(), grid2->resolution());
  const Vec3i r = grid1->resolution();
  for (int z = 0; z < r[2]; ++z)
    for (int y = 0; y < r[1]; ++y)
      for (int x = 0; x < r[0]; ++x) {
        const auto a = grid1->cell(x, y, z), b = grid2->cell(x, y, z);
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << x << " " << y << " " << z;
      }
  ASSERT_EQ(octree1->nodes().size(), octree2->nodes().size());
  ASSERT_EQ(octree1->triangles().size(), octree2->triangles().size());
  EXPECT_EQ(0, std::memcmp(octree1->nodes().data(), octree2->nodes().data(),
                           octree1->nodes().size() * sizeof(RayOctree::Node)));
  EXPECT_EQ(0, std::memcmp(octree1->triangles().data(), octree2->triangles().data(),
                           octree1->triangles().size() * sizeof(std::uint32_t)));
}

TEST(Accelerators, CachesHelpCoherentRays) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  const auto accel = make_accelerator(mesh, AcceleratorKind::rays5d);
  const AABB3f box = mesh.bounds();
  // A fan of coherent rays from one eye, then shadow rays towards one light.
  RayCache primary, shadow;
  const Vec3f eye = box.center() + Vec3f(0, 0, 3 * box.extent().norm());
  std::size_t blocked = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      Ray3f r;
      r.origin = eye;
      // A window of a tenth of the bunny: about a pixel per 1/1000 of the direction cube's face.
      const Vec3f target = box.center() + 0.1f * Vec3f(box.extent()[0] * ((x + 0.5f) / 40 - 0.5f),
                                                        box.extent()[1] * ((y + 0.5f) / 40 - 0.5f), 0);
      r.direction = (target - eye).normalized();
      const RayHit hit = accel->intersect(r, primary);
      ASSERT_TRUE(same_hit(mesh, r, brute_closest(mesh, r), hit, AcceleratorKind::rays5d));
      if (!hit.hit()) continue;
      Ray3f s;
      s.origin = r.at(hit.t) - 1e-4f * r.direction;
      s.direction = Vec3f(0.2f, 0.1f, -1.0f).normalized();  // into the bunny: blocked by its back
      const bool occluded = accel->occluded(s, shadow);
      ASSERT_EQ(occluded, brute_any(mesh, s));
      blocked += occluded;
    }
  EXPECT_GT(primary.cell_hits, 800u) << "coherent rays should mostly start in the cached leaf";
  EXPECT_GT(blocked, 0u);
  EXPECT_GT(shadow.occluder_hits, 0u) << "neighbouring shadow rays should share occluders";
  const AcceleratorStats stats = accel->stats();
  EXPECT_GT(stats.nodes, 6u) << "rays should have subdivided the 5D octrees";
  EXPECT_EQ(stats.references, static_cast<const RayClassifier&>(*accel).references());
}

TEST(Accelerators, StatsDescribeTheStructures) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  const auto grid = UniformGrid::build(mesh);
  const AcceleratorStats g = grid->stats();
  EXPECT_EQ(g.kind, "grid");
  EXPECT_EQ(g.triangles, mesh.num_triangles());
  EXPECT_EQ(g.nodes, std::size_t(g.resolution[0]) * g.resolution[1] * g.resolution[2]);
  // About density * n cells.
  EXPECT_GT(g.nodes, mesh.num_triangles());
  EXPECT_LT(g.nodes, 12 * mesh.num_triangles());
  EXPECT_GE(g.references, mesh.num_triangles());
  const auto octree = RayOctree::build(mesh);
  const AcceleratorStats o = octree->stats();
  EXPECT_EQ((o.nodes - 1) % 8, 0u);
  EXPECT_GE(o.references, mesh.num_triangles());
  EXPECT_GT(o.depth, 2u);
  EXPECT_LE(o.depth, 12u);
}

// save() / load_accelerator(): every kind comes back mapped (the 5D classifier
// rebuilt from its saved triangles) and answers every ray bit for bit like the
// original, caches included; bad files give geods::Error naming the file.
TEST(AcceleratorArchive, EveryKindRoundTripsBitForBit) {
  TriMesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  TriMesh flat = ugly_soup(31, 400);
  for (Vec3f& v : flat.vertices) v.y() = -0.5f;
  const std::pair<const char*, TriMesh> meshes[] = {
      {"bunny", test::data_mesh("bunny.ply")}, {"one", one}, {"flat", flat}, {"soup", ugly_soup(32, 1500)}};
  for (const auto& [name, mesh] : meshes)
    for (AcceleratorKind kind : all_accelerator_kinds()) {
      SCOPED_TRACE(std::string(name) + " " + std::string(to_string(kind)));
      const auto built = make_accelerator(mesh, kind);
      const auto path = geods::test::temp_archive("accel_" + std::string(to_string(kind)));
      built->save(path);
      const auto loaded = load_accelerator(path);
      std::filesystem::remove(path);
      ASSERT_EQ(loaded->kind(), kind);
      EXPECT_TRUE(loaded->mapped());
      EXPECT_FALSE(built->mapped());
      EXPECT_EQ(loaded->num_triangles(), mesh.num_triangles());
      EXPECT_NO_THROW(loaded->validate());
      const AcceleratorStats a = built->stats(), b = loaded->stats();
      if (kind != AcceleratorKind::rays5d) {  // its trees grow with the rays
        EXPECT_EQ(a.nodes, b.nodes);
        EXPECT_EQ(a.references, b.references);
        EXPECT_EQ(a.depth, b.depth);
      }
      EXPECT_EQ(a.build_s, kind == AcceleratorKind::rays5d ? a.build_s : b.build_s);
      RayCache ca, cb, sa, sb;
      for (const Ray3f& ray : test_rays(mesh, 41, 900)) {
        const RayHit ha = built->intersect(ray, ca), hb = loaded->intersect(ray, cb);
        ASSERT_EQ(std::memcmp(&ha, &hb, sizeof ha), 0) << "t " << ha.t << " vs " << hb.t;
        ASSERT_EQ(built->occluded(ray, sa), loaded->occluded(ray, sb));
      }
    }
}

TEST(AcceleratorArchive, OctreeArraysAreMappedAndEqual) {
  const TriMesh mesh = test::data_mesh("teapot.obj");
  const auto built = RayOctree::build(mesh);
  const auto path = geods::test::temp_archive("octree_arrays");
  built->save(path);
  const auto loaded = RayOctree::load(path);
  EXPECT_TRUE(loaded->nodes().mapped());
  EXPECT_TRUE(loaded->triangles().mapped());
  EXPECT_EQ(loaded->triangles(), built->triangles());
  ASSERT_EQ(loaded->nodes().size(), built->nodes().size());
  for (std::size_t i = 0; i < built->nodes().size(); ++i) {
    EXPECT_EQ(loaded->nodes()[i].first, built->nodes()[i].first);
    EXPECT_EQ(loaded->nodes()[i].count, built->nodes()[i].count);
  }
  std::filesystem::remove(path);
}

TEST(AcceleratorArchive, BadFilesAreRefused) {
  const TriMesh mesh = ugly_soup(33, 300);
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    SCOPED_TRACE(to_string(kind));
    const auto path = geods::test::temp_archive("accel_bad_" + std::string(to_string(kind)));
    make_accelerator(mesh, kind)->save(path);
    geods::test::expect_bad_copies_refused(path, [](const auto& p) { load_accelerator(p); }, 20, 60);
    std::filesystem::remove(path);
  }
  // Each class refuses the others' files, naming the file and both kinds.
  const auto path = geods::test::temp_archive("accel_kind");
  UniformGrid::build(mesh)->save(path);
  try {
    RayOctree::load(path);
    ADD_FAILURE() << "loaded a grid as an octree";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    EXPECT_NE(what.find("ray.UniformGrid"), std::string::npos) << what;
  }
  EXPECT_THROW(RayClassifier::load(path), Error);
  EXPECT_THROW(BvhAccelerator::load(path), Error);
  EXPECT_THROW(bvh::TriangleBvh::load(path), Error);
  EXPECT_NO_THROW(UniformGrid::load(path));
  bvh::TriangleBvh::build(mesh).save(path);
  EXPECT_THROW(load_accelerator(path), Error);
  std::filesystem::remove(path);
}

// Archives with the right checksums and an inconsistent structure.
TEST(AcceleratorArchive, InconsistentGridsAndOctreesAreRefused) {
  const TriMesh mesh = ugly_soup(34, 200);
  const auto grid = UniformGrid::build(mesh);
  const auto path = geods::test::temp_archive("accel_inconsistent");
  std::vector<Vec3f> corners;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) corners.push_back(mesh.vertices[t[k]]);
  auto write_grid = [&](const Vec3i& resolution, const std::vector<std::uint32_t>& begin,
                        const std::vector<std::uint32_t>& triangles, const std::vector<Vec3f>& c) {
    ArchiveWriter out(UniformGrid::kArchiveKind, UniformGrid::kArchiveVersion);
    out.add("corners", c);
    out.add_value("build_s", 0.0);
    out.add_value("resolution", resolution);
    out.add("cell_begin", begin);
    out.add("cell_triangles", triangles);
    out.write(path);
  };
  const Vec3i res = grid->resolution();
  std::vector<std::uint32_t> begin, triangles;
  begin.push_back(0);
  for (int z = 0; z < res[2]; ++z)
    for (int y = 0; y < res[1]; ++y)
      for (int x = 0; x < res[0]; ++x) {
        const auto cell = grid->cell(x, y, z);
        triangles.insert(triangles.end(), cell.begin(), cell.end());
        begin.push_back(std::uint32_t(triangles.size()));
      }
  write_grid(res, begin, triangles, corners);
  EXPECT_NO_THROW(UniformGrid::load(path));  // the writer is right
  write_grid(Vec3i(res[0], res[1], res[2] + 1), begin, triangles, corners);
  EXPECT_THROW(UniformGrid::load(path), Error);
  write_grid(Vec3i(-1, res[1], res[2]), begin, triangles, corners);
  EXPECT_THROW(UniformGrid::load(path), Error);
  write_grid(Vec3i(1 << 30, 1 << 30, 1 << 30), begin, triangles, corners);
  EXPECT_THROW(UniformGrid::load(path), Error);
  std::vector<std::uint32_t> bad = triangles;
  bad[0] = std::uint32_t(mesh.num_triangles());
  write_grid(res, begin, bad, corners);
  EXPECT_THROW(UniformGrid::load(path), Error);
  std::vector<Vec3f> nan_corners = corners;
  nan_corners[4].x() = std::numeric_limits<float>::quiet_NaN();
  write_grid(res, begin, triangles, nan_corners);
  EXPECT_THROW(UniformGrid::load(path), Error);

  const auto octree = RayOctree::build(mesh);
  auto write_octree = [&](std::uint64_t depth, const std::vector<RayOctree::Node>& nodes) {
    ArchiveWriter out(RayOctree::kArchiveKind, RayOctree::kArchiveVersion);
    out.add("corners", corners);
    out.add_value("build_s", 0.0);
    out.add_value("depth", depth);
    out.add("nodes", nodes);
    out.add("leaf_triangles", octree->triangles());
    out.write(path);
  };
  const std::vector<RayOctree::Node> nodes = octree->nodes().to_vector();
  const std::uint64_t depth = octree->stats().depth;
  write_octree(depth, nodes);
  EXPECT_NO_THROW(RayOctree::load(path));
  write_octree(depth + 1, nodes);
  EXPECT_THROW(RayOctree::load(path), Error);
  write_octree(1000000, nodes);
  EXPECT_THROW(RayOctree::load(path), Error);
  std::vector<RayOctree::Node> cycle = nodes;
  ASSERT_FALSE(cycle[0].leaf());
  cycle[0].first = 0;  // the root its own child
  write_octree(depth, cycle);
  EXPECT_THROW(RayOctree::load(path), Error);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace geods::ray

namespace geods::ray {
namespace {

// Packets of N consecutive rays against one ray at a time.
template <int N>
std::size_t expect_packets_answer_as_single_rays(const Accelerator& accel, AcceleratorKind kind,
                                                 const std::vector<Ray3f>& rays) {
  RayCache cache, shadow_cache;
  std::size_t hits = 0;
  for (std::size_t first = 0; first + N <= rays.size(); first += N) {
    bvh::RayPacketN<N> packet;
    for (int i = 0; i < N; ++i) packet.rays[i] = rays[first + std::size_t(i)];
    packet.active = first % 3 == 0 ? (1u << N) - 1 : 0xb7b7u & ((1u << N) - 1);
    const bvh::HitPacketN<N> out = accel.intersect(packet, cache);
    const std::uint32_t blocked = accel.occluded(packet, shadow_cache);
    for (int i = 0; i < N; ++i) {
      const Ray3f& r = packet.rays[i];
      const bool active = packet.active >> i & 1;
      const RayHit single = active ? accel.intersect(r) : RayHit{};
      EXPECT_EQ(std::memcmp(&out.hits[i].t, &single.t, sizeof(float)), 0)
          << to_string(kind) << " packet of " << N << " ray " << first + i;
      EXPECT_EQ(out.hits[i].prim, single.prim) << to_string(kind) << " packet of " << N << " ray " << first + i;
      EXPECT_EQ(bool(blocked >> i & 1), active && accel.occluded(r))
          << to_string(kind) << " packet of " << N << " ray " << first + i;
      hits += single.hit();
    }
  }
  return hits;
}

// The packet queries of every kind, of 8 and 16 rays, give what one ray at a
// time gives (the BVH traverses the packet together; the others loop), bad
// rays and partial masks included.
TEST(Accelerators, PacketsAnswerAsSingleRays) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  std::vector<Ray3f> rays = test_rays(mesh, 17, 400);
  rays[3].direction = Vec3f::Zero();
  rays[12].origin.x() = std::numeric_limits<float>::quiet_NaN();
  rays[21].tmin = 2, rays[21].tmax = 1;
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    const auto accel = make_accelerator(mesh, kind);
    EXPECT_GT(expect_packets_answer_as_single_rays<8>(*accel, kind, rays), rays.size() / 10) << to_string(kind);
    EXPECT_GT(expect_packets_answer_as_single_rays<16>(*accel, kind, rays), rays.size() / 10) << to_string(kind);
  }
}

}  // namespace
}  // namespace geods::ray
