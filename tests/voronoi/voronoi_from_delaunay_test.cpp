// Voronoi2 built from Delaunay2 on larger and degenerate sets: validity, cells
// and nearest sites against brute force, applications against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "brute_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/circles.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/proximity.hpp"

namespace geods::voronoi {
namespace {

using testing::prim_mst_length;
using testing::uniform_points;

std::vector<Vec2d> clustered(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2d> centers = uniform_points(8, seed + 100);
  std::vector<Vec2d> p(n);
  for (Vec2d& v : p) v = centers[rng.below(8)] + Vec2d(rng.normal(), rng.normal()) * 0.01;
  return p;
}

std::vector<Vec2d> shuffled_grid(int k, std::uint64_t seed) {
  std::vector<Vec2d> p;
  for (int x = 0; x < k; ++x)
    for (int y = 0; y < k; ++y) p.push_back(Vec2d(x, y));
  Rng rng(seed);
  for (std::size_t i = p.size(); i > 1; --i) std::swap(p[i - 1], p[rng.below(i)]);
  for (int d = 0; d < 20; ++d) p.push_back(p[rng.below(p.size())]);  // duplicates
  return p;
}

// The 12 integer points on the circle of radius 5 and its centre's neighbours.
std::vector<Vec2d> pythagorean_circle() {
  std::vector<Vec2d> p;
  for (int sx : {-1, 1})
    for (int sy : {-1, 1}) p.insert(p.end(), {Vec2d(3 * sx, 4 * sy), Vec2d(4 * sx, 3 * sy)});
  p.insert(p.end(), {Vec2d(5, 0), Vec2d(-5, 0), Vec2d(0, 5), Vec2d(0, -5)});
  return p;
}

void check_nearest(const Voronoi2& v, std::uint64_t seed, int queries) {
  const SlabLocator slab(v);
  slab.validate();
  const WalkLocator walk(v);
  const AABB2d box = v.default_box(0.5);
  Rng rng(seed);
  std::vector<Vec2d> q;
  for (int i = 0; i < queries; ++i) q.push_back({rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1])});
  for (int i = 0; i < 50; ++i) q.push_back(v.points()[rng.below(v.size())]);
  const auto a = slab.nearest_batch(q), b = walk.nearest_batch(q);
  for (std::size_t i = 0; i < q.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (const Vec2d& p : v.points()) best = std::min(best, (p - q[i]).squaredNorm());
    EXPECT_EQ((v.points()[a[i]] - q[i]).squaredNorm(), best) << "slab, query " << q[i].transpose();
    EXPECT_EQ((v.points()[b[i]] - q[i]).squaredNorm(), best) << "walk, query " << q[i].transpose();
  }
}

void check_cells(const Voronoi2& v, std::uint64_t seed) {
  const AABB2d box = v.default_box(0.1);
  const auto cells = v.cell_polygons(box);
  double area = 0;
  for (std::uint32_t i = 0; i < v.size(); ++i)
    if (v.representative(i) == i) area += polygon_area(cells[i]);
  const double box_area = (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]);
  EXPECT_NEAR(area, box_area, 1e-9 * box_area);
  const WalkLocator walk(v);
  Rng rng(seed);
  for (int s = 0; s < 300; ++s) {
    const Vec2d q(rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1]));
    const std::uint32_t site = walk.nearest(q);
    // The cell of the nearest site holds q unless q is within rounding of its boundary.
    const auto& cell = cells[site];
    bool on_boundary = false;
    for (std::size_t k = 0; k < cell.size(); ++k) {
      const Vec2d a = cell[k], b = cell[(k + 1) % cell.size()];
      const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      on_boundary = on_boundary || (a + t * (b - a) - q).norm() < 1e-9 * (box.hi - box.lo).norm();
    }
    EXPECT_TRUE(on_boundary || point_in_polygon(q, cell)) << q.transpose();
  }
}

TEST(VoronoiFromDelaunay, UniformClusteredGridCircle) {
  std::vector<std::vector<Vec2d>> sets = {uniform_points(3000, 1), clustered(2000, 2), shuffled_grid(25, 3),
                                          pythagorean_circle()};
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const Voronoi2 v(sets[k]);
    v.validate();
    check_nearest(v, k, 400);
    check_cells(v, k + 10);
  }
}

TEST(VoronoiFromDelaunay, CoCircularCentreIsOneVertexOfDegree12) {
  const Voronoi2 v(pythagorean_circle());
  v.validate();
  ASSERT_EQ(v.vertices().size(), 1u);
  EXPECT_EQ(v.vertices()[0], Vec2d(0, 0));
  EXPECT_EQ(v.stats().edges, 12u);
  EXPECT_EQ(v.stats().unbounded_cells, 12u);
  EXPECT_EQ(largest_empty_circle(v).radius, 5);
}

TEST(VoronoiFromDelaunay, HugeTinyAndOffsetCoordinates) {
  // The range in which circumcentres, cubic in the coordinates, keep every
  // resolvable difference: up to 3.5e100, extents down to 4e-87.
  for (double scale : {1e100, 1e-80}) {
    std::vector<Vec2d> p = uniform_points(500, 4);
    for (Vec2d& x : p) x *= scale;
    const Voronoi2 v(p);
    v.validate();
    check_nearest(v, 5, 200);
  }
  for (double scale : {1e101, 1e-100}) {
    std::vector<Vec2d> p = uniform_points(500, 4);
    for (Vec2d& x : p) x *= scale;
    EXPECT_THROW(Voronoi2{p}, Error) << scale;
  }
  std::vector<Vec2d> p = uniform_points(500, 6);
  for (Vec2d& x : p) x = x * 1e-3 + Vec2d(1e6, -1e6);  // small spread far from the origin
  const Voronoi2 v(p);
  v.validate();
  check_nearest(v, 7, 200);
}

TEST(VoronoiFromDelaunay, ApplicationsOnLargerSets) {
  for (const auto& p : {uniform_points(1500, 8), clustered(1500, 9), shuffled_grid(20, 10)}) {
    const Voronoi2 v(p);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p.size(); ++i)
      for (std::size_t j = i + 1; j < p.size(); ++j) best = std::min(best, (p[i] - p[j]).norm());
    EXPECT_EQ(closest_pair(p).distance, best);
    const auto nn = all_nearest_neighbors(v);
    for (std::size_t i = 0; i < p.size(); i += 7) {
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < p.size(); ++j)
        if (j != i) nearest = std::min(nearest, (p[i] - p[j]).norm());
      EXPECT_EQ((p[i] - p[nn[i]]).norm(), nearest);
    }
    // Prim on the complete graph.
    const double prim = prim_mst_length(p);
    const SpanningTree tree = emst(p);
    EXPECT_EQ(tree.edges.size(), p.size() - 1);
    EXPECT_NEAR(tree.length, prim, 1e-9 * prim);
    // The largest empty circle is empty and centred in the hull (checked against the triangulation's hull).
    const Circle c = largest_empty_circle(v);
    for (const Vec2d& s : p) EXPECT_GE((s - c.center).norm(), c.radius * (1 - 1e-12));
    const Delaunay2 dt(p);
    const auto& hull = dt.hull();
    for (std::size_t k = 0; k < hull.size(); ++k)
      EXPECT_GE(orient2d(p[hull[k]], p[hull[(k + 1) % hull.size()]], c.center), -1e-9);
    // No Voronoi vertex inside the hull has a larger empty circle.
    for (const Vec2d& x : v.vertices()) {
      bool inside = true;
      for (std::size_t k = 0; k < hull.size(); ++k) inside = inside && orient2d(p[hull[k]], p[hull[(k + 1) % hull.size()]], x) > 0;
      if (!inside) continue;
      double r = std::numeric_limits<double>::infinity();
      for (const Vec2d& s : p) r = std::min(r, (s - x).norm());
      EXPECT_LE(r, c.radius * (1 + 1e-12));
    }
  }
}

TEST(VoronoiFromDelaunay, RemovedPointsAreRejected) {
  Delaunay2 dt(uniform_points(20, 11));
  dt.remove(3);
  EXPECT_THROW(Voronoi2 v(dt), Error);
  EXPECT_THROW(Voronoi2(std::vector<Vec2d>{}), Error);
}

}  // namespace
}  // namespace geods::voronoi
