// Packets of rays (ray_packet.hpp) against the single-ray queries on the same
// rays: bit-identical closest hits (t, u, v, triangle) and occlusion for every
// ray, on incoherent, coherent (pinhole camera tiles) and degenerate rays,
// rays from inside boxes and axis-parallel rays, packets of 8 and 16, 4 and 8
// wide, the fallback layouts, partial masks and every SIMD level; brute force
// checks the t.
#include <gtest/gtest.h>

#include <limits>

#include "bvh/bvh_test_util.hpp"
#include "geods/core/error.hpp"
#include "geods/core/simd_level.hpp"

namespace geods::bvh {
namespace {

// Packets of N consecutive rays with the given active masks (cycled; empty:
// all rays) against one ray at a time; returns the number of hits.
template <int N>
std::size_t expect_packets_match(const TriangleBvh& bvh, const std::vector<Ray3f>& rays, const std::string& what,
                                 const std::vector<std::uint32_t>& masks = {}) {
  std::size_t hits = 0, k = 0;
  for (std::size_t first = 0; first < rays.size(); first += N, ++k) {
    RayPacketN<N> packet;
    const std::size_t n = std::min<std::size_t>(N, rays.size() - first);
    for (std::size_t i = 0; i < n; ++i) packet.rays[i] = rays[first + i];
    packet.active = (masks.empty() ? ~0u : masks[k % masks.size()]) & ((1u << n) - 1);
    const HitPacketN<N> out = bvh.intersect(packet);
    const std::uint32_t blocked = bvh.occluded(packet);
    for (std::size_t i = 0; i < n; ++i) {
      if (!(packet.active >> i & 1)) {
        EXPECT_FALSE(out.hits[i].hit()) << what << ": inactive ray " << first + i;
        EXPECT_FALSE(blocked >> i & 1) << what << ": inactive ray " << first + i;
        continue;
      }
      const RayHit single = bvh.intersect(rays[first + i]);
      EXPECT_TRUE(test::same_bits(out.hits[i], single))
          << what << " packet of " << N << " ray " << first + i << ": packet t " << out.hits[i].t << " prim " << out.hits[i].prim
          << ", single t " << single.t << " prim " << single.prim;
      EXPECT_EQ(bool(blocked >> i & 1), bvh.occluded(rays[first + i])) << what << " packet of " << N << " ray " << first + i;
      hits += single.hit();
    }
  }
  return hits;
}

// Every layout the packet reads (4 and 8 wide) and one it does not (OBBs: ray
// by ray), packets of 8 and of 16.
void expect_layouts_match(const TriMesh& mesh, const std::vector<Ray3f>& rays, const std::string& what) {
  for (int arity : {4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(mesh, options);
    const std::string name = what + " arity " + std::to_string(arity);
    const std::size_t hits = expect_packets_match<8>(bvh, rays, name, {0xff, 0x5a, 0x81, 0x01, 0xfe, 0x00});
    EXPECT_GT(hits, rays.size() / 20) << what << ": the rays must hit something to compare";
    expect_packets_match<16>(bvh, rays, name, {0xffff, 0x5aa5, 0x8001, 0x0001, 0xfffe, 0x0000, 0x00ff, 0xff00, 0x0700});
  }
  BuildOptions obb;
  obb.bv = BoundingVolume::obb;
  const TriangleBvh obb_bvh = TriangleBvh::build(mesh, obb);
  const std::vector<Ray3f> some(rays.begin(), rays.begin() + std::min<std::size_t>(rays.size(), 400));
  expect_packets_match<8>(obb_bvh, some, what + " obb");
  expect_packets_match<16>(obb_bvh, some, what + " obb");
}

// Primary rays of a pinhole camera in 4 x tile_h pixel tiles (coherent packets).
std::vector<Ray3f> camera_rays(const AABB3f& box, Vec3f eye, int width, int height, int tile_h = 2) {
  const Vec3f target = box.center();
  const Vec3f forward = (target - eye).normalized();
  const Vec3f right = forward.cross(Vec3f::UnitY()).normalized();
  const Vec3f up = right.cross(forward);
  std::vector<Ray3f> rays;
  for (int ty = 0; ty < height; ty += tile_h)
    for (int tx = 0; tx < width; tx += 4)
      for (int y = ty; y < ty + tile_h; ++y)
        for (int x = tx; x < tx + 4; ++x) {
          Ray3f r;
          r.origin = eye;
          r.direction = (forward + (float(x) / float(width) - 0.5f) * 0.8f * right -
                         (float(y) / float(height) - 0.5f) * 0.8f * up)
                            .normalized();
          rays.push_back(r);
        }
  return rays;
}

TEST(RayPacket, IncoherentAndHardRaysMatchTheSingleRayOnTheBunny) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  expect_layouts_match(bunny, test::test_rays(bunny, 1600, 21), "bunny hard rays");
}

TEST(RayPacket, CoherentCameraRaysMatchTheSingleRayAndBruteForce) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const AABB3f box = bunny.bounds();
  const std::vector<Ray3f> rays = camera_rays(box, box.center() + 1.5f * box.extent(), 48, 32);
  expect_layouts_match(bunny, rays, "bunny camera");
  // 4 x 4 tiles: the packets of 16 of rtcIntersect16.
  const std::vector<Ray3f> tiles16 = camera_rays(box, box.center() + 1.5f * box.extent(), 48, 32, 4);
  expect_layouts_match(bunny, tiles16, "bunny camera 4 x 4");
  BuildOptions options;
  options.arity = 8;
  const TriangleBvh bvh = TriangleBvh::build(bunny, options);
  std::vector<RayHit> hits(rays.size()), hits16(rays.size());
  bvh.intersect_packets(rays, hits);
  bvh.intersect_packets(tiles16, hits16, 16);
  std::vector<std::uint8_t> blocked(rays.size()), blocked16(rays.size());
  bvh.occluded_packets(rays, blocked);
  bvh.occluded_packets(tiles16, blocked16, 16);
  for (std::size_t i = 0; i < rays.size(); i += 7) {
    const RayHit brute = test::brute_intersect(bunny, rays[i]);
    EXPECT_EQ(hits[i].t, brute.t) << "ray " << i;
    EXPECT_EQ(bool(blocked[i]), brute.hit()) << "ray " << i;
    const RayHit brute16 = test::brute_intersect(bunny, tiles16[i]);
    EXPECT_EQ(hits16[i].t, brute16.t) << "4 x 4 ray " << i;
    EXPECT_EQ(bool(blocked16[i]), brute16.hit()) << "4 x 4 ray " << i;
  }
  // Shadow rays from the hits towards a light (any hit), a short tmax too.
  std::vector<Ray3f> shadows;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!hits[i].hit()) continue;
    Ray3f s;
    s.origin = rays[i].at(hits[i].t) + 1e-4f * Vec3f(0.3f, 1.0f, 0.2f);
    s.direction = Vec3f(0.3f, 1.0f, 0.2f).normalized();
    s.tmax = i % 3 == 0 ? 0.01f : std::numeric_limits<float>::infinity();
    shadows.push_back(s);
  }
  ASSERT_GT(shadows.size(), rays.size() / 10);
  expect_packets_match<8>(bvh, shadows, "shadow rays");
  expect_packets_match<16>(bvh, shadows, "shadow rays");
}

TEST(RayPacket, RaysFromInsideBoxesAndAxisParallelRays) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const AABB3f box = bunny.bounds();
  Rng rng(5);
  std::vector<Ray3f> rays;
  // From the centre and from points inside the box, in all directions.
  for (int i = 0; i < 400; ++i) {
    Ray3f r;
    r.origin = i < 200 ? box.center() : Vec3f(box.center() + 0.45f * box.extent().cwiseProduct(test::random_point(rng, -1, 1)));
    r.direction = test::random_direction(rng);
    rays.push_back(r);
  }
  // Packets of parallel axis-aligned rays (+-x, +-y, +-z), from inside and outside.
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1})
      for (int i = 0; i < 64; ++i) {
        Ray3f r;
        r.origin = box.center() + 0.4f * box.extent().cwiseProduct(Vec3f(float(i % 8) / 8 - 0.5f, float(i / 8) / 8 - 0.5f, 0.1f));
        if (i >= 32) r.origin[axis] = sign > 0 ? box.lo[axis] - 0.1f : box.hi[axis] + 0.1f;
        r.direction = Vec3f::Zero();
        r.direction[axis] = float(sign);
        rays.push_back(r);
      }
  expect_layouts_match(bunny, rays, "inside and axis-parallel");
}

TEST(RayPacket, DegenerateSoupsAndDegenerateRays) {
  const TriMesh soup = test::random_soup(500, 31);
  std::vector<Ray3f> rays = test::test_rays(soup, 1200, 32);
  // Rays the packet hands to the single ray, mixed into packets of good rays.
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 3; i < rays.size(); i += 29) {
    Ray3f& r = rays[i];
    switch (i % 6) {
      case 0: r.direction = Vec3f::Zero(); break;
      case 1: r.origin[1] = nan; break;
      case 2: r.direction[2] = inf; break;
      case 3: r.tmin = r.tmax = 0.5f; break;
      case 4: r.tmin = 2.0f, r.tmax = 1.0f; break;
      default: r.tmax = nan; break;
    }
  }
  expect_layouts_match(soup, rays, "soup");
}

TEST(RayPacket, TiesAtSharedEdgesKeepTheSingleRayTriangle) {
  // A flat grid hit exactly through its vertices and edges: several triangles
  // at the same t, where the single ray's visiting order picks one.
  const int n = 12;
  const TriMesh grid = test::flat_grid(n);
  std::vector<Ray3f> rays;
  for (int y = 0; y <= 2 * n; ++y)
    for (int x = 0; x <= 2 * n; ++x) {
      Ray3f r;
      r.origin = {0.5f * float(x), 0.5f * float(y), 1.0f};
      r.direction = {0.0f, 0.0f, -1.0f};
      rays.push_back(r);
    }
  for (int y = 0; y <= 2 * n; ++y)
    for (int x = 0; x <= 2 * n; ++x) {
      Ray3f r;
      r.direction = Vec3f(0.25f, -0.5f, -1.0f);
      r.origin = Vec3f(0.5f * float(x), 0.5f * float(y), 0.0f) - r.direction;
      rays.push_back(r);
    }
  expect_layouts_match(grid, rays, "grid");
}

TEST(RayPacket, LinesWithNegativeTminSeeHitsBehindTheirOrigins) {
  // Parallel lines (tmin < 0) through a flat grid from above it: every hit
  // lies behind the origin, in boxes flat along the direction's main axis.
  const TriMesh grid = test::flat_grid(6);
  std::vector<Ray3f> rays;
  for (int i = 0; i < 256; ++i) {
    Ray3f r;
    r.origin = Vec3f(0.25f + 0.02f * float(i % 16), 0.25f + 0.02f * float(i / 16), 0.5f + 0.01f * float(i % 7));
    r.origin *= 6.0f;
    r.direction = Vec3f(0.125f, -0.0625f, 1.0f);
    r.tmin = i % 3 ? -100.0f : -std::numeric_limits<float>::infinity();
    rays.push_back(r);
  }
  for (std::size_t i = 0; i < rays.size(); i += 37)
    ASSERT_TRUE(test::brute_intersect(grid, rays[i]).hit()) << "the lines must cross the grid behind their origins";
  expect_layouts_match(grid, rays, "lines");
}

TEST(RayPacket, EveryLevelGivesThePortableSingleRayHits) {
  const test::LevelGuard guard;
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const AABB3f box = bunny.bounds();
  std::vector<Ray3f> rays = camera_rays(box, box.center() + 1.5f * box.extent(), 32, 16);
  const std::vector<Ray3f> tiles16 = camera_rays(box, box.center() + 1.5f * box.extent(), 32, 16, 4);
  rays.insert(rays.end(), tiles16.begin(), tiles16.end());
  const std::vector<Ray3f> hard = test::test_rays(bunny, 512, 41);
  rays.insert(rays.end(), hard.begin(), hard.end());
  BuildOptions options;
  options.arity = 8;
  const TriangleBvh bvh = TriangleBvh::build(bunny, options);
  set_simd_level(SimdLevel::portable);
  std::vector<RayHit> expected(rays.size());
  std::vector<std::uint8_t> blocked(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) expected[i] = bvh.intersect(rays[i]), blocked[i] = bvh.occluded(rays[i]);
  for (SimdLevel level : {SimdLevel::portable, SimdLevel::avx, SimdLevel::avx2, SimdLevel::avx512}) {
    if (level > best_simd_level()) continue;
    set_simd_level(level);
    for (int size : {8, 16}) {
      std::vector<RayHit> hits(rays.size());
      std::vector<std::uint8_t> occ(rays.size());
      bvh.intersect_packets(rays, hits, size);
      bvh.occluded_packets(rays, occ, size);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        ASSERT_TRUE(test::same_bits(hits[i], expected[i]))
            << simd_level_name(level) << " packets of " << size << " ray " << i;
        ASSERT_EQ(occ[i], blocked[i]) << simd_level_name(level) << " packets of " << size << " ray " << i;
      }
    }
  }
}

TEST(RayPacket, EmptyHierarchyAndSizeMismatch) {
  const TriangleBvh empty;
  RayPacket packet;
  for (Ray3f& r : packet.rays) r.direction = Vec3f(0, 0, 1);
  const HitPacket out = empty.intersect(packet);
  for (const RayHit& h : out.hits) EXPECT_FALSE(h.hit());
  EXPECT_EQ(empty.occluded(packet), 0u);
  RayPacket16 packet16;
  for (Ray3f& r : packet16.rays) r.direction = Vec3f(0, 0, 1);
  for (const RayHit& h : empty.intersect(packet16).hits) EXPECT_FALSE(h.hit());
  EXPECT_EQ(empty.occluded(packet16), 0u);
  std::vector<Ray3f> rays(10);
  std::vector<RayHit> hits(9);
  std::vector<std::uint8_t> occ(11);
  EXPECT_THROW(empty.intersect_packets(rays, hits), Error);
  EXPECT_THROW(empty.occluded_packets(rays, occ), Error);
  std::vector<RayHit> ten(10);
  std::vector<std::uint8_t> ten_occ(10);
  EXPECT_THROW(empty.intersect_packets(rays, ten, 4), Error);
  EXPECT_THROW(empty.occluded_packets(rays, ten_occ, 32), Error);
}

}  // namespace
}  // namespace geods::bvh
