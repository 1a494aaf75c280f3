// Nearest-site queries (slab structure, walking) against brute force with exact
// distance comparisons, on random, co-circular grid, collinear and duplicated sites.
#include <gtest/gtest.h>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/voronoi/post_office.hpp"

namespace geods::voronoi {
namespace {

using testing::brute_delaunay;
using testing::grid_delaunay;
using testing::uniform_points;

// Queries: random ones, the sites themselves, the Voronoi vertices (equidistant
// from three or more sites), midpoints of site pairs, far away ones.
std::vector<Vec2d> queries_for(const Voronoi2& v, std::uint64_t seed) {
  Rng rng(seed);
  const AABB2d box = v.default_box(1.0);
  std::vector<Vec2d> q;
  for (int i = 0; i < 400; ++i) q.push_back({rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1])});
  for (const Vec2d& p : v.points()) q.push_back(p);
  for (const Vec2d& c : v.vertices()) q.push_back(c);
  for (std::size_t i = 0; i + 1 < v.size(); ++i) q.push_back((v.points()[i] + v.points()[i + 1]) / 2);
  q.push_back({1e6, -3e5});
  q.push_back({-1e6, 1e6});
  return q;
}

// The answer is a representative whose distance ties the smallest (compared in long double
// on coordinates that are exact in it for these inputs), never a point farther away.
void expect_nearest(const Voronoi2& v, const Vec2d& q, std::uint32_t answer) {
  ASSERT_LT(answer, v.size());
  EXPECT_EQ(v.representative(answer), answer);
  const auto d2 = [&](const Vec2d& p) {
    const long double dx = (long double)p[0] - q[0], dy = (long double)p[1] - q[1];
    return dx * dx + dy * dy;
  };
  long double best = d2(v.points()[0]);
  for (const Vec2d& p : v.points()) best = std::min(best, d2(p));
  EXPECT_LE(d2(v.points()[answer]), best * (1 + 1e-15L)) << "query " << q.transpose() << " answer " << answer;
}

void check_locators(const Voronoi2& v, std::uint64_t seed) {
  const SlabLocator slab(v);
  slab.validate();
  const WalkLocator walk(v);
  const std::vector<Vec2d> queries = queries_for(v, seed);
  const auto slab_batch = slab.nearest_batch(queries);
  const auto walk_batch = walk.nearest_batch(queries);
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const Vec2d& q = queries[i];
    expect_nearest(v, q, slab.nearest(q));
    expect_nearest(v, q, walk.nearest(q));
    expect_nearest(v, q, walk.nearest(q, std::uint32_t(i % v.size())));
    expect_nearest(v, q, slab_batch[i]);
    expect_nearest(v, q, walk_batch[i]);
  }
}

TEST(PostOffice, RandomSites) {
  for (std::uint64_t seed : {1, 2}) check_locators(brute_delaunay(uniform_points(50, seed)).voronoi(), seed);
}

TEST(PostOffice, SlabSearchAloneFindsTheCellAwayFromEdges) {
  const Voronoi2 v = brute_delaunay(uniform_points(40, 3)).voronoi();
  const SlabLocator slab(v);
  const SlabLocatorStats s = slab.stats();
  EXPECT_EQ(s.slabs, v.vertices().size() + 1);
  EXPECT_GT(s.crossings, 0u);
  Rng rng(4);
  for (int i = 0; i < 1000; ++i) {
    const Vec2d q(rng.uniform(-0.5, 1.5), rng.uniform(-0.5, 1.5));
    const std::uint32_t cell = slab.locate(q);
    // Any other site is farther by a margin, unless q is within rounding of an edge.
    for (std::uint32_t j = 0; j < v.size(); ++j)
      EXPECT_LE((v.points()[cell] - q).squaredNorm(), (v.points()[j] - q).squaredNorm() + 1e-12);
  }
}

TEST(PostOffice, CoCircularGridWithTies) {
  const Voronoi2 v = grid_delaunay(7).voronoi();
  check_locators(v, 5);
  // Integer and half-integer queries: exact ties between 2 and 4 sites.
  const SlabLocator slab(v);
  const WalkLocator walk(v);
  for (int x = -2; x <= 16; ++x)
    for (int y = -2; y <= 16; ++y) {
      const Vec2d q(x / 2.0, y / 2.0);
      expect_nearest(v, q, slab.nearest(q));
      expect_nearest(v, q, walk.nearest(q));
    }
}

TEST(PostOffice, CollinearAndDuplicatedSites) {
  check_locators(brute_delaunay({{0, 0}, {3, 1.5}, {1, 0.5}, {2, 1}, {1, 0.5}, {-2, -1}}).voronoi(), 6);
  check_locators(brute_delaunay({{0, 1}, {2, 1}, {5, 1}, {2, 1}}).voronoi(), 7);   // horizontal
  check_locators(brute_delaunay({{4, 0}, {4, 2}, {4, -5}}).voronoi(), 8);          // vertical
  check_locators(brute_delaunay({{4, 0}, {4, 0}}).voronoi(), 9);                   // one site
  std::vector<Vec2d> p = uniform_points(30, 10);
  p.insert(p.end(), {p[0], p[5], p[5]});
  check_locators(brute_delaunay(p).voronoi(), 11);
}

// Sites on a lattice, many nearly coincident (moved by 1e-12): Voronoi vertices computed
// twice a rounding apart cut slabs of a few ulps, and rounding at a slab's middle reorders
// edges that go on from the slab before (it is sorted again then). validate() used to
// throw here: the cells on either side of such slivers agree only up to that rounding.
TEST(PostOffice, NearlyCoincidentLatticeSites) {
  Rng rng(31);
  std::vector<Vec2d> p;
  for (int i = 0; i < 2000; ++i)
    p.push_back({std::floor(rng.uniform(0, 41)) + rng.uniform(-1e-12, 1e-12),
                 std::floor(rng.uniform(0, 41)) + rng.uniform(-1e-12, 1e-12)});
  check_locators(Voronoi2(p), 32);
}

// The slabs are derived in runs of 1024, in parallel: the same structure, so the same
// answers, on any number of threads.
TEST(PostOffice, SlabsTheSameOnAnyNumberOfThreads) {
  std::vector<Vec2d> p = uniform_points(6000, 21);
  for (int i = 0; i < 2000; ++i) p.push_back(p[std::size_t(i)] * 1e-3 + Vec2d(0.5, 0.5));  // a dense cluster
  const Voronoi2 v(p);
  Rng rng(22);
  std::vector<Vec2d> queries;
  for (int i = 0; i < 20000; ++i) queries.push_back({rng.uniform(-0.2, 1.2), rng.uniform(-0.2, 1.2)});
  for (int i = 0; i < 2000; ++i) queries.push_back(Vec2d(0.5, 0.5) + 1e-3 * Vec2d(rng.uniform(), rng.uniform()));
  for (const Vec2d& c : v.vertices()) queries.push_back(c);
  set_num_threads(1);
  const SlabLocator one(v);
  one.validate();
  std::vector<std::uint32_t> want;
  for (const Vec2d& q : queries) want.push_back(one.locate(q));
  for (int threads : {2, 3, 5}) {
    set_num_threads(threads);
    const SlabLocator many(v);
    many.validate();
    EXPECT_EQ(many.stats().slabs, one.stats().slabs);
    EXPECT_EQ(many.stats().crossings, one.stats().crossings);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) differ += many.locate(queries[i]) != want[i];
    EXPECT_EQ(differ, 0u) << threads << " threads";
  }
  set_num_threads(0);
  for (std::size_t i = 0; i < queries.size(); i += 97) expect_nearest(v, queries[i], one.nearest(queries[i]));
}

TEST(PostOffice, BadQueries) {
  const Voronoi2 v = brute_delaunay(uniform_points(10, 12)).voronoi();
  const SlabLocator slab(v);
  const WalkLocator walk(v);
  EXPECT_THROW(slab.nearest({std::nan(""), 0}), Error);
  EXPECT_THROW(walk.nearest({0, std::numeric_limits<double>::infinity()}), Error);
  EXPECT_THROW(walk.nearest({0, 0}, 10), Error);
}

}  // namespace
}  // namespace geods::voronoi
