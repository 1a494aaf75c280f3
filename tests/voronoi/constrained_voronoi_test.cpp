// Constrained Voronoi diagram VD(S, L): every sampled point lies in a piece of
// its nearest visible site (brute force over all sites and all segments with
// exact crossing tests), the pieces tile the box, points just across a
// constraint from each other belong to sites they see; no segments gives the
// Voronoi diagram; degenerate inputs; bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/constrained_voronoi.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {
namespace {

using Segment = ConstrainedVoronoi::Segment;

bool proper_cross(const Vec2d& x, const Vec2d& q, const Vec2d& a, const Vec2d& b) {
  const auto sgn = [](double v) { return (v > 0) - (v < 0); };
  return sgn(orient2d(a, b, x)) * sgn(orient2d(a, b, q)) < 0 && sgn(orient2d(x, q, a)) * sgn(orient2d(x, q, b)) < 0;
}

// Samples drawn from `window` (the box if empty); distances compared to 1e-9
// of its side (and the rounding of the coordinates).
void expect_matches_brute_force(const ConstrainedVoronoi& v, std::span<const Segment> segments, std::uint64_t seed,
                                int samples = 300, AABB2d window = AABB2d()) {
  v.validate();
  const AABB2d& box = v.box();
  if (window.empty()) window = box;
  const double scale = std::max(window.hi[0] - window.lo[0], window.hi[1] - window.lo[1]);
  double area = 0;
  for (const auto& p : v.pieces()) area += polygon_area(p.polygon);
  const double box_area = (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]);
  EXPECT_NEAR(area, box_area, 1e-7 * box_area);
  Rng rng(seed);
  int outside = 0;
  for (int s = 0; s < samples; ++s) {
    const Vec2d x(rng.uniform(window.lo[0], window.hi[0]), rng.uniform(window.lo[1], window.hi[1]));
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t q = 0; q < v.points().size(); ++q) {
      bool seen = true;
      for (const Segment& g : segments) seen &= !proper_cross(x, v.points()[q], v.points()[g[0]], v.points()[g[1]]);
      if (seen) best = std::min(best, (x - v.points()[q]).norm());
    }
    int containing = 0;
    for (const auto& piece : v.pieces()) {
      if (!point_in_polygon(x, piece.polygon)) continue;
      ++containing;
      EXPECT_TRUE(v.visible(x, piece.site)) << x.transpose();
      EXPECT_NEAR((x - v.points()[piece.site]).norm(), best,
                  1e-9 * (scale + best) + 64 * std::numeric_limits<double>::epsilon() * x.cwiseAbs().maxCoeff())
          << "sample " << x.transpose();
    }
    outside += containing == 0;
  }
  EXPECT_EQ(outside, 0);
}

TEST(ConstrainedVoronoi, RandomSitesAndWallsMatchBruteForce) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    auto p = testing::uniform_points(60, seed);
    // Walls: long horizontal segments at four heights, and short random ones that cross none of them.
    std::vector<Segment> segments;
    Rng rng(seed + 50);
    for (int w = 0; w < 4; ++w) {
      const double c = 0.2 * (w + 1) + rng.uniform(-0.05, 0.05), lo = rng.uniform(0.05, 0.4), hi = rng.uniform(0.6, 0.95);
      const auto i = std::uint32_t(p.size());
      p.push_back({lo, c}), p.push_back({hi, c});
      segments.push_back({i, i + 1});
    }
    for (int tries = 0; tries < 20; ++tries) {
      const std::uint32_t a = std::uint32_t(rng.below(60)), b = std::uint32_t(rng.below(60));
      if (a == b || (p[a] - p[b]).norm() > 0.3) continue;
      bool crossing = false;
      for (const Segment& g : segments) crossing |= proper_cross(p[a], p[b], p[g[0]], p[g[1]]) || g[0] == a || g[1] == a || g[0] == b || g[1] == b;
      if (!crossing) segments.push_back({a, b});
    }
    const ConstrainedVoronoi v(p, segments, frame_around(p));
    SCOPED_TRACE(seed);
    EXPECT_GT(segments.size(), 5u);
    expect_matches_brute_force(v, segments, seed);
  }
}

TEST(ConstrainedVoronoi, PolygonWithBoundaryAndDiagonals) {
  // A square room with an inner wall and sites around: regions split by the segments.
  std::vector<Vec2d> p{{0, 0}, {4, 0}, {4, 4}, {0, 4}, {2, 1}, {2, 3}, {1, 2}, {3, 2}, {2, 5}, {5, 2}, {-1, 2}, {2, -1}};
  const std::vector<Segment> segments{{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}};
  const ConstrainedVoronoi v(p, segments, frame_around(p));
  expect_matches_brute_force(v, segments, 3, 1000);
  // Just left and right of the inner wall's middle: sites 6 and 7, not each other.
  bool left = false, right = false;
  for (const auto& piece : v.pieces()) {
    left |= point_in_polygon(Vec2d(1.999, 2.0), piece.polygon) && piece.site == 6;
    right |= point_in_polygon(Vec2d(2.001, 2.0), piece.polygon) && piece.site == 7;
  }
  EXPECT_TRUE(left);
  EXPECT_TRUE(right);
}

TEST(ConstrainedVoronoi, WithoutSegmentsItIsTheVoronoiDiagram) {
  const auto p = testing::uniform_points(50, 9);
  const AABB2d box = frame_around(p);
  const ConstrainedVoronoi v(p, {}, box);
  const Voronoi2 vd(p);
  std::vector<double> area(p.size(), 0);
  for (const auto& piece : v.pieces()) area[piece.site] += polygon_area(piece.polygon);
  for (std::uint32_t i = 0; i < p.size(); ++i) EXPECT_NEAR(area[i], polygon_area(vd.cell_polygon(i, box)), 1e-9);
}

TEST(ConstrainedVoronoi, GridCollinearAndDuplicates) {
  std::vector<Vec2d> grid;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) grid.push_back({double(x), double(y)});
  grid.push_back(grid[12]);
  const std::vector<Segment> walls{{6, 8}, {11, 16}, {13, 18}};  // through grid sites: split there
  expect_matches_brute_force(ConstrainedVoronoi(grid, walls, frame_around(grid)), walls, 4);
  const std::vector<Vec2d> line{{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  const std::vector<Segment> on_line{{0, 2}};
  expect_matches_brute_force(ConstrainedVoronoi(line, on_line, frame_around(line)), on_line, 5);
}

TEST(ConstrainedVoronoi, SitesFarCloserThanTheBox) {
  // Lattice sites 1e-7 and 1e-9 of a unit box apart, with and without a wall
  // among them: pieces under 1e-15 of the box's area were dropped as slivers,
  // leaving points in no piece for 13 to 60 of 60 such subsets.
  for (const double spacing : {1e-7, 1e-9})
    for (std::uint64_t seed = 1; seed < 200; seed += 14) {
      SCOPED_TRACE("spacing " + std::to_string(spacing) + " seed " + std::to_string(seed));
      std::vector<Vec2d> sites = testing::lattice_subset(seed, true);
      for (Vec2d& p : sites) p = Vec2d(0.5, 0.5) + spacing * p;
      const std::uint32_t n = std::uint32_t(sites.size());
      sites.push_back(Vec2d(0.5, 0.5) + spacing * Vec2d(2.5, 1.5));
      sites.push_back(Vec2d(0.5, 0.5) + spacing * Vec2d(2.5, 7));
      const AABB2d near_sites(Vec2d(0.5, 0.5) - Vec2d(3, 3) * spacing, Vec2d(0.5, 0.5) + Vec2d(9, 9) * spacing);
      for (const std::vector<Segment>& walls : {std::vector<Segment>{}, std::vector<Segment>{{n, n + 1}}})
        expect_matches_brute_force(ConstrainedVoronoi(sites, walls, AABB2d(Vec2d(0, 0), Vec2d(1, 1))), walls, seed, 200,
                                   near_sites);
    }
}

TEST(ConstrainedVoronoi, BadInput) {
  const std::vector<Vec2d> p{{0, 0}, {2, 2}, {0, 2}, {2, 0}};
  const AABB2d box(Vec2d(-1, -1), Vec2d(3, 3));
  EXPECT_THROW(ConstrainedVoronoi(p, std::vector<Segment>{{0, 1}, {2, 3}}, box), Error);  // crossing
  EXPECT_THROW(ConstrainedVoronoi(p, std::vector<Segment>{{0, 0}}, box), Error);
  EXPECT_THROW(ConstrainedVoronoi(p, std::vector<Segment>{{0, 9}}, box), Error);
  EXPECT_THROW(ConstrainedVoronoi(std::vector<Vec2d>{{0, std::nan("")}}, {}, box), Error);
  EXPECT_THROW(ConstrainedVoronoi(p, {}, AABB2d()), Error);
}

}  // namespace
}  // namespace geods::voronoi
