// Voronoi2: the dual structure against brute force (cells hold exactly the
// points nearest to their site) on random, co-circular, collinear and
// duplicated sites; clipping; bad input.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <cmath>

#include "../../src/voronoi/exact_compare.hpp"
#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {
namespace {

using testing::brute_delaunay;
using testing::grid_delaunay;
using testing::nearest_squared_distance;
using testing::uniform_points;

// Every sampled point of the box lies in the clipped cell of a nearest site, and
// the clipped cells tile the box.
void expect_cells_match_brute_force(const Voronoi2& v, const AABB2d& box, std::uint64_t seed) {
  const std::vector<std::vector<Vec2d>> cells = v.cell_polygons(box);
  const std::vector<Vec2d> points(v.points().begin(), v.points().end());
  double area = 0;
  for (std::uint32_t i = 0; i < cells.size(); ++i)
    if (v.representative(i) == i) area += polygon_area(cells[i]);
  const double box_area = (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]);
  EXPECT_NEAR(area, box_area, 1e-9 * box_area);
  Rng rng(seed);
  for (int s = 0; s < 500; ++s) {
    const Vec2d q(rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1]));
    const double best = nearest_squared_distance(points, q);
    int containing = 0;
    for (std::uint32_t i = 0; i < cells.size(); ++i) {
      if (v.representative(i) != i || !point_in_polygon(q, cells[i])) continue;
      ++containing;
      EXPECT_NEAR((points[i] - q).squaredNorm(), best, 1e-9 * (1 + best)) << "sample " << q.transpose();
    }
    EXPECT_GE(containing, 1) << "sample " << q.transpose() << " is in no cell";
  }
}

TEST(Voronoi2, RandomSitesAgainstBruteForce) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto t = brute_delaunay(uniform_points(40, seed));
    const Voronoi2 v = t.voronoi();
    v.validate();
    const Voronoi2Stats s = v.stats();
    EXPECT_EQ(s.vertices, t.triangles.size() / 3);  // no co-circular sites
    std::size_t hull = 0;
    for (std::uint32_t h : t.halfedges) hull += h == Voronoi2::kNoEdge;
    EXPECT_EQ(s.edges, (t.triangles.size() + hull) / 2);
    EXPECT_EQ(s.unbounded_cells, hull);
    // Euler: V - E + F = 1 with the unbounded edges ending at one vertex at infinity (V + 1 - E + n = 2).
    EXPECT_EQ(long(s.vertices) + 1 - long(s.edges) + long(s.distinct), 2);
    expect_cells_match_brute_force(v, v.default_box(), seed);
    expect_cells_match_brute_force(v, AABB2d({0.3, 0.2}, {0.6, 0.9}), seed + 10);
  }
}

TEST(Voronoi2, CellsAreCounterClockwiseAndContainTheirSites) {
  const auto t = brute_delaunay(uniform_points(30, 7));
  const Voronoi2 v = t.voronoi();
  const AABB2d box = v.default_box();
  for (std::uint32_t i = 0; i < v.size(); ++i) {
    const auto cell = v.cell_polygon(i, box);
    EXPECT_GT(polygon_area(cell), 0);
    EXPECT_TRUE(point_in_polygon(v.points()[i], cell));
    // The half-edges of the cell go round it counter-clockwise, ending where the next one starts.
    std::uint32_t e = v.cell_edge(i);
    do {
      EXPECT_EQ(v.edges()[e].site, i);
      e = v.edges()[e].next;
    } while (e != v.cell_edge(i));
  }
}

TEST(Voronoi2, ClippedEdgesLieOnBisectorsInsideTheBox) {
  const Voronoi2 v = brute_delaunay(uniform_points(40, 8)).voronoi();
  const AABB2d box({0.2, 0.1}, {0.7, 0.8});
  std::size_t inside = 0;
  for (std::uint32_t e = 0; e < v.edges().size(); ++e) {
    const auto segment = v.clipped_edge(e, box);
    const auto twin = v.clipped_edge(v.edges()[e].twin, box);
    ASSERT_EQ(segment.has_value(), twin.has_value());
    if (!segment) continue;
    ++inside;
    EXPECT_EQ(segment->first, twin->second);
    for (const Vec2d& x : {segment->first, segment->second}) {
      EXPECT_TRUE(box.contains(x + (x - (box.lo + box.hi) / 2) * -1e-12));
      EXPECT_NEAR((x - v.points()[v.edges()[e].site]).norm(), (x - v.points()[v.opposite_site(e)]).norm(), 1e-12);
    }
    // Going along the edge, its site is on the left.
    const Vec2d d = segment->second - segment->first, s = v.points()[v.edges()[e].site] - segment->first;
    EXPECT_GT(d[0] * s[1] - d[1] * s[0], 0);
  }
  EXPECT_GT(inside, 20u);
  EXPECT_FALSE(v.clipped_edge(0, AABB2d({5, 5}, {6, 6})).has_value());
}

TEST(Voronoi2, CoCircularGridMergesCircumcentres) {
  const auto t = grid_delaunay(6);
  const Voronoi2 v = t.voronoi();
  v.validate();
  // One vertex per square (its centre), each of degree 4; no zero-length edges.
  ASSERT_EQ(v.vertices().size(), 25u);
  for (const Vec2d& c : v.vertices()) {
    EXPECT_EQ(c[0] - std::floor(c[0]), 0.5);
    EXPECT_EQ(c[1] - std::floor(c[1]), 0.5);
  }
  std::vector<int> degree(v.vertices().size(), 0);
  for (const auto& e : v.edges())
    if (e.origin != Voronoi2::kInfinity) ++degree[e.origin];
  for (int d : degree) EXPECT_EQ(d, 4);
  EXPECT_EQ(v.stats().edges, 2u * 5 * 4 + 4u * 5);  // 40 inner segments + 20 rays
  // The diagonal neighbours meet only at a vertex but stay Delaunay neighbours.
  EXPECT_EQ(v.neighbors(0).size(), 3u);
  expect_cells_match_brute_force(v, AABB2d({-1.3, -0.7}, {6.1, 5.4}), 5);
}

TEST(Voronoi2, CollinearSitesHaveParallelLines) {
  std::vector<Vec2d> p = {{0, 0}, {3, 1.5}, {1, 0.5}, {2, 1}, {1, 0.5}, {-2, -1}};
  const auto t = brute_delaunay(p);
  ASSERT_TRUE(t.triangles.empty());
  const Voronoi2 v = t.voronoi();
  v.validate();
  EXPECT_TRUE(v.vertices().empty());
  EXPECT_EQ(v.stats().edges, 4u);
  EXPECT_EQ(v.stats().unbounded_cells, 5u);
  EXPECT_EQ(v.representative(4), 2u);
  for (const auto& e : v.edges()) {
    EXPECT_EQ(e.origin, Voronoi2::kInfinity);
    EXPECT_EQ(e.target, Voronoi2::kInfinity);
    EXPECT_NEAR(std::abs(v.direction(std::uint32_t(&e - v.edges().data())).dot(Vec2d(2, 1).normalized())), 0, 1e-12);
  }
  expect_cells_match_brute_force(v, AABB2d({-3, -2}, {4, 3}), 9);
  // Horizontal sites give vertical lines.
  const auto h = brute_delaunay({{0, 1}, {2, 1}, {5, 1}});
  expect_cells_match_brute_force(h.voronoi(), AABB2d({-1, -1}, {6, 3}), 10);
}

// The circumcentre of nearly flat triangles (a corner 1e-9 off the line of the other
// two, two corners 1e-12 apart; at scales 1 and 1e12) against rational arithmetic:
// within 2^-38 of its offset from a and of a. (The rounded formula alone was off
// by up to 1e-5 of the distance.)
TEST(Voronoi2, CircumcentresOfNearlyFlatTrianglesAreAccurate) {
  Rng rng(41);
  for (int i = 0; i < 3000; ++i) {
    const double scale = i % 2 ? 1 : 1e12;
    Vec2d a(rng.uniform(-1, 1), rng.uniform(-1, 1)), b(rng.uniform(-1, 1), rng.uniform(-1, 1)), c;
    if (i % 3 == 0) {
      c = a + 1e-12 * Vec2d(rng.uniform(-1, 1), rng.uniform(-1, 1));
    } else {
      const double t = rng.uniform(-2, 2);
      c = a + t * (b - a) + 1e-9 * Vec2d(rng.uniform(-1, 1), rng.uniform(-1, 1));
    }
    a *= scale, b *= scale, c *= scale;
    if (orient2d(a, b, c) == 0) continue;
    const mpq_class ax(a[0]), ay(a[1]), bx = mpq_class(b[0]) - ax, by = mpq_class(b[1]) - ay;
    const mpq_class cx = mpq_class(c[0]) - ax, cy = mpq_class(c[1]) - ay;
    const mpq_class d = 2 * (bx * cy - by * cx), b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    const mpq_class ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
    const Vec2d got = detail::circumcentre(a, b, c);
    const double error = std::max(std::abs(mpq_class(mpq_class(got[0]) - ax - ux).get_d()),
                                  std::abs(mpq_class(mpq_class(got[1]) - ay - uy).get_d()));
    const double size = std::max(std::abs(ux.get_d()), std::abs(uy.get_d())) + a.cwiseAbs().maxCoeff();
    EXPECT_LE(error, std::ldexp(size, -38)) << i << ": " << a.transpose() << " / " << b.transpose() << " / "
                                            << c.transpose();
  }
}

// Sites on a line with a few 1e-10 off it, and lattice sites moved by 1e-12: the
// vertices of their nearly flat triangles are equidistant from their sites
// (validate() threw here before the circumcentre above).
TEST(Voronoi2, NearlyCollinearAndNearlyCoincidentSites) {
  Rng rng(43);
  std::vector<Vec2d> line, lattice;
  for (int i = 0; i < 400; ++i) {
    const double x = std::floor(rng.uniform(0, 21));
    line.push_back({x, 2 * x + 1 + (i % 5 == 0 ? rng.uniform(-1e-10, 1e-10) : 0.0)});
    lattice.push_back({std::floor(rng.uniform(0, 21)) + rng.uniform(-1e-12, 1e-12),
                       std::floor(rng.uniform(0, 21)) + rng.uniform(-1e-12, 1e-12)});
  }
  Voronoi2(line).validate();
  Voronoi2(lattice).validate();
}

// Nearly co-circular lattice sites 1e-3 apart in a unit box: some hull
// triangles are nearly flat, their circumcentres 1e10 away. The clipped
// cells tile the box (clipped as polygons reaching that far, neighbours
// disagreed on their shared edge's exit and left a gap of 1.8e-7); and sites
// an ulp apart at 2e7 pass validate() (their rounded midpoint fell on one of
// them, which read as a site not left of its edge).
TEST(Voronoi2, CellsOfNearlyCoCircularSitesTileTheBox) {
  for (const double at : {0.0, 2e7})
    for (const double spacing : {1e-3, 1e-9})
      for (std::uint64_t seed = 1; seed < 400; seed += 7) {
        SCOPED_TRACE("at " + std::to_string(at) + " spacing " + std::to_string(spacing) + " seed " + std::to_string(seed));
        std::vector<Vec2d> sites = testing::lattice_subset(seed, true);
        for (Vec2d& p : sites) p = Vec2d(at + 0.5 + spacing * p[0], 0.5 + spacing * p[1]);
        const Voronoi2 v(sites);
        v.validate();
        const AABB2d box({at, 0}, {at + 1, 1});
        double area = 0;
        for (std::uint32_t i = 0; i < sites.size(); ++i)
          if (v.representative(i) == i) area += polygon_area(v.cell_polygon(i, box));
        EXPECT_NEAR(area, 1.0, 1e-12);
      }
}

// polygon_area sums a fan about the first corner: a unit square 1e15 from the origin
// has area 1 (about the origin its products cancelled it away).
TEST(Voronoi2, PolygonAreaFarFromTheOrigin) {
  const std::vector<Vec2d> square = {{1e15, 1e15}, {1e15 + 1, 1e15}, {1e15 + 1, 1e15 + 1}, {1e15, 1e15 + 1}};
  EXPECT_EQ(polygon_area(square), 1.0);
  EXPECT_EQ(polygon_area(std::vector<Vec2d>(square.rbegin(), square.rend())), -1.0);
  EXPECT_EQ(polygon_area({}), 0.0);
}

TEST(Voronoi2, DuplicatesShareTheCellOfTheirFirstOccurrence) {
  std::vector<Vec2d> p = uniform_points(25, 11);
  p.push_back(p[3]);
  p.push_back(p[7]);
  p.push_back(p[3]);
  const auto t = brute_delaunay(p);
  const Voronoi2 v = t.voronoi();
  v.validate();
  EXPECT_EQ(v.representative(25), 3u);
  EXPECT_EQ(v.representative(27), 3u);
  EXPECT_EQ(v.cell_edge(27), v.cell_edge(3));
  const AABB2d box = v.default_box();
  EXPECT_EQ(v.cell_polygon(26, box), v.cell_polygon(7, box));
  EXPECT_EQ(v.stats().distinct, 25u);
  expect_cells_match_brute_force(v, box, 12);
}

TEST(Voronoi2, OneOrTwoSites) {
  const auto one = brute_delaunay({{1, 2}, {1, 2}});
  const Voronoi2 v1 = one.voronoi();
  v1.validate();
  EXPECT_EQ(v1.cell_edge(1), Voronoi2::kNoEdge);
  EXPECT_NEAR(polygon_area(v1.cell_polygon(0, AABB2d({0, 0}, {3, 4}))), 12, 1e-12);
  const auto two = brute_delaunay({{0, 0}, {1, 1}});
  const Voronoi2 v2 = two.voronoi();
  v2.validate();
  expect_cells_match_brute_force(v2, AABB2d({-2, -1}, {2, 3}), 13);
}

TEST(Voronoi2, BadInput) {
  const std::vector<Vec2d> p = {{0, 0}, {1, 0}, {0, 1}};
  const std::vector<std::uint32_t> rep = {0, 1, 2}, tri = {0, 1, 2}, he = {Voronoi2::kNoEdge, Voronoi2::kNoEdge, Voronoi2::kNoEdge};
  EXPECT_THROW(Voronoi2({}, {}, {}, {}), Error);
  EXPECT_THROW(Voronoi2(p, tri, he, std::vector<std::uint32_t>{0, 1}), Error);
  EXPECT_THROW(Voronoi2(p, std::vector<std::uint32_t>{0, 1}, std::vector<std::uint32_t>{0, 1}, rep), Error);
  EXPECT_THROW(Voronoi2(p, std::vector<std::uint32_t>{0, 1, 5}, he, rep), Error);
  EXPECT_THROW(Voronoi2(p, tri, std::vector<std::uint32_t>{1, 1, Voronoi2::kNoEdge}, rep), Error);
  const std::vector<Vec2d> nan = {{0, 0}, {std::nan(""), 0}};
  EXPECT_THROW(Voronoi2(nan, {}, {}, std::vector<std::uint32_t>{0, 1}), Error);
  const Voronoi2 v(p, tri, he, rep);
  v.validate();
  EXPECT_THROW(v.cell_polygon(0, AABB2d()), Error);
}

}  // namespace
}  // namespace geods::voronoi
