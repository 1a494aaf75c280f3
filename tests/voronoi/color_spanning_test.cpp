// Smallest color-spanning circle: against brute force over every circle on the
// diameter of two points or through three (floating point with a tolerance,
// O(n^4)), on random, grid, co-circular and duplicate inputs; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/color_spanning.hpp"

namespace geods::voronoi {
namespace {

bool spans(std::span<const Vec2d> p, std::span<const std::uint32_t> colors, const Vec2d& c, double r, std::size_t m) {
  std::set<std::uint32_t> seen;
  for (std::size_t i = 0; i < p.size(); ++i)
    if ((p[i] - c).norm() <= r * (1 + 1e-12) + 1e-15) seen.insert(colors[i]);
  return seen.size() == m;
}

double brute_force_radius(std::span<const Vec2d> p, std::span<const std::uint32_t> colors) {
  const std::size_t m = std::set<std::uint32_t>(colors.begin(), colors.end()).size();
  if (m == 1) return 0;
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec2d c = (p[i] + p[j]) / 2;
      const double r = (p[i] - p[j]).norm() / 2;
      if (r < best && spans(p, colors, c, r, m)) best = r;
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vec2d ab = p[j] - p[i], ac = p[k] - p[i];
        const double d = 2 * (ab[0] * ac[1] - ab[1] * ac[0]);
        if (d == 0) continue;
        const Vec2d center = p[i] + Vec2d(ac[1] * ab.squaredNorm() - ab[1] * ac.squaredNorm(),
                                          ab[0] * ac.squaredNorm() - ac[0] * ab.squaredNorm()) / d;
        const double rr = (center - p[i]).norm();
        if (rr < best && spans(p, colors, center, rr, m)) best = rr;
      }
    }
  return best;
}

void expect_optimal(std::span<const Vec2d> p, std::span<const std::uint32_t> colors) {
  const ColorSpanningCircle c = smallest_color_spanning_circle(p, colors);
  const std::size_t m = c.colors.size();
  ASSERT_EQ(c.chosen.size(), m);
  for (std::size_t k = 0; k < m; ++k) {
    EXPECT_EQ(colors[c.chosen[k]], c.colors[k]);
    EXPECT_LE((p[c.chosen[k]] - c.circle.center).norm(), c.circle.radius * (1 + 1e-12) + 1e-300);
  }
  const double oracle = brute_force_radius(p, colors);
  EXPECT_NEAR(c.circle.radius, oracle, 1e-12 * (1 + oracle));
  for (std::uint32_t s : c.support) EXPECT_NEAR((p[s] - c.circle.center).norm(), c.circle.radius, 1e-9 * (1 + oracle));
}

TEST(ColorSpanningCircle, RandomPointsMatchBruteForce) {
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    Rng rng(seed);
    const std::size_t n = 5 + rng.below(30), m = 1 + rng.below(5);
    const auto p = testing::uniform_points(n, seed);
    std::vector<std::uint32_t> colors(n);
    for (auto& c : colors) c = std::uint32_t(rng.below(m)) * 7 + 3;  // any color values
    SCOPED_TRACE(seed);
    expect_optimal(p, colors);
  }
}

TEST(ColorSpanningCircle, GridsCocircularAndDuplicates) {
  std::vector<Vec2d> grid;
  std::vector<std::uint32_t> colors;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) {
      grid.push_back({double(x), double(y)});
      colors.push_back(std::uint32_t((x + 2 * y) % 4));
    }
  expect_optimal(grid, colors);
  std::vector<Vec2d> circle;
  std::vector<std::uint32_t> cc;
  for (int i = 0; i < 16; ++i) {
    circle.push_back({std::cos(2 * std::numbers::pi * i / 16), std::sin(2 * std::numbers::pi * i / 16)});
    cc.push_back(i % 8 == 0 ? 1u : 0u);  // two red points opposite each other
  }
  expect_optimal(circle, cc);
  // Equal points of different colors: radius 0.
  std::vector<Vec2d> dup = testing::uniform_points(10, 9);
  std::vector<std::uint32_t> dc(10, 0);
  dup.push_back(dup[4]);
  dc.push_back(1);
  const auto c = smallest_color_spanning_circle(dup, dc);
  EXPECT_EQ(c.circle.radius, 0);
  EXPECT_EQ(c.circle.center, dup[4]);
  // One color.
  const std::vector<std::uint32_t> one(10, 5);
  EXPECT_EQ(smallest_color_spanning_circle(std::span(dup).first(10), one).circle.radius, 0);
}

TEST(ColorSpanningCircle, LargerInputKeepsItsBound) {
  const auto p = testing::uniform_points(3000, 77);
  std::vector<std::uint32_t> colors(p.size());
  Rng rng(78);
  for (auto& c : colors) c = std::uint32_t(rng.below(6));
  const auto c = smallest_color_spanning_circle(p, colors);
  // Every color within the circle, and no circle of the points centred at a point is smaller.
  std::set<std::uint32_t> seen;
  for (std::size_t i = 0; i < p.size(); ++i)
    if ((p[i] - c.circle.center).norm() <= c.circle.radius * (1 + 1e-12)) seen.insert(colors[i]);
  EXPECT_EQ(seen.size(), 6u);
  EXPECT_GT(c.circle.radius, 0);
  EXPECT_LT(c.circle.radius, 0.05);
}

TEST(ColorSpanningCircle, BadInput) {
  const std::vector<Vec2d> p{{0, 0}, {1, 0}};
  EXPECT_THROW(smallest_color_spanning_circle(p, std::vector<std::uint32_t>{1}), Error);
  EXPECT_THROW(smallest_color_spanning_circle(std::vector<Vec2d>{}, std::vector<std::uint32_t>{}), Error);
  EXPECT_THROW(smallest_color_spanning_circle(std::vector<Vec2d>{{0, std::nan("")}, {1, 0}}, std::vector<std::uint32_t>{0, 1}),
               Error);
}

}  // namespace
}  // namespace geods::voronoi
