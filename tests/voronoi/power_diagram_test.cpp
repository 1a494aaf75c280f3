// Regular triangulation and power diagram: every triangle empty of points
// below its lifted plane (exact power test, brute force over all points),
// sampled points in the cell of the least power (brute force), cells tiling the
// box; equal weights give the Delaunay triangulation; degenerate inputs
// (grids, duplicates with different weights, collinear sets, redundant points); bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/power_diagram.hpp"

namespace geods::voronoi {
namespace {

using testing::uniform_points;

// The lifted triangles are the lower hull: no point (site or not) strictly
// below a triangle's plane, and every point missing from the triangulation is
// redundant by the same test against the triangle that holds it.
void expect_regular(const RegularTriangulation& rt) {
  rt.validate();
  const auto& t = rt.triangles();
  const auto p = rt.points();
  const auto w = rt.weights();
  for (std::size_t k = 0; k < t.size(); k += 3)
    for (std::uint32_t q = 0; q < p.size(); ++q)
      ASSERT_LE(power_test(p[t[k]], w[t[k]], p[t[k + 1]], w[t[k + 1]], p[t[k + 2]], w[t[k + 2]], p[q], w[q]), 0)
          << "point " << q << " lies below triangle " << k / 3;
  std::vector<char> is_vertex(p.size(), 0);
  for (std::uint32_t v : t) is_vertex[v] = 1;
  for (std::uint32_t q = 0; q < p.size(); ++q)
    if (!rt.degenerate() && !is_vertex[q]) { EXPECT_TRUE(rt.is_redundant(q) || rt.representative(q) != q) << q; }
}

// Each sample lies in the cell of a site of least power; the cells' areas add up to the box.
void expect_cells_match_brute_force(const PowerDiagram& d, std::uint64_t seed, int samples = 800) {
  d.validate();
  const AABB2d& box = d.box();
  double area = 0;
  for (std::uint32_t i = 0; i < d.cells().size(); ++i)
    if (d.triangulation().representative(i) == i && !d.cells()[i].empty()) area += polygon_area(d.cells()[i]);
  const double box_area = (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]);
  EXPECT_NEAR(area, box_area, 1e-7 * box_area);
  Rng rng(seed);
  int outside = 0;
  for (int s = 0; s < samples; ++s) {
    const Vec2d q(rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1]));
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t i = 0; i < d.points().size(); ++i) best = std::min(best, power_distance(q, d.points()[i], d.weights()[i]));
    int containing = 0;
    for (std::uint32_t i = 0; i < d.cells().size(); ++i) {
      if (d.triangulation().representative(i) != i || d.cells()[i].empty() || !point_in_polygon(q, d.cells()[i])) continue;
      ++containing;
      const double scale = 1 + std::abs(best) + (box.hi - box.lo).squaredNorm();
      EXPECT_NEAR(power_distance(q, d.points()[i], d.weights()[i]), best, 1e-9 * scale) << "sample in cell " << i;
    }
    outside += containing == 0;
  }
  EXPECT_EQ(outside, 0);
}

std::vector<double> random_weights(std::size_t n, std::uint64_t seed, double scale) {
  Rng rng(seed);
  std::vector<double> w(n);
  for (double& x : w) x = rng.uniform(0, scale);
  return w;
}

TEST(PowerDiagram, RandomWeightedPointsMatchBruteForce) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const auto p = uniform_points(150, seed);
    const auto w = random_weights(p.size(), seed + 100, seed % 2 ? 0.01 : 0.05);
    const PowerDiagram d(p, w, frame_around(p));
    expect_regular(d.triangulation());
    expect_cells_match_brute_force(d, seed);
    EXPECT_GT(d.triangulation().stats().vertices, 10u);
  }
}

// Weighted sites on a grid 1e15 from the origin (coordinates exact, corners rounded
// to 1/8): validate() allows the corners their own rounding, and the cells tile the box.
TEST(PowerDiagram, FarFromTheOrigin) {
  std::vector<Vec2d> grid;
  for (int i = 0; i < 200; ++i) grid.push_back({1e15 + double(i % 17), 1e15 + 0.5 * double((i * 7) % 23)});
  const PowerDiagram d(grid, random_weights(grid.size(), 12, 0.01), frame_around(grid));
  d.validate();
  double area = 0;
  for (std::uint32_t i = 0; i < d.cells().size(); ++i)
    if (d.triangulation().representative(i) == i) area += polygon_area(d.cells()[i]);
  const AABB2d& box = d.box();
  const double box_area = (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]);
  EXPECT_NEAR(area, box_area, 1e-3 * box_area);
}

TEST(PowerDiagram, HeavyWeightsMakeRedundantPoints) {
  const auto p = uniform_points(200, 7);
  const auto w = random_weights(p.size(), 8, 0.2);  // big circles swallow small ones
  const PowerDiagram d(p, w, frame_around(p));
  expect_regular(d.triangulation());
  expect_cells_match_brute_force(d, 9);
  const auto red = d.triangulation().redundant();
  EXPECT_GT(red.size(), 20u);
  EXPECT_GT(d.triangulation().stats().removals, 0u);  // some were removed after insertion (3-1 flips)
  for (std::uint32_t r : red) EXPECT_TRUE(d.cells()[r].empty());
}

TEST(PowerDiagram, EqualWeightsGiveTheDelaunayTriangulation) {
  const auto p = uniform_points(300, 11);
  const std::vector<double> w(p.size(), 0.7);
  const RegularTriangulation rt(p, w);
  const Delaunay2 dt(p);
  EXPECT_EQ(rt.triangle_count(), dt.triangle_count());  // general position: the same triangles
  for (std::size_t k = 0; k < rt.triangles().size(); k += 3) {
    const auto& t = rt.triangles();
    for (const Vec2d& q : p) ASSERT_LE(incircle(p[t[k]], p[t[k + 1]], p[t[k + 2]], q), 0);
  }
  EXPECT_TRUE(rt.redundant().empty());
  const PowerDiagram d(rt, frame_around(p));
  const Voronoi2 v(p);
  for (std::uint32_t i = 0; i < p.size(); ++i)
    EXPECT_NEAR(polygon_area(d.cells()[i]), polygon_area(v.cell_polygon(i, d.box())), 1e-9);
}

TEST(PowerDiagram, GridsWithEqualAndIntegerWeights) {
  std::vector<Vec2d> p;
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) p.push_back({double(x), double(y)});
  {
    const std::vector<double> w(p.size(), 0.0);  // co-circular everywhere
    const PowerDiagram d(p, w, frame_around(p));
    expect_regular(d.triangulation());
    expect_cells_match_brute_force(d, 3);
    EXPECT_EQ(d.triangulation().triangle_count(), 2u * 8 * 8);
  }
  Rng rng(5);
  std::vector<double> w(p.size());
  for (double& x : w) x = double(rng.below(3)) * 0.25;  // many exact ties of the power test
  const PowerDiagram d(p, w, frame_around(p));
  expect_regular(d.triangulation());
  expect_cells_match_brute_force(d, 4);
}

TEST(PowerDiagram, EqualPointsKeepTheHeaviest) {
  auto p = uniform_points(60, 21);
  auto w = random_weights(p.size(), 22, 0.001);
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < 20; ++i) {
    p.push_back(p[i]);
    w.push_back(i % 2 ? w[i] + 0.0005 : w[i]);  // heavier copy or an equal duplicate
  }
  const PowerDiagram d(p, w, frame_around(p));
  const auto& rt = d.triangulation();
  expect_regular(rt);
  expect_cells_match_brute_force(d, 23);
  for (std::size_t i = 0; i < 20; ++i) {
    if (i % 2) {
      EXPECT_TRUE(rt.is_redundant(std::uint32_t(i))) << i;  // the lighter original
      EXPECT_EQ(rt.representative(std::uint32_t(n + i)), n + i);
    } else {
      EXPECT_EQ(rt.representative(std::uint32_t(n + i)), i);  // an equal duplicate shares the cell
      EXPECT_EQ(d.cells()[n + i], d.cells()[i]);
    }
  }
  EXPECT_EQ(rt.stats().duplicates, 10u);
}

TEST(PowerDiagram, CollinearPointsGiveStrips) {
  std::vector<Vec2d> p;
  std::vector<double> w;
  for (int i = 0; i < 12; ++i) {
    p.push_back({0.5 * i, 0.25 * i});
    w.push_back(i == 5 ? -0.5 : (i % 3) * 0.05);  // point 5 is far above its neighbours: redundant
  }
  const PowerDiagram d(p, w, frame_around(p));
  const auto& rt = d.triangulation();
  EXPECT_TRUE(rt.degenerate());
  EXPECT_TRUE(rt.is_redundant(5));
  EXPECT_FALSE(rt.is_redundant(0));
  EXPECT_FALSE(rt.is_redundant(11));
  expect_cells_match_brute_force(d, 31);
}

TEST(PowerDiagram, CollinearHullPointsAndAHeavyInteriorPoint) {
  // Points on the sides of a square, and a heavy centre that swallows the inner ones.
  std::vector<Vec2d> p;
  std::vector<double> w;
  for (int i = 0; i <= 6; ++i)
    for (const Vec2d& q : {Vec2d(i, 0), Vec2d(6, i), Vec2d(6 - i, 6), Vec2d(0, 6 - i)}) {
      p.push_back(q);
      w.push_back(i % 2 ? -1.0 : 0.0);
    }
  p.push_back({3, 3});
  w.push_back(8.0);
  for (int k = 0; k < 10; ++k) {
    p.push_back({2.5 + 0.1 * k, 3.2});
    w.push_back(0);
  }
  const PowerDiagram d(p, w, frame_around(p));
  expect_regular(d.triangulation());
  expect_cells_match_brute_force(d, 41);
  EXPECT_TRUE(d.triangulation().is_redundant(std::uint32_t(p.size() - 1)));
}

TEST(PowerDiagram, PowerTestIsExactNearDegeneracy) {
  // Four co-circular points with weights nudged by one ulp either way.
  const Vec2d a(1, 0), b(0, 1), c(-1, 0), d(0, -1);
  EXPECT_EQ(power_test(a, 0, b, 0, c, 0, d, 0), 0);
  EXPECT_EQ(power_test(a, 0, b, 0, c, 0, d, 0x1p-60), 1);
  EXPECT_EQ(power_test(a, 0, b, 0, c, 0, d, -0x1p-60), -1);
  EXPECT_EQ(power_test(b, 0, a, 0, c, 0, d, 0x1p-60), -1);  // clockwise flips the sign
  // Huge and tiny magnitudes together (the big-integer path).
  EXPECT_EQ(power_test(Vec2d(1e100, 0), 1e-200, Vec2d(0, 1e100), 1e-200, Vec2d(-1e100, 0), 1e-200, Vec2d(0, -1e100),
                       2e-200),
            1);
  EXPECT_EQ(collinear_power_test(Vec2d(0, 0), 0, Vec2d(1, 0), 0, Vec2d(2, 0), 0), 1);
  EXPECT_EQ(collinear_power_test(Vec2d(0, 0), 0, Vec2d(1, 0), -1, Vec2d(2, 0), 0), 0);
  EXPECT_EQ(collinear_power_test(Vec2d(0, 0), 0, Vec2d(1, 0), -1.5, Vec2d(2, 0), 0), -1);
}

// Against 128-bit integer arithmetic on small integers, scaled by powers of two
// (which keep the sign) into the filter's, the expansions' and the big integers' ranges.
TEST(PowerDiagram, PowerTestMatchesIntegerArithmetic) {
  Rng rng(99);
  int zeros = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    std::int64_t x[4], y[4], w[4];
    for (int k = 0; k < 4; ++k) x[k] = std::int64_t(rng.below(9)) - 4, y[k] = std::int64_t(rng.below(9)) - 4, w[k] = std::int64_t(rng.below(21)) - 10;
    __int128 lift[3], m[3];
    const auto dx = [&](int k) { return __int128(x[k] - x[3]); };
    const auto dy = [&](int k) { return __int128(y[k] - y[3]); };
    for (int k = 0; k < 3; ++k) lift[k] = dx(k) * dx(k) + dy(k) * dy(k) - (w[k] - w[3]);
    m[0] = dx(1) * dy(2) - dx(2) * dy(1), m[1] = dx(2) * dy(0) - dx(0) * dy(2), m[2] = dx(0) * dy(1) - dx(1) * dy(0);
    const __int128 det = lift[0] * m[0] + lift[1] * m[1] + lift[2] * m[2];
    const int expected = (det > 0) - (det < 0);
    zeros += expected == 0;
    for (const int e : {0, -40, 300}) {
      Vec2d p[4];
      double wt[4];
      for (int k = 0; k < 4; ++k) p[k] = {std::ldexp(double(x[k]), e), std::ldexp(double(y[k]), e)}, wt[k] = std::ldexp(double(w[k]), 2 * e);
      ASSERT_EQ(power_test(p[0], wt[0], p[1], wt[1], p[2], wt[2], p[3], wt[3]), expected) << trial << " scaled by 2^" << e;
    }
  }
  EXPECT_GT(zeros, 20);  // ties are exercised
}

TEST(PowerDiagram, BadInput) {
  const std::vector<Vec2d> p{{0, 0}, {1, 0}, {0, 1}};
  EXPECT_THROW(RegularTriangulation(p, std::vector<double>{1, 2}), Error);
  EXPECT_THROW(RegularTriangulation(std::vector<Vec2d>{}, std::vector<double>{}), Error);
  EXPECT_THROW(RegularTriangulation(p, std::vector<double>{0, std::nan(""), 0}), Error);
  EXPECT_THROW(RegularTriangulation(std::vector<Vec2d>{{0, std::nan("")}, {1, 0}, {0, 1}}, std::vector<double>{0, 0, 0}), Error);
  EXPECT_THROW(RegularTriangulation(std::vector<Vec2d>{{1e300, 0}, {1, 0}, {0, 1}}, std::vector<double>{0, 0, 0}), Error);
  EXPECT_THROW(PowerDiagram(p, std::vector<double>{0, 0, 0}, AABB2d()), Error);
  const RegularTriangulation one(std::vector<Vec2d>{{2, 3}}, std::vector<double>{1});
  EXPECT_EQ(one.stats().vertices, 1u);
  const PowerDiagram single(std::vector<Vec2d>{{2, 3}}, std::vector<double>{1}, AABB2d(Vec2d(0, 0), Vec2d(4, 4)));
  EXPECT_NEAR(polygon_area(single.cells()[0]), 16, 1e-12);
}

}  // namespace
}  // namespace geods::voronoi
namespace geods::voronoi {
TEST(PowerDiagram, ManySeedsOfRandomPointsGridsAndLinesAreLowerHulls) {
  for (std::uint64_t seed = 1; seed <= 120; ++seed) {
    Rng rng(seed);
    std::vector<Vec2d> p;
    std::vector<double> w;
    const int n = 20 + int(rng.below(200));
    const bool grid = seed % 3 == 0;
    for (int i = 0; i < n; ++i) {
      if (seed % 5 == 1) p.push_back({double(rng.below(12)), double(rng.below(2)) * (i < 3 ? 1 : 0)});
      else if (grid) p.push_back({double(rng.below(8)), double(rng.below(8))});
      else p.push_back({rng.uniform(0, 1), rng.uniform(0, 1)});
      w.push_back(grid || seed % 5 == 1 ? double(rng.below(4)) * 0.5 : rng.uniform(0, seed % 2 ? 0.3 : 0.01));
    }
    const RegularTriangulation rt(p, w, seed);
    ASSERT_NO_THROW(rt.validate()) << seed;
    const auto& t = rt.triangles();
    for (std::size_t k = 0; k < t.size(); k += 3)
      for (std::uint32_t q = 0; q < p.size(); ++q)
        ASSERT_LE(power_test(p[t[k]], w[t[k]], p[t[k + 1]], w[t[k + 1]], p[t[k + 2]], w[t[k + 2]], p[q], w[q]), 0) << seed;
  }
}
}
