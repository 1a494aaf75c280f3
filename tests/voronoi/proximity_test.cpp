// Applications of the Voronoi diagram against brute force: closest pair, all
// nearest neighbours, EMST (Prim on the complete graph), k nearest sites,
// largest empty circle, smallest enclosing circle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/circles.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/proximity.hpp"

namespace geods::voronoi {
namespace {

using testing::brute_delaunay;
using testing::grid_delaunay;
using testing::Triangulation;
using testing::prim_mst_length;
using testing::uniform_points;

std::vector<Triangulation> test_sets() {
  std::vector<Triangulation> sets;
  for (std::uint64_t seed : {1, 2, 3}) sets.push_back(brute_delaunay(uniform_points(35, seed)));
  sets.push_back(grid_delaunay(5));
  sets.push_back(brute_delaunay({{0, 0}, {3, 1.5}, {1, 0.5}, {2, 1}, {1, 0.5}, {-2, -1}}));  // collinear, duplicate
  std::vector<Vec2d> p = uniform_points(20, 4);
  p.insert(p.end(), {p[2], p[9]});
  sets.push_back(brute_delaunay(p));
  return sets;
}

double distance(const std::vector<Vec2d>& p, std::uint32_t i, std::uint32_t j) { return (p[i] - p[j]).norm(); }

TEST(Proximity, ClosestPairAndAllNearestNeighbors) {
  for (const Triangulation& t : test_sets()) {
    const Voronoi2 v = t.voronoi();
    const auto& p = t.points;
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t i = 0; i < p.size(); ++i)
      for (std::uint32_t j = i + 1; j < p.size(); ++j) best = std::min(best, distance(p, i, j));
    const ClosestPair cp = closest_pair(v);
    EXPECT_LT(cp.i, cp.j);
    EXPECT_EQ(cp.distance, best);
    EXPECT_EQ(distance(p, cp.i, cp.j), best);
    const std::vector<std::uint32_t> nn = all_nearest_neighbors(v);
    for (std::uint32_t i = 0; i < p.size(); ++i) {
      double nearest = std::numeric_limits<double>::infinity();
      for (std::uint32_t j = 0; j < p.size(); ++j)
        if (j != i) nearest = std::min(nearest, distance(p, i, j));
      EXPECT_NE(nn[i], i);
      EXPECT_EQ(distance(p, i, nn[i]), nearest) << "point " << i;
    }
  }
}

TEST(Proximity, EmstAgainstPrim) {
  for (const Triangulation& t : test_sets()) {
    const auto& p = t.points;
    const SpanningTree tree = emst(t.voronoi());
    ASSERT_EQ(tree.edges.size(), p.size() - 1);
    // A spanning tree: n - 1 edges joining everything.
    std::vector<std::uint32_t> parent(p.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x];
      return x;
    };
    for (const auto& [i, j] : tree.edges) {
      EXPECT_LT(i, j);
      ASSERT_NE(root(i), root(j));
      parent[root(i)] = root(j);
    }
    // Its length equals Prim's on the complete graph.
    const double prim = prim_mst_length(p);
    EXPECT_NEAR(tree.length, prim, 1e-12 * (1 + prim));
  }
}

TEST(Proximity, KNearestSites) {
  for (const Triangulation& t : test_sets()) {
    const Voronoi2 v = t.voronoi();
    const WalkLocator locator(v);
    std::vector<std::uint32_t> sites;
    for (std::uint32_t i = 0; i < v.size(); ++i)
      if (v.representative(i) == i) sites.push_back(i);
    Rng rng(9);
    for (int s = 0; s < 50; ++s) {
      const Vec2d q(rng.uniform(-1, 4), rng.uniform(-1, 4));
      for (std::size_t k : {1, 3, 8, 100}) {
        const auto got = k_nearest_sites(locator, q, k);
        std::vector<std::uint32_t> expected = sites;
        std::sort(expected.begin(), expected.end(), [&](std::uint32_t a, std::uint32_t b) {
          return std::pair((t.points[a] - q).squaredNorm(), a) < std::pair((t.points[b] - q).squaredNorm(), b);
        });
        expected.resize(std::min(k, expected.size()));
        ASSERT_EQ(got.size(), expected.size());
        for (std::size_t r = 0; r < got.size(); ++r)
          EXPECT_EQ((t.points[got[r]] - q).squaredNorm(), (t.points[expected[r]] - q).squaredNorm());
      }
    }
  }
}

// Brute force: the centres worth trying are circumcentres of site triples inside
// the hull and crossings of pair bisectors with hull edges; the radius of a
// centre is its distance to the nearest site.
double brute_largest_empty_radius(const std::vector<Vec2d>& p, const std::vector<std::uint32_t>& hull) {
  const auto radius = [&](const Vec2d& c) {
    double r = std::numeric_limits<double>::infinity();
    for (const Vec2d& s : p) r = std::min(r, (s - c).norm());
    return r;
  };
  const auto inside = [&](const Vec2d& c) {
    for (std::size_t k = 0; k < hull.size(); ++k)
      if (orient2d(p[hull[k]], p[hull[(k + 1) % hull.size()]], c) < -1e-12) return false;
    return true;
  };
  double best = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      for (std::size_t k = j + 1; k < p.size(); ++k) {
        const Vec2d a = p[i], b = p[j], c = p[k];
        const double d = 2 * ((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0]);
        if (d == 0) continue;
        const Vec2d ab = b - a, ac = c - a;
        const Vec2d center = a + Vec2d(ac[1] * ab.squaredNorm() - ab[1] * ac.squaredNorm(),
                                       ab[0] * ac.squaredNorm() - ac[0] * ab.squaredNorm()) / d;
        if (inside(center)) best = std::max(best, radius(center));
      }
      for (std::size_t h = 0; h < hull.size(); ++h) {
        const Vec2d a = p[hull[h]], b = p[hull[(h + 1) % hull.size()]];
        const Vec2d dir = b - a, n = p[j] - p[i];
        if (dir.dot(n) == 0) continue;
        const double t = ((p[i] + p[j]) / 2 - a).dot(n) / dir.dot(n);
        if (t >= 0 && t <= 1) best = std::max(best, radius(a + t * dir));
      }
    }
  return best;
}

TEST(Circles, LargestEmptyCircleAgainstBruteForce) {
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    const auto t = brute_delaunay(uniform_points(30, seed));
    const Voronoi2 v = t.voronoi();
    // The hull from the brute-force triangulation's boundary edges, counter-clockwise.
    std::vector<std::uint32_t> next(t.points.size(), Voronoi2::kNoEdge);
    std::uint32_t start = 0;
    for (std::uint32_t e = 0; e < t.triangles.size(); ++e)
      if (t.halfedges[e] == Voronoi2::kNoEdge) next[start = t.triangles[e]] = t.triangles[e % 3 == 2 ? e - 2 : e + 1];
    std::vector<std::uint32_t> hull;
    for (std::uint32_t s = start; hull.empty() || s != start; s = next[s]) hull.push_back(s);
    const Circle c = largest_empty_circle(v);
    EXPECT_NEAR(c.radius, brute_largest_empty_radius(t.points, hull), 1e-9);
    for (const Vec2d& p : t.points) EXPECT_GE((p - c.center).norm(), c.radius * (1 - 1e-9));
    for (std::size_t k = 0; k < hull.size(); ++k)
      EXPECT_GE(orient2d(t.points[hull[k]], t.points[hull[(k + 1) % hull.size()]], c.center), -1e-12);
  }
}

TEST(Circles, LargestEmptyCircleDegenerate) {
  // Collinear: half the largest gap, centred between its sites.
  const Circle line = largest_empty_circle(brute_delaunay({{0, 0}, {3, 1.5}, {1, 0.5}, {2, 1}, {-2, -1}}).voronoi());
  EXPECT_NEAR(line.radius, std::sqrt(5.0) / 2, 1e-12);  // the gap from (-2, -1) to (0, 0)
  EXPECT_NEAR((line.center - Vec2d(-1, -0.5)).norm(), 0, 1e-12);
  // The grid: the centre of a square.
  const Circle grid = largest_empty_circle(grid_delaunay(4).voronoi());
  EXPECT_NEAR(grid.radius, std::sqrt(0.5), 1e-12);
  const Circle one = largest_empty_circle(brute_delaunay({{2, 3}, {2, 3}}).voronoi());
  EXPECT_EQ(one.radius, 0);
}

// The smallest circle through 2 or 3 of the points that holds them all.
double brute_enclosing_radius(const std::vector<Vec2d>& p) {
  const auto covers = [&](const Vec2d& c, double r) {
    for (const Vec2d& s : p)
      if ((s - c).norm() > r * (1 + 1e-12) + 1e-15) return false;
    return true;
  };
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i; j < p.size(); ++j) {
      const Vec2d c = (p[i] + p[j]) / 2;
      if (const double r = (p[i] - c).norm(); r < best && covers(c, r)) best = r;
      for (std::size_t k = j + 1; k < p.size(); ++k) {
        const Vec2d a = p[i], ab = p[j] - a, ac = p[k] - a;
        const double d = 2 * (ab[0] * ac[1] - ab[1] * ac[0]);
        if (d == 0) continue;
        const Vec2d center = a + Vec2d(ac[1] * ab.squaredNorm() - ab[1] * ac.squaredNorm(),
                                       ab[0] * ac.squaredNorm() - ac[0] * ab.squaredNorm()) / d;
        if (const double r = (a - center).norm(); r < best && covers(center, r)) best = r;
      }
    }
  return best;
}

TEST(Circles, SmallestEnclosingCircleAgainstBruteForce) {
  std::vector<std::vector<Vec2d>> sets;
  for (std::uint64_t seed : {1, 2, 3, 4, 5}) sets.push_back(uniform_points(25, seed, -3, 5));
  sets.push_back({{0, 0}, {1, 0}, {0, 1}, {1, 1}, {0.5, 0.5}});            // co-circular square
  sets.push_back({{0, 0}, {2, 2}, {1, 1}, {3, 3}, {3, 3}});                // collinear, duplicate
  sets.push_back({{1, 1}, {1, 1}, {1, 1}});                                // one point
  sets.push_back({{1e-80, 0}, {-1e-80, 0}, {0, 1e-80}});                   // tiny (1e-300: refused)
  std::vector<Vec2d> circle;
  for (int k = 0; k < 16; ++k) circle.push_back({std::cos(k * M_PI / 8) * 1e8, std::sin(k * M_PI / 8) * 1e8});
  sets.push_back(circle);
  for (const auto& p : sets) {
    for (std::uint64_t seed : {0, 1}) {
      const Circle c = smallest_enclosing_circle(p, seed);
      for (const Vec2d& s : p) EXPECT_LE((s - c.center).norm(), c.radius);
      EXPECT_NEAR(c.radius, brute_enclosing_radius(p), 1e-9 * (1 + c.radius));
    }
  }
  EXPECT_THROW(smallest_enclosing_circle(std::vector<Vec2d>{}), Error);
  EXPECT_THROW(smallest_enclosing_circle(std::vector<Vec2d>{{0, 0}, {std::nan(""), 1}}), Error);
}

TEST(Proximity, TooFewPoints) {
  const Voronoi2 v = brute_delaunay({{1, 1}}).voronoi();
  EXPECT_THROW(closest_pair(v), Error);
  EXPECT_THROW(all_nearest_neighbors(v), Error);
  EXPECT_TRUE(emst(v).edges.empty());
}


// Every application is invariant under scaling by a power of two, which is
// exact in floating point: inside the range where their cubic circumcentres
// and squared distances stay finite and normal, scaled copies give the same
// answers scaled exactly; beyond it they refuse (at 1e300 they used to answer
// (0, 0, 0) and infinite radii with exit 0).
TEST(Applications, ExtremeScalesAreExactOrRefused) {
  const std::vector<Vec2d> unit = uniform_points(60, 11);
  auto scaled = [&](int e) {
    std::vector<Vec2d> p = unit;
    for (Vec2d& x : p) x = Vec2d(std::ldexp(x[0], e), std::ldexp(x[1], e));
    return p;
  };
  const ClosestPair pair = closest_pair(unit);
  const auto nn = all_nearest_neighbors(unit);
  const SpanningTree tree = emst(unit);
  const Circle enclosing = smallest_enclosing_circle(unit), empty = largest_empty_circle(unit);
  for (int e : {-280, -100, 100, 330}) {
    const std::vector<Vec2d> p = scaled(e);
    const ClosestPair got = closest_pair(p);
    EXPECT_EQ(std::pair(got.i, got.j), std::pair(pair.i, pair.j)) << e;
    EXPECT_EQ(got.distance, std::ldexp(pair.distance, e)) << e;
    EXPECT_EQ(all_nearest_neighbors(p), nn) << e;
    const SpanningTree t = emst(p);
    EXPECT_EQ(t.edges, tree.edges) << e;
    EXPECT_DOUBLE_EQ(t.length, std::ldexp(tree.length, e)) << e;
    for (const auto& [want, got_circle] : {std::pair(enclosing, smallest_enclosing_circle(p)),
                                           std::pair(empty, largest_empty_circle(p))}) {
      EXPECT_EQ(got_circle.radius, std::ldexp(want.radius, e)) << e;
      EXPECT_EQ(got_circle.center, Vec2d(std::ldexp(want.center[0], e), std::ldexp(want.center[1], e))) << e;
    }
    const Voronoi2 diagram(p);
    diagram.validate();
    const WalkLocator walk(diagram);
    const SlabLocator slabs(diagram);
    for (std::size_t i = 0; i < unit.size(); ++i) {
      const Vec2d q = 0.5 * (p[i] + p[(i + 7) % p.size()]);
      std::uint32_t best = 0;
      for (std::uint32_t j = 1; j < p.size(); ++j)
        if ((p[j] - q).squaredNorm() < (p[best] - q).squaredNorm()) best = j;
      EXPECT_EQ((p[walk.nearest(q)] - q).squaredNorm(), (p[best] - q).squaredNorm()) << e;
      EXPECT_EQ((p[slabs.nearest(q)] - q).squaredNorm(), (p[best] - q).squaredNorm()) << e;
    }
    EXPECT_THROW(walk.nearest(Vec2d(1e200, 0)), Error);
    EXPECT_THROW(slabs.nearest(Vec2d(0, -1e200)), Error);
  }
  for (double s : {1e300, 1e-300, 1e101, 1e-90}) {
    std::vector<Vec2d> p = unit;
    for (Vec2d& x : p) x *= s;
    EXPECT_THROW(closest_pair(p), Error) << s;
    EXPECT_THROW(all_nearest_neighbors(p), Error) << s;
    EXPECT_THROW(emst(p), Error) << s;
    EXPECT_THROW(smallest_enclosing_circle(p), Error) << s;
    EXPECT_THROW(largest_empty_circle(p), Error) << s;
    EXPECT_THROW(Voronoi2{p}, Error) << s;
  }
}

}  // namespace
}  // namespace geods::voronoi
