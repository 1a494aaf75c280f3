#include "common/data_files.hpp"
#include "geods/bsp/deferred.hpp"

#include <gtest/gtest.h>

#include <random>

#include "bsp/meshes.hpp"
#include "geods/core/predicates.hpp"

using namespace geods;
using namespace geods::bsp;
using namespace bsp_test;

namespace {

// Brute force with the same exact test, written out independently.
bool brute(const Triangles& m, const Vec3d& p, const Vec3d& q) {
  for (const auto& t : m.triangles) {
    const Vec3d &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    if ((b - a).cross(c - a).squaredNorm() == 0) continue;
    const double sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
    if (sp * sq > 0 || (sp == 0 && sq == 0)) continue;
    const double e0 = orient3d(p, q, a, b), e1 = orient3d(p, q, b, c), e2 = orient3d(p, q, c, a);
    if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0)) return true;
  }
  return false;
}

}  // namespace

// Answers equal brute force; on a skewed query distribution (most segments near one spot
// of the bunny) the self-organizing tree tests fewer triangles per query than the
// oblivious one, after building only part of it.
TEST(DeferredBsp, ExactAndAdaptive) {
  const Triangles bunny = from_tri_mesh(test::data_mesh("bunny.ply"));
  DeferredBsp lazy(bunny, 4, 8), oblivious(bunny, 0, 8);
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0, 1);
  const Vec3d hot{-1.5, 8.0, 0.5};  // near the ears
  int hits = 0;
  const int n = 3000;
  DeferredStats half_a, half_b;  // after the first half: the second half is the steady state
  for (int i = 0; i < n; ++i) {
    if (i == n / 2) half_a = lazy.stats(), half_b = oblivious.stats();
    const bool skewed = u(rng) < 0.9;
    const Vec3d c = skewed ? hot + Vec3d(0.6 * g(rng), 0.6 * g(rng), 0.6 * g(rng)) : Vec3d(5 * g(rng), 5 + 4 * g(rng), 4 * g(rng));
    const Vec3d d = Vec3d(g(rng), g(rng), g(rng)).normalized() * (skewed ? 0.8 : 2.0);
    const bool got = lazy.intersects(c - d, c + d);
    if (i < 400) {
      EXPECT_EQ(got, brute(bunny, c - d, c + d));
    }
    EXPECT_EQ(oblivious.intersects(c - d, c + d), got);
    hits += got;
  }
  EXPECT_GT(hits, n / 10);
  const auto& a = lazy.stats();
  const auto& b = oblivious.stats();
  EXPECT_LT(a.nodes, b.nodes);  // deferred: only the queried part is built
  auto per_query = [](const DeferredStats& end, const DeferredStats& start) {
    return double(end.triangle_tests - start.triangle_tests + end.node_visits - start.node_visits) /
           double(end.queries - start.queries);
  };
  const double per_query_lazy = per_query(a, half_a), per_query_obl = per_query(b, half_b);
  std::printf("second half: deferred %zu nodes, %.1f tests+visits per query; oblivious %zu nodes, %.1f per query\n", a.nodes,
              per_query_lazy, b.nodes, per_query_obl);
  EXPECT_LT(per_query_lazy, per_query_obl);
}
