// TriangleBvh queries against brute force, for every builder and bounding volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "bvh_test_util.hpp"
#include "common/collinear_triangles.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/triangle_box.hpp"

namespace geods::bvh {
namespace {

using test::brute_intersect;

constexpr Builder kBuilders[] = {Builder::sah,    Builder::median,    Builder::pca,    Builder::bottom_up,
                                 Builder::tiling, Builder::insertion, Builder::boxtree};
constexpr BoundingVolume kVolumes[] = {BoundingVolume::aabb,   BoundingVolume::sphere, BoundingVolume::kdop6,
                                       BoundingVolume::kdop14, BoundingVolume::kdop18, BoundingVolume::kdop26,
                                       BoundingVolume::obb,    BoundingVolume::obb_hull,
                                       BoundingVolume::rss};

// The closest hit must have the brute-force t, and its triangle must be hit
// there. Where several triangles meet the ray at the same point (a ray through
// a vertex), the traversal may report another of them, but never one whose t
// rounded higher: box pruning keeps the slack of its rounding.
void expect_same_hit(const TriMesh& mesh, const Ray3f& ray, const RayHit& got, const RayHit& want, const std::string& what) {
  ASSERT_EQ(got.hit(), want.hit()) << what;
  if (!want.hit()) return;
  ASSERT_EQ(got.t, want.t) << what;
  ASSERT_TRUE(test::hits_at(mesh, got.prim, ray, got.t)) << what;
}

void check_rays(const TriMesh& mesh, const TriangleBvh& bvh, const std::vector<Ray3f>& rays,
                const std::vector<RayHit>& expected, const std::string& what) {
  for (std::size_t i = 0; i < rays.size(); ++i) {
    expect_same_hit(mesh, rays[i], bvh.intersect(rays[i]), expected[i], what + " ray " + std::to_string(i));
    ASSERT_EQ(bvh.occluded(rays[i]), expected[i].hit()) << what << " ray " << i;
  }
}

TEST(TriangleBvh, EveryBuilderAndVolumeMatchesBruteForceOnTheBunny) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const auto rays = test::test_rays(bunny, 120, 1);
  std::vector<RayHit> expected;
  for (const auto& r : rays) expected.push_back(brute_intersect(bunny, r));
  Rng rng(2);
  std::vector<Vec3f> points;
  for (int i = 0; i < 20; ++i) points.push_back(test::random_point(rng, -1.2f, 1.2f));
  std::vector<float> distances;
  for (const auto& p : points) distances.push_back(test::brute_distance(bunny, p));
  for (Builder builder : kBuilders)
    for (BoundingVolume bv : kVolumes) {
      BuildOptions options;
      options.builder = builder;
      options.bv = bv;
      options.arity = bv == BoundingVolume::aabb ? 4 : 2;
      const std::string what = std::string(to_string(builder)) + "/" + std::string(to_string(bv));
      const TriangleBvh bvh = TriangleBvh::build(bunny, options);
      ASSERT_NO_THROW(bvh.validate()) << what;
      check_rays(bunny, bvh, rays, expected, what);
      for (std::size_t i = 0; i < points.size(); ++i) {
        const ClosestPoint cp = bvh.closest_point(points[i]);
        ASSERT_EQ(cp.distance, distances[i]) << what;
        ASSERT_LT((cp.point - points[i]).norm() - cp.distance, 1e-6f) << what;
      }
      const BvhStats s = bvh.stats();
      EXPECT_EQ(s.triangles, bunny.num_triangles());
      EXPECT_GE(s.sah_cost, 1.0) << what;
      EXPECT_GT(s.tightness_volume, 0.0) << what;
      EXPECT_GT(s.tightness_hausdorff, 0.0) << what;
    }
}

TEST(TriangleBvh, ArityAndLeafSizeVariantsMatchBruteForceOnTheTeapot) {
  const TriMesh teapot = test::data_mesh("teapot.obj");
  const auto rays = test::test_rays(teapot, 300, 3);
  std::vector<RayHit> expected;
  for (const auto& r : rays) expected.push_back(brute_intersect(teapot, r));
  for (int arity : {2, 4, 8})
    for (int leaf : {1, 4, 16}) {
      for (BoundingVolume bv : {BoundingVolume::aabb, BoundingVolume::obb}) {
        BuildOptions options;
        options.arity = arity;
        options.leaf_size = leaf;
        options.bv = bv;
        const TriangleBvh bvh = TriangleBvh::build(teapot, options);
        const std::string what = "arity " + std::to_string(arity) + " leaf " + std::to_string(leaf);
        ASSERT_NO_THROW(bvh.validate()) << what;
        check_rays(teapot, bvh, rays, expected, what);
        EXPECT_LE(bvh.stats().depth, 64);
      }
    }
}

TEST(TriangleBvh, RandomSoupsWithDegenerateTinyHugeAndAxisAlignedTriangles) {
  for (std::uint64_t seed : {11u, 12u}) {
    const TriMesh soup = test::random_soup(1500, seed);
    const auto rays = test::test_rays(soup, 300, seed + 100);
    std::vector<RayHit> expected;
    for (const auto& r : rays) expected.push_back(brute_intersect(soup, r));
    for (Builder builder : kBuilders)
      for (BoundingVolume bv : {BoundingVolume::aabb, BoundingVolume::sphere, BoundingVolume::kdop18, BoundingVolume::obb}) {
        BuildOptions options;
        options.builder = builder;
        options.bv = bv;
        const TriangleBvh bvh = TriangleBvh::build(soup, options);
        const std::string what = std::string(to_string(builder)) + "/" + std::string(to_string(bv));
        ASSERT_NO_THROW(bvh.validate()) << what;
        check_rays(soup, bvh, rays, expected, what);
      }
  }
}

TEST(TriangleBvh, TrianglesOfZeroAreaAreNeverHitByAnyLayout) {
  // Rounded, the triangle test "hit" some collinear triangles off the
  // triangle, and tight volumes (k-DOPs, OBB, RSS) skipped a few of those.
  const TriMesh soup = geods::test::collinear_soup(600, 41);
  const auto rays = geods::test::rays_along_triangles(soup, 1200, 42);
  std::vector<RayHit> expected;
  for (const auto& r : rays) expected.push_back(brute_intersect(soup, r));
  for (BoundingVolume bv : kVolumes)
    for (int arity : {2, 4, 8}) {
      if (arity > 2 && bv != BoundingVolume::aabb) continue;
      BuildOptions options;
      options.bv = bv;
      options.arity = arity;
      const TriangleBvh bvh = TriangleBvh::build(soup, options);
      const std::string what = std::string(to_string(bv)) + " arity " + std::to_string(arity);
      ASSERT_NO_THROW(bvh.validate()) << what;
      check_rays(soup, bvh, rays, expected, what);
      std::vector<RayHit> packed(rays.size());
      bvh.intersect_packets(rays, packed);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        ASSERT_EQ(packed[i].t, expected[i].t) << what << " packet ray " << i;
        if (!packed[i].hit()) continue;
        ASSERT_FALSE(has_zero_area(test::corner(soup, packed[i].prim, 0), test::corner(soup, packed[i].prim, 1),
                                   test::corner(soup, packed[i].prim, 2)))
            << what << " ray " << i;
      }
    }
}

TEST(TriangleBvh, RaysFromInsideAClosedMeshThroughEveryVertexNeverSlipThrough) {
  // From a point inside a closed mesh every ray must hit, also the rays
  // aimed exactly at vertices (where up to a dozen triangles meet).
  const TriMesh bunny = test::data_mesh("bunny.ply");
  // The grid point deepest inside (winding number as the oracle).
  const TriangleBvh probe = TriangleBvh::build(bunny);
  Vec3f inside = Vec3f::Zero();
  float depth = 0;
  const AABB3f box = bunny.bounds();
  for (int i = 1; i < 8; ++i)
    for (int j = 1; j < 8; ++j)
      for (int k = 1; k < 8; ++k) {
        const Vec3f p = box.lo + Vec3f(i / 8.0f, j / 8.0f, k / 8.0f).cwiseProduct(box.extent());
        const float d = probe.closest_point(p).distance;
        if (d > depth && test::winding_number(bunny, p) > 0.99) depth = d, inside = p;
      }
  ASSERT_GT(depth, 0.05f);
  for (int arity : {2, 4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(bunny, options);
    for (const Vec3f& v : bunny.vertices) {
      Ray3f ray;
      ray.origin = inside;
      ray.direction = v - inside;
      ASSERT_TRUE(bvh.intersect(ray).hit()) << v.transpose();
      ASSERT_TRUE(bvh.occluded(ray));
    }
  }
}

TEST(TriangleBvh, TiedTrianglesOfALeafGoToTheLastInLeafOrder) {
  // n copies of one triangle make one leaf; every copy is hit at the same t,
  // and the one kept is the last in leaf order, as testing them one after
  // the other against the shrinking tmax keeps it (the wide layout tests
  // 4 or 8 at once: 1 to 4 groups, pairs and a group alone).
  for (int arity : {2, 4, 8})
    for (int n = 1; n <= 16; ++n) {
      TriMesh mesh;
      mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
      mesh.triangles.assign(std::size_t(n), {0, 1, 2});
      BuildOptions options;
      options.arity = arity;
      options.leaf_size = 16;
      const TriangleBvh bvh = TriangleBvh::build(mesh, options);
      const std::string what = "arity " + std::to_string(arity) + ", " + std::to_string(n) + " copies";
      ASSERT_EQ(bvh.topology().nodes.size(), 1u) << what;
      Ray3f ray;
      ray.origin = Vec3f(0.25f, 0.25f, -1.0f);
      const RayHit hit = bvh.intersect(ray);
      ASSERT_TRUE(hit.hit()) << what;
      EXPECT_EQ(hit.t, 1.0f) << what;
      EXPECT_EQ(hit.prim, bvh.triangle_ids()[std::size_t(n) - 1]) << what;
    }
}

TEST(TriangleBvh, TmaxAndTminBoundTheHits) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const TriangleBvh bvh = TriangleBvh::build(bunny);
  for (const auto& ray : test::test_rays(bunny, 60, 5)) {
    const RayHit full = bvh.intersect(ray);
    if (!full.hit()) continue;
    Ray3f shorter = ray;
    shorter.tmax = std::nextafter(full.t, 0.0f);
    EXPECT_EQ(bvh.intersect(shorter).t, brute_intersect(bunny, shorter).t);
    Ray3f later = ray;
    later.tmin = std::nextafter(full.t, INFINITY);
    expect_same_hit(bunny, later, bvh.intersect(later), brute_intersect(bunny, later), "tmin");
  }
}

TEST(TriangleBvh, NegativeTminFindsHitsBehindTheOrigin) {
  // Lines (tmin < 0) through a grid of flat, axis-aligned squares: the boxes
  // are flat and the hits lie behind the origin, where the box test's
  // widening must still widen (a relative slack applied to a negative exit
  // distance would narrow it).
  const TriMesh grid = test::flat_grid(6);
  Rng rng(23);
  for (int arity : {2, 4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(grid, options);
    for (int i = 0; i < 400; ++i) {
      Ray3f ray;
      ray.origin = Vec3f(float(rng.uniform() * 6), float(rng.uniform() * 6), float(0.1 + rng.uniform() * 10));
      ray.direction = Vec3f(float(rng.uniform() - 0.5), float(rng.uniform() - 0.5), 1.0f);
      ray.tmin = i % 2 ? -1000.0f : -std::numeric_limits<float>::infinity();
      const RayHit want = brute_intersect(grid, ray);
      ASSERT_TRUE(want.hit() || ray.origin.x() - ray.origin.z() * ray.direction.x() < 0 ||
                  ray.origin.x() - ray.origin.z() * ray.direction.x() > 6 ||
                  ray.origin.y() - ray.origin.z() * ray.direction.y() < 0 ||
                  ray.origin.y() - ray.origin.z() * ray.direction.y() > 6);
      expect_same_hit(grid, ray, bvh.intersect(ray), want, "arity " + std::to_string(arity) + " ray " + std::to_string(i));
      ASSERT_EQ(bvh.occluded(ray), want.hit()) << arity << " " << i;
    }
  }
}

TEST(TriangleBvh, ContainsAgreesWithTheWindingNumber) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  Rng rng(7);
  for (BoundingVolume bv : {BoundingVolume::aabb, BoundingVolume::sphere}) {
    BuildOptions options;
    options.bv = bv;
    const TriangleBvh bvh = TriangleBvh::build(bunny, options);
    int inside = 0, checked = 0;
    for (int i = 0; i < 400; ++i) {
      const Vec3f p = test::random_point(rng, -1.1f, 1.1f);
      if (bvh.closest_point(p).distance < 1e-4f) continue;
      const bool expected = test::winding_number(bunny, p) > 0.5;
      ASSERT_EQ(bvh.contains(p), expected) << p.transpose();
      inside += expected;
      ++checked;
    }
    EXPECT_GT(inside, 20);
    EXPECT_GT(checked - inside, 20);
  }
  // Vertices lie on the surface: inside.
  const TriangleBvh bvh = TriangleBvh::build(bunny);
  for (std::size_t i = 0; i < bunny.num_vertices(); i += 37) EXPECT_TRUE(bvh.contains(bunny.vertices[i]));
}

TEST(TriangleBvh, ContainsOnAClosedAxisAlignedCubeWithPointsOnItsGrid) {
  // A unit cube as 12 triangles: query points share coordinates with its
  // vertices and edges, so many rays would pass through edges.
  TriMesh cube;
  for (int i = 0; i < 8; ++i) cube.vertices.push_back(Vec3f(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)));
  cube.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  ASSERT_TRUE(cube.validate().closed_manifold());
  const TriangleBvh bvh = TriangleBvh::build(cube);
  for (int x = -1; x <= 5; ++x)
    for (int y = -1; y <= 5; ++y)
      for (int z = -1; z <= 5; ++z) {
        const Vec3f p(x * 0.25f, y * 0.25f, z * 0.25f);
        const bool expected = (p.array() >= 0).all() && (p.array() <= 1).all();
        ASSERT_EQ(bvh.contains(p), expected) << p.transpose();
      }
}

TEST(TriangleBvh, BoxAndFrustumCullingMatchBruteForce) {
  const TriMesh soup = test::random_soup(2000, 21);
  Rng rng(22);
  for (BoundingVolume bv : kVolumes) {
    BuildOptions options;
    options.bv = bv;
    const TriangleBvh bvh = TriangleBvh::build(soup, options);
    for (int q = 0; q < 20; ++q) {
      const Vec3f a = test::random_point(rng, -1.2f, 1.2f), b = test::random_point(rng, -1.2f, 1.2f);
      const AABB3f box(a.cwiseMin(b), a.cwiseMax(b));
      std::vector<std::uint32_t> expected;
      for (std::size_t i = 0; i < soup.num_triangles(); ++i)
        if (triangle_box_overlap(test::corner(soup, i, 0), test::corner(soup, i, 1), test::corner(soup, i, 2), box))
          expected.push_back(std::uint32_t(i));
      ASSERT_EQ(bvh.cull_box(box), expected);
      std::vector<Plane3f> planes;
      for (int k = 0; k < 5; ++k) planes.push_back(Plane3f::from_point_normal(test::random_point(rng, -0.5f, 0.5f), test::random_direction(rng)));
      expected.clear();
      for (std::size_t i = 0; i < soup.num_triangles(); ++i) {
        bool outside = false;
        for (const auto& p : planes) {
          bool all = true;
          for (int k = 0; k < 3; ++k) all = all && p.signed_distance(test::corner(soup, i, k)) < 0;
          outside = outside || all;
        }
        if (!outside) expected.push_back(std::uint32_t(i));
      }
      ASSERT_EQ(bvh.cull_frustum(planes), expected);
    }
  }
}

TEST(TriangleBvh, ParallelBuildIsDeterministic) {
  const TriMesh soup = test::random_soup(70000, 41);
  for (Builder builder : {Builder::sah, Builder::median, Builder::pca, Builder::boxtree, Builder::bottom_up,
                          Builder::tiling}) {
    BuildOptions options;
    options.builder = builder;
    set_num_threads(1);
    const TriangleBvh serial = TriangleBvh::build(soup, options);
    set_num_threads(0);
    const TriangleBvh parallel = TriangleBvh::build(soup, options);
    ASSERT_EQ(serial.triangle_ids(), parallel.triangle_ids()) << to_string(builder);
    const auto& a = serial.topology().nodes;
    const auto& b = parallel.topology().nodes;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      ASSERT_TRUE(std::tie(a[i].first_child, a[i].num_children, a[i].prim_first, a[i].prim_count) ==
                  std::tie(b[i].first_child, b[i].num_children, b[i].prim_first, b[i].prim_count));
    ASSERT_NO_THROW(parallel.validate());
  }
}

TEST(TriangleBvh, BadInputRaisesErrors) {
  TriMesh mesh = test::random_soup(10, 1);
  BuildOptions options;
  options.arity = 3;
  EXPECT_THROW(TriangleBvh::build(mesh, options), Error);
  options = {};
  options.leaf_size = 0;
  EXPECT_THROW(TriangleBvh::build(mesh, options), Error);
  mesh.vertices[0][1] = std::nanf("");
  EXPECT_THROW(TriangleBvh::build(mesh), Error);
  mesh = test::random_soup(10, 1);
  mesh.triangles[3][2] = 1000;
  EXPECT_THROW(TriangleBvh::build(mesh), Error);
  EXPECT_THROW(parse_builder("octree"), Error);
  EXPECT_THROW(parse_bounding_volume("cone"), Error);
  const TriangleBvh bvh = TriangleBvh::build(test::random_soup(10, 1));
  EXPECT_THROW(bvh.closest_point(Vec3f(0, INFINITY, 0)), Error);
}

// Within the range of the float watertight test (core/ray_triangle.hpp:
// |coordinate| <= 2^35, an extent of at least 2^-34) the hits of a mesh and
// rays scaled by a power of two are those at unit scale, t scaled; beyond it
// every ray query refuses the mesh or the ray. (They once answered t = inf,
// the wrong triangle or no hit at all, silently: the test's degree-3 terms
// overflowed from about 2^45 and lost precision below about 2^-35.)
TEST(TriangleBvh, RaysAtPowerOfTwoScalesHitAsAtUnitScaleOrAreRefused) {
  const TriMesh bunny = test::data_mesh("bunny.ply");  // coordinates up to 10, extent 10
  const std::vector<Ray3f> rays = test::test_rays(bunny, 700, 61);
  auto scaled_mesh = [&](int e) {
    TriMesh m = bunny;
    for (Vec3f& v : m.vertices) v = Vec3f(std::ldexp(v[0], e), std::ldexp(v[1], e), std::ldexp(v[2], e));
    return m;
  };
  auto scaled_ray = [](Ray3f r, int e) {
    r.origin = Vec3f(std::ldexp(r.origin[0], e), std::ldexp(r.origin[1], e), std::ldexp(r.origin[2], e));
    r.tmin = std::ldexp(r.tmin, e), r.tmax = std::ldexp(r.tmax, e);
    return r;
  };
  for (int arity : {4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh unit = TriangleBvh::build(bunny, options);
    for (int e : {-30, -12, 12, 30}) {
      const TriangleBvh bvh = TriangleBvh::build(scaled_mesh(e), options);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const RayHit want = unit.intersect(rays[i]);
        const RayHit got = bvh.intersect(scaled_ray(rays[i], e));
        ASSERT_EQ(got.prim, want.prim) << "scale 2^" << e << " ray " << i;
        if (!want.hit()) continue;
        ASSERT_EQ(got.t, std::ldexp(want.t, e)) << "scale 2^" << e << " ray " << i;
        ASSERT_EQ(got.u, want.u) << i;
        ASSERT_EQ(got.v, want.v) << i;
      }
    }
  }
  Ray3f ray = rays[0];
  RayPacket packet;
  packet.rays[0] = ray;
  packet.active = 1;
  for (int e : {40, -40}) {  // 2^40 x 10 is beyond 2^35; 2^-40 x 10 spans less than 2^-34
    const TriangleBvh bvh = TriangleBvh::build(scaled_mesh(e));
    const Ray3f far = scaled_ray(ray, e);
    RayPacket far_packet = packet;
    far_packet.rays[0] = far;
    EXPECT_THROW(bvh.intersect(far), Error) << e;
    EXPECT_THROW(bvh.occluded(far), Error) << e;
    EXPECT_THROW(bvh.intersect(far_packet), Error) << e;
    EXPECT_THROW(bvh.occluded(far_packet), Error) << e;
    std::vector<RayHit> hits(1);
    EXPECT_THROW(bvh.intersect_packets(std::span<const Ray3f>(&far, 1), hits), Error) << e;
    EXPECT_NO_THROW(bvh.closest_point(far.origin)) << e;  // distances have their own range
  }
  // A ray from beyond the range towards a mesh inside it; a NaN origin still hits nothing.
  const TriangleBvh bvh = TriangleBvh::build(bunny);
  ray.origin = {std::ldexp(1.0f, 36), 0, 0};
  ray.direction = {-1, 0, 0};
  EXPECT_THROW(bvh.intersect(ray), Error);
  packet.rays[0] = ray;
  EXPECT_THROW(bvh.occluded(packet), Error);
  packet.active = 0;  // an inactive lane is not looked at
  EXPECT_NO_THROW(bvh.occluded(packet));
  ray.origin = {std::nanf(""), 0, 0};
  EXPECT_FALSE(bvh.intersect(ray).hit());
}

TEST(TriangleBvh, EmptyAndSingleTriangleMeshes) {
  const TriangleBvh empty = TriangleBvh::build(TriMesh{});
  Ray3f ray;
  ray.origin = {0.2f, 0.2f, -1};
  EXPECT_FALSE(empty.intersect(ray).hit());
  EXPECT_FALSE(empty.occluded(ray));
  EXPECT_FALSE(empty.contains(Vec3f::Zero()));
  EXPECT_EQ(empty.closest_point(Vec3f::Zero()).prim, RayHit::no_hit);
  EXPECT_NO_THROW(empty.validate());
  EXPECT_EQ(empty.stats().nodes, 0u);
  TriMesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  for (int arity : {2, 4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(one, options);
    EXPECT_NO_THROW(bvh.validate());
    const RayHit hit = bvh.intersect(ray);
    ASSERT_TRUE(hit.hit());
    EXPECT_EQ(hit.t, 1.0f);
    EXPECT_EQ(hit.prim, 0u);
  }
}

}  // namespace
}  // namespace geods::bvh
