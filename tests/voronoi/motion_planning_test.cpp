// Motion planning for a disc robot on the segment Voronoi diagram: the path
// keeps the clearance at every sample (exact point-segment distances), and
// whether a path exists agrees with a grid planner (free cells: centre at
// least r from every obstacle edge and the frame, outside the obstacles;
// 4-connected flood fill) for radii two cells away from the critical radius;
// the critical radius of a known scene; the reasons; bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <queue>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/motion_planning.hpp"

namespace geods::voronoi {
namespace {

using Polygons = std::vector<std::vector<Vec2d>>;

Polygons square_scene() { return {{{40, 40}, {60, 40}, {60, 60}, {40, 60}}}; }

// Random disjoint rectangles and triangles in [0, 100]^2.
Polygons random_scene(std::uint64_t seed, int count) {
  Rng rng(seed);
  Polygons out;
  std::vector<AABB2d> boxes;
  for (int tries = 0; static_cast<int>(out.size()) < count && tries < 1000; ++tries) {
    const double x = std::floor(rng.uniform(0, 90)), y = std::floor(rng.uniform(0, 90));
    const double w = std::floor(rng.uniform(3, 20)), h = std::floor(rng.uniform(3, 20));
    const AABB2d b(Vec2d(x, y), Vec2d(x + w, y + h));
    bool ok = true;
    for (const auto& o : boxes)
      ok = ok && (b.lo[0] > o.hi[0] + 2 || o.lo[0] > b.hi[0] + 2 || b.lo[1] > o.hi[1] + 2 || o.lo[1] > b.hi[1] + 2);
    if (!ok) continue;
    boxes.push_back(b);
    if (rng.uniform(0, 1) < 0.5) {
      out.push_back({{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}});
    } else {
      out.push_back({{x, y}, {x + w, y + std::floor(rng.uniform(0, h))}, {x + std::floor(rng.uniform(0, w)), y + h}});
    }
  }
  return out;
}

// Grid planner: does a 4-connected chain of free cells join the cells of start and goal?
bool grid_connected(const MotionPlanner& planner, const Vec2d& start, const Vec2d& goal, double radius, double h) {
  const AABB2d f = planner.frame();
  const int nx = static_cast<int>(std::ceil((f.hi[0] - f.lo[0]) / h)), ny = static_cast<int>(std::ceil((f.hi[1] - f.lo[1]) / h));
  auto centre = [&](int i, int j) { return Vec2d(f.lo[0] + (i + 0.5) * h, f.lo[1] + (j + 0.5) * h); };
  std::vector<char> free(static_cast<std::size_t>(nx) * ny), seen(free.size(), 0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Vec2d c = centre(i, j);
      free[static_cast<std::size_t>(j) * nx + i] = f.contains(c) && !planner.inside_obstacle(c) && planner.clearance(c) >= radius;
    }
  auto cell = [&](const Vec2d& p) {
    return std::make_pair(std::clamp(static_cast<int>((p[0] - f.lo[0]) / h), 0, nx - 1),
                          std::clamp(static_cast<int>((p[1] - f.lo[1]) / h), 0, ny - 1));
  };
  const auto [si, sj] = cell(start);
  const auto [gi, gj] = cell(goal);
  if (!free[static_cast<std::size_t>(sj) * nx + si] || !free[static_cast<std::size_t>(gj) * nx + gi]) return false;
  std::queue<std::pair<int, int>> q;
  q.push({si, sj});
  seen[static_cast<std::size_t>(sj) * nx + si] = 1;
  while (!q.empty()) {
    const auto [i, j] = q.front();
    q.pop();
    if (i == gi && j == gj) return true;
    const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int a = i + di[k], b = j + dj[k];
      if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
      const std::size_t id = static_cast<std::size_t>(b) * nx + a;
      if (!free[id] || seen[id]) continue;
      seen[id] = 1;
      q.push({a, b});
    }
  }
  return false;
}

void expect_path_valid(const MotionPlanner& planner, const PathPlan& plan, const Vec2d& start, const Vec2d& goal,
                       double radius) {
  ASSERT_TRUE(plan.found) << plan.reason;
  ASSERT_GE(plan.path.size(), 2u);
  EXPECT_EQ(plan.path.front(), start);
  EXPECT_EQ(plan.path.back(), goal);
  const double tol = 1e-9 * (planner.frame().hi - planner.frame().lo).maxCoeff();
  double polyline = 0;
  for (std::size_t k = 0; k < plan.path.size(); ++k) {
    ASSERT_GE(planner.clearance(plan.path[k]), radius - tol) << "sample " << k << " at " << plan.path[k].transpose();
    ASSERT_FALSE(planner.inside_obstacle(plan.path[k]));
    if (k > 0) polyline += (plan.path[k] - plan.path[k - 1]).norm();
  }
  EXPECT_GE(plan.min_clearance, radius - tol);
  // Chords of the arcs are a little shorter than the arcs.
  EXPECT_LE(polyline, plan.length * (1 + 1e-9) + tol);
  EXPECT_GE(polyline, plan.length * (1 - 1e-3));
  EXPECT_GE(plan.length, (goal - start).norm() - tol);
}

TEST(MotionPlanning, SquareObstacleCriticalRadius) {
  const Vec2d start(10, 50), goal(90, 50);
  // Frame: [10, 90] x [40, 60] grown by 20 on each side; the corridors above and below the square are 20 wide.
  MotionPlanner planner(square_scene(), PlanOptions{}, start, goal);
  EXPECT_NEAR(planner.max_radius(start, goal), 10, 1e-9);
  const PathPlan small = planner.plan(start, goal, 3);
  expect_path_valid(planner, small, start, goal, 3);
  // Around the square at clearance >= 3: longer than the straight line through it.
  EXPECT_GT(small.length, 80 + 1);
  const PathPlan big = planner.plan(start, goal, 10.5);
  EXPECT_FALSE(big.found);
  EXPECT_EQ(big.reason, "disconnected");
  EXPECT_NEAR(big.max_radius, 10, 1e-9);
  EXPECT_TRUE(planner.plan(start, goal, 10 * (1 - 1e-9)).found);
  const PathPlan near = planner.plan(Vec2d(39, 50), goal, 3);
  EXPECT_EQ(near.reason, "start_too_close");
  EXPECT_EQ(planner.plan(start, Vec2d(61, 50), 3).reason, "goal_too_close");
}

TEST(MotionPlanning, AgreesWithGridPlanner) {
  int compared = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Polygons scene = random_scene(seed, 8);
    Rng rng(seed + 100);
    MotionPlanner planner(scene, [] {
      PlanOptions o;
      o.use_bounds = true;
      o.bounds = AABB2d(Vec2d(-5, -5), Vec2d(115, 115));
      return o;
    }());
    const double h = 120.0 / 240;
    for (int q = 0; q < 3; ++q) {
      Vec2d start, goal;
      do start = Vec2d(rng.uniform(-4, 114), rng.uniform(-4, 114));
      while (planner.inside_obstacle(start) || planner.clearance(start) < 2);
      do goal = Vec2d(rng.uniform(-4, 114), rng.uniform(-4, 114));
      while (planner.inside_obstacle(goal) || planner.clearance(goal) < 2);
      const double rmax = planner.max_radius(start, goal);
      ASSERT_GT(rmax, 0);
      const double low = rmax - 2 * h;
      if (low > 0) {
        const PathPlan p = planner.plan(start, goal, low);
        expect_path_valid(planner, p, start, goal, low);
        EXPECT_TRUE(grid_connected(planner, start, goal, low, h)) << "seed " << seed << " r " << low;
        ++compared;
      }
      // Above the critical radius, when the bottleneck is between the obstacles (not at start or goal).
      const double high = rmax + 2 * h;
      if (high < std::min(planner.clearance(start), planner.clearance(goal)) - 2 * h) {
        const PathPlan p = planner.plan(start, goal, high);
        EXPECT_FALSE(p.found);
        EXPECT_EQ(p.reason, "disconnected");
        EXPECT_FALSE(grid_connected(planner, start, goal, high, h)) << "seed " << seed << " r " << high;
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 12);
}

TEST(MotionPlanning, BadInput) {
  const Vec2d start(10, 50), goal(90, 50);
  EXPECT_THROW(plan_path(square_scene(), Vec2d(50, 50), goal, 1), Error);  // start inside the obstacle
  EXPECT_THROW(plan_path(square_scene(), start, Vec2d(45, 55), 1), Error);  // goal inside
  const Polygons bowtie{{{0, 0}, {10, 10}, {10, 0}, {0, 10}}};
  EXPECT_THROW(plan_path(bowtie, Vec2d(-5, 5), Vec2d(15, 5), 1), Error);
  const Polygons overlapping{{{0, 0}, {10, 0}, {10, 10}, {0, 10}}, {{5, 5}, {15, 5}, {15, 15}, {5, 15}}};
  EXPECT_THROW(plan_path(overlapping, Vec2d(-5, 5), Vec2d(20, 5), 1), Error);
  EXPECT_THROW(plan_path(square_scene(), start, goal, -1), Error);
  EXPECT_THROW(plan_path(square_scene(), Vec2d(std::nan(""), 0), goal, 1), Error);
  EXPECT_THROW(plan_path({{{0, 0}, {1, 1}}}, start, goal, 1), Error);  // not a polygon
  EXPECT_TRUE(plan_path({}, start, goal, 1).found);  // no obstacles: only the frame
}

}  // namespace
}  // namespace geods::voronoi
