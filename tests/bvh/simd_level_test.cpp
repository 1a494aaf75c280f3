// The wide ray traversal at every SIMD level the CPU runs (core/simd_level.hpp)
// against the portable path on the same inputs: bit-identical hits (t, u, v,
// triangle) and occlusion, 4 and 8 wide; and the level switch itself.
#include <gtest/gtest.h>

#include <limits>

#include "bvh/bvh_test_util.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/core/error.hpp"

namespace geods::bvh {
namespace {

std::vector<SimdLevel> levels_to_test() {
  std::vector<SimdLevel> out;
  for (SimdLevel l : {SimdLevel::avx, SimdLevel::avx2, SimdLevel::avx512})
    if (l <= best_simd_level()) out.push_back(l);
  return out;
}

void expect_levels_agree(const TriMesh& mesh, const std::vector<Ray3f>& rays, const std::string& what) {
  const test::LevelGuard guard;
  for (int arity : {4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(mesh, options);
    set_simd_level(SimdLevel::portable);
    std::vector<RayHit> expected;
    std::vector<char> blocked;
    std::size_t hits = 0;
    for (const Ray3f& r : rays) {
      expected.push_back(bvh.intersect(r));
      blocked.push_back(bvh.occluded(r));
      hits += expected.back().hit();
      EXPECT_EQ(bool(blocked.back()), expected.back().hit()) << what;
    }
    EXPECT_GT(hits, rays.size() / 10) << what << ": the rays must hit something to compare";
    for (SimdLevel level : levels_to_test()) {
      set_simd_level(level);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const RayHit hit = bvh.intersect(rays[i]);
        ASSERT_TRUE(test::same_bits(hit, expected[i])) << what << " arity " << arity << " " << simd_level_name(level)
                                                       << " ray " << i << ": t " << hit.t << " vs " << expected[i].t;
        ASSERT_EQ(bvh.occluded(rays[i]), bool(blocked[i])) << what << " " << simd_level_name(level) << " ray " << i;
      }
    }
  }
}

TEST(SimdLevel, NamesRoundTripAndUnknownNamesAreErrors) {
  for (SimdLevel l : {SimdLevel::portable, SimdLevel::avx, SimdLevel::avx2, SimdLevel::avx512})
    EXPECT_EQ(parse_simd_level(simd_level_name(l)), l);
  EXPECT_THROW(parse_simd_level("sse9"), Error);
  EXPECT_LE(simd_level(), best_simd_level());
}

TEST(SimdLevel, SetRefusesLevelsTheCpuLacksAndKeepsTheCurrentOne) {
  const test::LevelGuard guard;
  set_simd_level(SimdLevel::portable);
  EXPECT_EQ(simd_level(), SimdLevel::portable);
  if (best_simd_level() < SimdLevel::avx512) {
    EXPECT_THROW(set_simd_level(SimdLevel::avx512), Error);
    EXPECT_EQ(simd_level(), SimdLevel::portable);
  }
  set_simd_level(best_simd_level());
  EXPECT_EQ(simd_level(), best_simd_level());
}

TEST(SimdLevel, EveryLevelGivesThePortableHitsOnTheBunny) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  expect_levels_agree(bunny, test::test_rays(bunny, 3000, 7), "bunny");
}

TEST(SimdLevel, EveryLevelGivesThePortableHitsOnDegenerateSoups) {
  // Tiny, huge, axis-aligned and degenerate triangles; rays at vertices and
  // edge midpoints, where the scalar fallback of the 4-lane test decides.
  const TriMesh soup = test::random_soup(600, 11);
  expect_levels_agree(soup, test::test_rays(soup, 3000, 12), "soup");
}

TEST(SimdLevel, EveryLevelGivesThePortableHitsOnAGridThroughItsEdges) {
  // A flat grid of right triangles hit by axis-parallel rays exactly through
  // its vertices and edges (edge functions exactly zero in every lane).
  TriMesh grid;
  const int n = 12;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) grid.vertices.push_back({float(x), float(y), 0.0f});
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      grid.triangles.push_back({a, b, d});
      grid.triangles.push_back({a, d, c});
    }
  std::vector<Ray3f> rays;
  for (int y = 0; y <= 2 * n; ++y)
    for (int x = 0; x <= 2 * n; ++x) {
      Ray3f r;
      r.origin = {0.5f * float(x), 0.5f * float(y), 1.0f};
      r.direction = {0.0f, 0.0f, -1.0f};
      rays.push_back(r);
      r.direction = Vec3f(0.25f, -0.5f, -1.0f);  // oblique, through the same grid point at t = 1
      r.origin = Vec3f(0.5f * float(x), 0.5f * float(y), 0.0f) - r.direction;
      rays.push_back(r);
    }
  expect_levels_agree(grid, rays, "grid");
}

TEST(SimdLevel, RaysWithInfiniteDirectionsOrNaNOriginsMatchBruteForceAtEveryLevel) {
  // Slab distances that are all NaN for a node's empty slots (a zero inverse
  // on every axis, or a NaN origin): the traversal once took such a slot's
  // child index (kEmpty) for a node and read far outside the nodes. And
  // directions infinite on one axis: no hits, as the scalar test says.
  const TriMesh soup = test::random_soup(500, 41);
  std::vector<Ray3f> rays = test::test_rays(soup, 600, 42);
  test::make_non_finite_rays(rays, 5);
  const test::LevelGuard guard;
  for (int arity : {4, 8}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(soup, options);
    std::vector<SimdLevel> levels = levels_to_test();
    levels.insert(levels.begin(), SimdLevel::portable);
    for (SimdLevel level : levels) {
      set_simd_level(level);
      for (std::size_t i = 0; i < rays.size(); ++i) {
        const RayHit want = test::brute_intersect(soup, rays[i]), got = bvh.intersect(rays[i]);
        const std::string what = "arity " + std::to_string(arity) + " " + simd_level_name(level) + " ray " +
                                 std::to_string(i);
        ASSERT_EQ(got.hit(), want.hit()) << what;
        ASSERT_TRUE(!want.hit() || got.t == want.t) << what << ": t " << got.t << " vs " << want.t;
        ASSERT_EQ(bvh.occluded(rays[i]), want.hit()) << what;
      }
    }
  }
}

}  // namespace
}  // namespace geods::bvh
