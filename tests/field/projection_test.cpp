// field::project_distance against brute force: at every pixel of small
// images and volumes, the depth is the distance to the nearest site computed
// by a search over all sites (its own distance formulas, in double), and the
// id names a nearest site (ties: a site whose distance equals the nearest
// within rounding).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/projection.hpp"

namespace geods::field {
namespace {

// Brute-force distances, written independently of site_distance.
double point_segment(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
  // Minimize |a + t (b - a) - p| over t in [0, 1] by the derivative's root.
  const Vec3d d = b - a;
  double t = d.dot(d) == 0 ? 0 : -(a - p).dot(d) / d.dot(d);
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return std::hypot(a.x() + t * d.x() - p.x(), a.y() + t * d.y() - p.y(), a.z() + t * d.z() - p.z());
}

bool inside(const std::vector<Vec2d>& poly, double x, double y) {  // crossing number of a ray to +x
  int c = 0;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2d &a = poly[i], &b = poly[j];
    if ((a.y() > y) != (b.y() > y) && x < (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y()) + a.x()) ++c;
  }
  return c % 2 == 1;
}

double brute(const ProjectionSites& s, std::size_t id, const Vec3d& p) {
  if (id < s.points.size()) return std::hypot(p.x() - s.points[id].x(), p.y() - s.points[id].y(), p.z() - s.points[id].z());
  id -= s.points.size();
  if (id < s.segments.size()) return point_segment(p, s.segments[id][0], s.segments[id][1]);
  id -= s.segments.size();
  const auto& poly = s.polygons[id];
  double d = 0;
  if (!inside(poly, p.x(), p.y())) {
    d = std::numeric_limits<double>::infinity();
    for (std::size_t e = 0; e < poly.size(); ++e) {
      const Vec2d a = poly[e], b = poly[(e + 1) % poly.size()];
      d = std::min(d, point_segment(Vec3d(p.x(), p.y(), 0), Vec3d(a.x(), a.y(), 0), Vec3d(b.x(), b.y(), 0)));
    }
  }
  return std::hypot(d, p.z());
}

// Every pixel against brute force; counts the ties met.
void check_all(const ProjectionSites& sites, const Grid3Geometry& grid, const Projection& r,
               double max_distance = std::numeric_limits<double>::infinity(), std::size_t* tie_count = nullptr) {
  std::size_t ties = 0;
  for (std::size_t k = 0; k < grid.dims[2]; ++k)
    for (std::size_t j = 0; j < grid.dims[1]; ++j)
      for (std::size_t i = 0; i < grid.dims[0]; ++i) {
        const Vec3d p(double(grid.origin.x()) + double(i) * grid.spacing.x(),
                      double(grid.origin.y()) + double(j) * grid.spacing.y(),
                      double(grid.origin.z()) + double(k) * grid.spacing.z());
        double best = std::numeric_limits<double>::infinity();
        std::size_t best_id = kNoIndex;
        for (std::size_t s = 0; s < sites.size(); ++s) {
          const double d = brute(sites, s, p);
          if (d < best) best = d, best_id = s;
        }
        const std::size_t n = grid.index(i, j, k);
        const double scale = 1 + best;
        if (best > max_distance) {
          ASSERT_EQ(r.ids[n], kNoIndex) << i << " " << j << " " << k;
          ASSERT_EQ(r.distance.data[n], INFINITY);
          continue;
        }
        ASSERT_NEAR(r.distance.data[n], best, 1e-12 * scale) << i << " " << j << " " << k;
        ASSERT_NE(r.ids[n], kNoIndex);
        if (r.ids[n] != best_id) {  // a tie: the id's own distance is the nearest within rounding
          ASSERT_NEAR(brute(sites, r.ids[n], p), best, 1e-12 * scale) << i << " " << j << " " << k;
          ++ties;
        }
      }
  if (tie_count) *tie_count = ties;
}

Grid3Geometry image(std::size_t w, std::size_t h, double spacing = 1, Vec3f origin = Vec3f::Zero()) {
  Grid3Geometry g;
  g.dims = {w, h, 1};
  g.origin = origin;
  g.spacing = Vec3f::Constant(float(spacing));
  return g;
}

TEST(Projection, RandomPointsSegmentsPolygons2D) {
  Rng rng(7);
  for (int round = 0; round < 4; ++round) {
    ProjectionSites s;
    for (int i = 0; i < 12 + round * 5; ++i) s.points.emplace_back(rng.uniform(-2, 42), rng.uniform(-2, 32), 0);
    for (int i = 0; i < 4; ++i)
      s.segments.push_back({Vec3d(rng.uniform(0, 40), rng.uniform(0, 30), 0), Vec3d(rng.uniform(0, 40), rng.uniform(0, 30), 0)});
    const double cx = rng.uniform(5, 35), cy = rng.uniform(5, 25);
    s.polygons.push_back({{cx, cy}, {cx + 4, cy + 1}, {cx + 2, cy + 2}, {cx + 3, cy + 5}, {cx - 1, cy + 3}});  // non-convex
    const Grid3Geometry g = image(41, 31, 1.0, Vec3f(0.25f, -0.5f, 0));
    const Projection r = project_distance(s, g);
    check_all(s, g, r);
    EXPECT_EQ(r.stats.pixels, 41u * 31u);
    EXPECT_GT(r.stats.culled_sites, 0u);
    // Inside the polygon the depth is 0 and the id the polygon's.
    const std::size_t centre = g.index(std::size_t(cx + 1.5 - 0.25 + 0.5), std::size_t(cy + 2 + 0.5 + 0.5), 0);
    if (r.distance.data[centre] == 0) {
      EXPECT_EQ(r.ids[centre], s.size() - 1);
    }
  }
}

TEST(Projection, DegenerateTiesAndDuplicates) {
  // Sites on the pixel lattice, duplicates, a degenerate segment, co-circular
  // sites: many exact ties, which go to the smallest id.
  ProjectionSites s;
  s.points = {Vec3d(2, 2, 0), Vec3d(2, 2, 0), Vec3d(6, 2, 0), Vec3d(2, 6, 0), Vec3d(6, 6, 0)};
  s.segments = {{Vec3d(4, 4, 0), Vec3d(4, 4, 0)}, {Vec3d(0, 8, 0), Vec3d(8, 8, 0)}};
  const Grid3Geometry g = image(9, 9);
  const Projection r = project_distance(s, g);
  std::size_t ties = 0;  // brute force keeps the first of equal distances too: only rounding may differ
  check_all(s, g, r, INFINITY, &ties);
  EXPECT_EQ(ties, 0u);
  EXPECT_EQ(r.ids[g.index(2, 2, 0)], 0u);  // the duplicate's first copy
  EXPECT_EQ(r.ids[g.index(4, 2, 0)], 0u);  // equidistant from 0, 1 and 2: the smallest id
  EXPECT_EQ(r.distance.data[g.index(4, 4, 0)], 0.0);
  EXPECT_EQ(r.ids[g.index(4, 4, 0)], 5u);
  EXPECT_EQ(r.ids[g.index(5, 8, 0)], 6u);
  // One site: the cone itself.
  ProjectionSites one;
  one.points = {Vec3d(0.5, 0.5, 0)};
  const Projection c = project_distance(one, image(3, 2));
  EXPECT_DOUBLE_EQ(c.distance(2, 1, 0), std::hypot(1.5, 0.5));
}

TEST(Projection, HyperboloidsAndSegmentsOnSlices3D) {
  Rng rng(11);
  ProjectionSites s;
  for (int i = 0; i < 20; ++i) s.points.emplace_back(rng.uniform(0, 10), rng.uniform(0, 8), rng.uniform(-1, 7));
  for (int i = 0; i < 3; ++i)
    s.segments.push_back({Vec3d(rng.uniform(0, 10), rng.uniform(0, 8), rng.uniform(0, 6)),
                          Vec3d(rng.uniform(0, 10), rng.uniform(0, 8), rng.uniform(0, 6))});
  s.polygons.push_back({{1, 1}, {4, 1}, {4, 3}, {1, 3}});  // in the plane z = 0
  Grid3Geometry g;
  g.dims = {11, 9, 7};
  g.spacing = Vec3f(1.0f, 1.0f, 1.0f);
  const Projection r = project_distance(s, g);
  check_all(s, g, r);
  // Anisotropic spacing, an offset origin.
  g.spacing = Vec3f(0.75f, 1.25f, 0.5f);
  g.origin = Vec3f(-0.5f, 0.25f, -1.0f);
  check_all(s, g, project_distance(s, g));
}

TEST(Projection, MaxDistanceBoundsTheCones) {
  ProjectionSites s;
  s.points = {Vec3d(3, 3, 0), Vec3d(20, 10, 0)};
  const Grid3Geometry g = image(25, 14);
  ProjectionOptions o;
  o.max_distance = 4;
  const Projection r = project_distance(s, g, o);
  check_all(s, g, r, 4);
  EXPECT_EQ(r.ids[g.index(12, 7, 0)], kNoIndex);
  EXPECT_LT(r.stats.fragments, g.dims[0] * g.dims[1] * 2);
}

TEST(Projection, ThreadCountDoesNotChangeTheResult) {
  Rng rng(3);
  ProjectionSites s;
  for (int i = 0; i < 50; ++i) s.points.emplace_back(rng.uniform(0, 60), rng.uniform(0, 60), 0);
  const Grid3Geometry g = image(64, 64);
  const Projection a = project_distance(s, g);
  set_num_threads(1);
  const Projection b = project_distance(s, g);
  set_num_threads(0);
  EXPECT_EQ(a.distance.data, b.distance.data);
  EXPECT_EQ(a.ids, b.ids);
}

TEST(Projection, ConeTessellationError) {
  // A fan of n triangles overestimates by max_distance (1 / cos(pi / n) - 1): check against the
  // fan's plane through the apex and two rim vertices, at the middle of a side.
  const double R = 10;
  for (int n : {8, 32, 128}) {
    const double half = M_PI / n;
    const double chord = R * std::cos(half);  // the fan's edge midpoint is at radius chord, height R
    EXPECT_NEAR(cone_tessellation_error(R, n), R * R / chord - R, 1e-12);
  }
  EXPECT_THROW(cone_tessellation_error(1, 2), Error);
}

TEST(Projection, BadInput) {
  ProjectionSites s;
  const Grid3Geometry g = image(4, 4);
  EXPECT_THROW(project_distance(s, g), Error);  // no sites
  s.points = {Vec3d(std::nan(""), 0, 0)};
  EXPECT_THROW(project_distance(s, g), Error);
  s.points = {Vec3d(1, 1, 0)};
  s.polygons = {{{0, 0}, {1, 1}}};
  EXPECT_THROW(project_distance(s, g), Error);
  s.polygons.clear();
  Grid3Geometry bad = g;
  bad.spacing.x() = 0;
  EXPECT_THROW(project_distance(s, bad), Error);
  bad = g;
  bad.dims[1] = 0;
  EXPECT_THROW(project_distance(s, bad), Error);
  ProjectionOptions o;
  o.max_distance = -1;
  EXPECT_THROW(project_distance(s, g, o), Error);
  bad = g;
  bad.dims = {1u << 20, 1u << 20, 1u << 20};
  EXPECT_THROW(project_distance(s, bad), Error);  // before allocating
}

}  // namespace
}  // namespace geods::field
