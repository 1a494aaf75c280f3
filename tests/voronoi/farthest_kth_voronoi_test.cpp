// Farthest-point and k-th order Voronoi diagrams: sampled points lie in the cell
// of a farthest site / the region of their k nearest sites (brute force), the
// cells tile the box; k = 1 is the Voronoi diagram; degenerate inputs
// (co-circular, grids, duplicates, collinear); bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/farthest_voronoi.hpp"
#include "geods/voronoi/kth_order_voronoi.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {
namespace {

using testing::uniform_points;

double box_area(const AABB2d& b) { return (b.hi[0] - b.lo[0]) * (b.hi[1] - b.lo[1]); }

void expect_farthest_matches_brute_force(const FarthestVoronoi& v, std::uint64_t seed, int samples = 600) {
  v.validate();
  double area = 0;
  for (std::uint32_t i = 0; i < v.points().size(); ++i)
    if (v.representative(i) == i && !v.cells()[i].empty()) area += polygon_area(v.cells()[i]);
  EXPECT_NEAR(area, box_area(v.box()), 1e-7 * box_area(v.box()));
  Rng rng(seed);
  for (int s = 0; s < samples; ++s) {
    const Vec2d q(rng.uniform(v.box().lo[0], v.box().hi[0]), rng.uniform(v.box().lo[1], v.box().hi[1]));
    double best = 0;
    for (const Vec2d& p : v.points()) best = std::max(best, (q - p).norm());
    int containing = 0;
    for (std::uint32_t i = 0; i < v.points().size(); ++i) {
      if (v.representative(i) != i || v.cells()[i].empty() || !point_in_polygon(q, v.cells()[i])) continue;
      ++containing;
      EXPECT_NEAR((q - v.points()[i]).norm(), best, 1e-9 * (1 + best));
    }
    EXPECT_GE(containing, 1) << q.transpose();
  }
}

// Samples drawn from `window` (the box if empty); distances compared to 1e-9
// of its side (and the rounding of the coordinates).
void expect_kth_matches_brute_force(const KthOrderVoronoi& v, std::uint64_t seed, int samples = 500,
                                    AABB2d window = AABB2d()) {
  v.validate();
  if (window.empty()) window = v.box();
  const double scale = std::max(window.hi[0] - window.lo[0], window.hi[1] - window.lo[1]);
  double area = 0;
  for (const auto& r : v.regions()) area += polygon_area(r.polygon);
  EXPECT_NEAR(area, box_area(v.box()), 1e-7 * box_area(v.box())) << "k = " << v.k();
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < v.points().size(); ++i)
    if (v.representative(i) == i) sites.push_back(i);
  Rng rng(seed);
  int checked = 0;
  for (int s = 0; s < samples; ++s) {
    const Vec2d q(rng.uniform(window.lo[0], window.hi[0]), rng.uniform(window.lo[1], window.hi[1]));
    std::vector<std::pair<double, std::uint32_t>> by_distance;
    for (std::uint32_t i : sites) by_distance.push_back({(q - v.points()[i]).norm(), i});
    std::sort(by_distance.begin(), by_distance.end());
    const std::size_t k = v.k();
    // On a boundary, to the rounding of the coordinates:
    const double tie = 1e-9 * scale + 64 * std::numeric_limits<double>::epsilon() * q.cwiseAbs().maxCoeff();
    if (k < by_distance.size() && by_distance[k].first - by_distance[k - 1].first < tie) continue;
    std::vector<std::uint32_t> nearest;
    for (std::size_t j = 0; j < k; ++j) nearest.push_back(by_distance[j].second);
    std::sort(nearest.begin(), nearest.end());
    int containing = 0;
    for (const auto& r : v.regions()) {
      if (!point_in_polygon(q, r.polygon)) continue;
      ++containing;
      EXPECT_EQ(r.sites, nearest) << "sample " << q.transpose();
    }
    EXPECT_GE(containing, 1) << q.transpose();
    ++checked;
  }
  EXPECT_GT(checked, samples / 2);
}

TEST(FarthestVoronoi, RandomPointsMatchBruteForce) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto p = uniform_points(100 + 50 * seed, seed);
    const FarthestVoronoi v(p, frame_around(p, 1.0));
    expect_farthest_matches_brute_force(v, seed);
    for (std::uint32_t i = 0; i < p.size(); ++i)
      if (!v.cells()[i].empty()) {  // only corners have cells (a corner's cell may miss the box)
        EXPECT_NE(std::find(v.corners().begin(), v.corners().end(), i), v.corners().end());
      }
  }
}

TEST(FarthestVoronoi, CocircularGridDuplicatesCollinear) {
  std::vector<Vec2d> circle;
  for (int i = 0; i < 24; ++i) circle.push_back({std::cos(2 * std::numbers::pi * i / 24), std::sin(2 * std::numbers::pi * i / 24)});
  circle.push_back(circle[3]);
  circle.push_back({0, 0});
  const FarthestVoronoi c(circle, frame_around(circle));
  expect_farthest_matches_brute_force(c, 2);
  EXPECT_EQ(c.corners().size(), 24u);
  EXPECT_EQ(c.cells()[24], c.cells()[3]);
  EXPECT_TRUE(c.cells()[25].empty());

  std::vector<Vec2d> grid;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 6; ++x) grid.push_back({double(x), double(y)});
  const FarthestVoronoi g(grid, frame_around(grid));
  expect_farthest_matches_brute_force(g, 3);
  EXPECT_EQ(g.corners().size(), 4u);  // points on the hull's sides are no corners

  const std::vector<Vec2d> line{{0, 0}, {1, 1}, {3, 3}, {2, 2}};
  const FarthestVoronoi l(line, frame_around(line));
  expect_farthest_matches_brute_force(l, 4);
  EXPECT_EQ(l.corners().size(), 2u);

  const std::vector<Vec2d> one{{1, 1}, {1, 1}};
  const FarthestVoronoi o(one, AABB2d(Vec2d(0, 0), Vec2d(2, 2)));
  EXPECT_NEAR(polygon_area(o.cells()[0]), 4, 1e-12);
}

// Sites on a grid 1e15 from the origin (coordinates exact, corners rounded to 1/8):
// validate() allows the corners their own rounding, and the cells still tile the box.
TEST(FarthestVoronoi, FarFromTheOrigin) {
  std::vector<Vec2d> grid;
  for (int i = 0; i < 60; ++i) grid.push_back({1e15 + double(i % 9), 1e15 + 0.5 * double((i * 7) % 13)});
  const AABB2d box = frame_around(grid);
  const FarthestVoronoi v(grid, box);
  v.validate();
  double area = 0;
  for (const auto& cell : v.cells()) area += polygon_area(cell);
  const double box_area = (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]);
  EXPECT_NEAR(area, box_area, 1e-3 * box_area);
}

TEST(KthOrderVoronoi, FirstOrderIsTheVoronoiDiagram) {
  const auto p = uniform_points(80, 7);
  const AABB2d box = frame_around(p);
  const KthOrderVoronoi v(p, 1, box);
  const Voronoi2 vd(p);
  ASSERT_EQ(v.regions().size(), p.size());
  for (const auto& r : v.regions()) EXPECT_NEAR(polygon_area(r.polygon), polygon_area(vd.cell_polygon(r.sites[0], box)), 1e-12);
}

TEST(KthOrderVoronoi, RandomPointsMatchBruteForce) {
  for (std::size_t k = 1; k <= 4; ++k)
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
      const auto p = uniform_points(60, 10 * k + seed);
      const KthOrderVoronoi v(p, k, frame_around(p));
      expect_kth_matches_brute_force(v, seed);
    }
}

TEST(KthOrderVoronoi, ACornerOfTwoPiecesIsOneCorner) {
  // Two pieces of a region compute a corner they share each in its own
  // rounding. Merged within 1e-12 of the region's extent, 24 such pairs of
  // these 120 diagrams were rounded further apart than that and stayed as
  // edges of 1e-12 to 3e-11 of the extent; real edges here are above 7e-6.
  int diagrams = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed)
    for (std::size_t k = 2; k <= 4; ++k) {
      const auto p = uniform_points(60, seed);
      const KthOrderVoronoi v(p, k, frame_around(p));
      v.validate();
      for (const auto& r : v.regions()) {
        double extent = 0;
        for (const Vec2d& c : r.polygon) extent = std::max(extent, (c - r.polygon[0]).cwiseAbs().maxCoeff());
        for (std::size_t i = 0; i < r.polygon.size(); ++i)
          EXPECT_GT((r.polygon[(i + 1) % r.polygon.size()] - r.polygon[i]).cwiseAbs().maxCoeff(), 1e-10 * extent)
              << "seed " << seed << " k " << k;
      }
      ++diagrams;
    }
  EXPECT_EQ(diagrams, 120);
}

TEST(KthOrderVoronoi, DegenerateInputs) {
  std::vector<Vec2d> grid;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) grid.push_back({double(x), double(y)});
  grid.push_back(grid[7]);  // a duplicate
  for (std::size_t k : {2u, 3u}) expect_kth_matches_brute_force(KthOrderVoronoi(grid, k, frame_around(grid)), k);

  std::vector<Vec2d> circle;
  for (int i = 0; i < 12; ++i) circle.push_back({std::cos(2 * std::numbers::pi * i / 12), std::sin(2 * std::numbers::pi * i / 12)});
  expect_kth_matches_brute_force(KthOrderVoronoi(circle, 2, frame_around(circle)), 5);
  // The farthest-point diagram is the order n - 1 diagram.
  const KthOrderVoronoi last(circle, 11, frame_around(circle));
  expect_kth_matches_brute_force(last, 6);
  EXPECT_EQ(last.regions().size(), 12u);

  const std::vector<Vec2d> line{{0, 0}, {1, 0}, {2.5, 0}, {4, 0}, {4.5, 0}};
  expect_kth_matches_brute_force(KthOrderVoronoi(line, 2, frame_around(line)), 7);
  const KthOrderVoronoi all(line, 5, frame_around(line));
  ASSERT_EQ(all.regions().size(), 1u);
  EXPECT_NEAR(polygon_area(all.regions()[0].polygon), box_area(all.box()), 1e-9);
}

TEST(KthOrderVoronoi, SitesFarCloserThanTheBox) {
  // Nearly co-circular lattice sites 1e-7 and 1e-9 of a unit box apart:
  // regions under 1e-14 of the box's area were dropped as slivers, so that
  // 53 and 57 of 60 such subsets had points in no region near the sites.
  // At 1e-11 and 1e-12, regions lost corners merged within 1e-12 of the box.
  for (const double spacing : {1e-7, 1e-9, 1e-11, 1e-12})
    for (std::uint64_t seed = 1; seed < 200; seed += 14) {
      SCOPED_TRACE("spacing " + std::to_string(spacing) + " seed " + std::to_string(seed));
      std::vector<Vec2d> sites = testing::lattice_subset(seed, true);
      for (Vec2d& p : sites) p = Vec2d(0.5, 0.5) + spacing * p;
      const AABB2d near_sites(Vec2d(0.5, 0.5) - Vec2d(3, 3) * spacing, Vec2d(0.5, 0.5) + Vec2d(9, 9) * spacing);
      const KthOrderVoronoi v(sites, 2, AABB2d(Vec2d(0, 0), Vec2d(1, 1)));
      expect_kth_matches_brute_force(v, seed, 200, near_sites);
    }
}

TEST(KthOrderVoronoi, ThinStripsFarFromTheOrigin) {
  // Sites on the line x = 1e6 + 0.5, 1e-12 apart: the regions are strips
  // 1e-12 high. They were dropped as slivers (the rounding of x = 1e6 taken
  // for y's) and their corners merged (within 1e-12 of the box), leaving two
  // regions of half the box each.
  const double x = 1e6 + 0.5;
  std::vector<Vec2d> sites;
  for (double y : {3.01, 0.0, 5.01, 5.02, 3.02, 2.0, 2.01, 2.01, 2.02, 5.0, 1.0}) sites.push_back({x, 0.5 + 1e-12 * y});
  const AABB2d box(Vec2d(1e6, 0), Vec2d(1e6 + 1, 1));
  for (std::size_t k : {2u, 3u}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    const KthOrderVoronoi v(sites, k, box);
    v.validate();
    EXPECT_EQ(v.regions().size(), 10u - k + 1);  // 10 distinct sites in a row
    double area = 0;
    for (const auto& r : v.regions()) area += polygon_area(r.polygon);
    EXPECT_NEAR(area, 1.0, 1e-9);
    // The sites share x, so a point's nearest are those nearest in y (exact
    // differences of y near 0.5; x's rounding at 1e6 does not enter).
    Rng rng(k);
    for (int i = 0; i < 300; ++i) {
      const Vec2d q(rng.uniform(1e6, 1e6 + 1), 0.5 + 1e-12 * rng.uniform(-3, 9));
      std::vector<std::pair<double, std::uint32_t>> by_distance;
      for (std::uint32_t j = 0; j < sites.size(); ++j)
        if (v.representative(j) == j) by_distance.push_back({std::abs(q[1] - sites[j][1]), j});
      std::sort(by_distance.begin(), by_distance.end());
      if (by_distance[k].first - by_distance[k - 1].first < 1e-15) continue;  // on a boundary
      std::vector<std::uint32_t> nearest;
      for (std::size_t j = 0; j < k; ++j) nearest.push_back(by_distance[j].second);
      std::sort(nearest.begin(), nearest.end());
      int containing = 0;
      for (const auto& r : v.regions())
        if (point_in_polygon(q, r.polygon)) {
          ++containing;
          EXPECT_EQ(r.sites, nearest) << "sample " << q.transpose();
        }
      EXPECT_EQ(containing, 1) << q.transpose();
    }
  }
}

TEST(KthOrderVoronoi, BadInput) {
  const std::vector<Vec2d> p{{0, 0}, {1, 0}, {0, 1}, {0, 1}};
  const AABB2d box(Vec2d(-1, -1), Vec2d(2, 2));
  EXPECT_THROW(KthOrderVoronoi(p, 0, box), Error);
  EXPECT_THROW(KthOrderVoronoi(p, 4, box), Error);  // 3 distinct points
  EXPECT_THROW(KthOrderVoronoi(std::vector<Vec2d>{}, 1, box), Error);
  EXPECT_THROW(KthOrderVoronoi(std::vector<Vec2d>{{0, std::nan("")}}, 1, box), Error);
  EXPECT_THROW(KthOrderVoronoi(p, 1, AABB2d()), Error);
  EXPECT_THROW(FarthestVoronoi(std::vector<Vec2d>{{std::nan(""), 0}}, box), Error);
  EXPECT_THROW(FarthestVoronoi(std::vector<Vec2d>{}, box), Error);
}

}  // namespace
}  // namespace geods::voronoi
