// The 3D proximity applications (closest pair, all nearest neighbours, EMST)
// from Delaunay3 against brute force over all pairs (Prim's algorithm for the tree).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/proximity.hpp"

namespace geods::voronoi {
namespace {

std::vector<Vec3d> sample(int kind, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3d> p;
  if (kind == 0)  // uniform, with duplicates
    for (int i = 0; i < 300; ++i) p.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  if (kind == 1)  // integer lattice: ties everywhere
    for (int i = 0; i < 125; ++i) p.emplace_back(i % 5, (i / 5) % 5, i / 25);
  if (kind == 2)  // coplanar: no tetrahedra
    for (int i = 0; i < 60; ++i) p.emplace_back(rng.uniform(), rng.uniform(), 0.5);
  if (kind == 0) p.push_back(p[17]);
  return p;
}

double brute_mst(const std::vector<Vec3d>& p) {
  const std::size_t n = p.size();
  std::vector<double> best(n, std::numeric_limits<double>::infinity());
  std::vector<bool> in(n, false);
  best[0] = 0;
  double total = 0;
  for (std::size_t step = 0; step < n; ++step) {
    std::size_t u = n;
    for (std::size_t v = 0; v < n; ++v)
      if (!in[v] && (u == n || best[v] < best[u])) u = v;
    in[u] = true;
    total += best[u];
    for (std::size_t v = 0; v < n; ++v)
      if (!in[v]) best[v] = std::min(best[v], (p[u] - p[v]).norm());
  }
  return total;
}

TEST(Proximity3, AgreesWithBruteForce) {
  for (int kind : {0, 1, 2}) {
    SCOPED_TRACE("kind " + std::to_string(kind));
    const std::vector<Vec3d> p = sample(kind, 7);
    const Delaunay3 dt(p);
    // closest pair
    double closest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p.size(); ++i)
      for (std::size_t j = i + 1; j < p.size(); ++j) closest = std::min(closest, (p[i] - p[j]).norm());
    const ClosestPair pair = closest_pair(dt);
    EXPECT_LT(pair.i, pair.j);
    EXPECT_EQ(pair.distance, closest);
    EXPECT_EQ((p[pair.i] - p[pair.j]).norm(), closest);
    // all nearest neighbours: at the brute-force nearest distance
    const std::vector<std::uint32_t> nn = all_nearest_neighbors(dt);
    ASSERT_EQ(nn.size(), p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < p.size(); ++j)
        if (j != i) best = std::min(best, (p[i] - p[j]).squaredNorm());
      ASSERT_NE(nn[i], i);
      EXPECT_EQ((p[i] - p[nn[i]]).squaredNorm(), best) << "point " << i;
    }
    // EMST: n - 1 edges, a tree of the brute-force (Prim) length
    const SpanningTree tree = emst(dt);
    EXPECT_EQ(tree.edges.size(), p.size() - 1);
    EXPECT_NEAR(tree.length, brute_mst(p), 1e-9 * brute_mst(p));
  }
  EXPECT_THROW(closest_pair(std::vector<Vec3d>{{1, 2, 3}}), Error);
}


// The distances along the exact Delaunay graph are squared in double: scaled
// copies inside that range give the same answers scaled exactly, and 1e300 or
// 1e-300 are refused (they used to give the pair (0, 0) at distance 0).
TEST(Proximity3, ExtremeScalesAreExactOrRefused) {
  const std::vector<Vec3d> unit = sample(0, 41);
  const ClosestPair pair = closest_pair(unit);
  const auto nn = all_nearest_neighbors(unit);
  const SpanningTree tree = emst(unit);
  for (int e : {-440, 480}) {
    std::vector<Vec3d> p = unit;
    for (Vec3d& x : p) x = Vec3d(std::ldexp(x[0], e), std::ldexp(x[1], e), std::ldexp(x[2], e));
    const ClosestPair got = closest_pair(p);
    EXPECT_EQ(std::pair(got.i, got.j), std::pair(pair.i, pair.j)) << e;
    EXPECT_EQ(got.distance, std::ldexp(pair.distance, e)) << e;
    EXPECT_EQ(all_nearest_neighbors(p), nn) << e;
    EXPECT_EQ(emst(p).edges, tree.edges) << e;
  }
  for (double s : {1e300, 1e-300}) {
    std::vector<Vec3d> p = unit;
    for (Vec3d& x : p) x *= s;
    EXPECT_THROW(closest_pair(p), Error) << s;
    EXPECT_THROW(all_nearest_neighbors(p), Error) << s;
    EXPECT_THROW(emst(p), Error) << s;
  }
}

}  // namespace
}  // namespace geods::voronoi
