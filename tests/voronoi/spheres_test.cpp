// The largest empty sphere against brute force: every candidate centre of the
// maximum (circumcentres of four points, equidistant lines of three crossing
// supporting planes, bisector planes of two crossing boundary segments),
// kept when inside the hull; the best distance to the nearest point wins.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/spheres.hpp"

namespace geods::voronoi {
namespace {

struct Plane {
  Vec3d normal;  // unit, outwards
  double offset;
};

double nearest_distance(const std::vector<Vec3d>& p, const Vec3d& q) {
  double d = INFINITY;
  for (const Vec3d& x : p) d = std::min(d, (x - q).norm());
  return d;
}

double brute_largest_empty_radius(const std::vector<Vec3d>& p) {
  const std::size_t n = p.size();
  const double scale = 1e-9;
  // Supporting planes: through three points with every point on one side.
  std::vector<Plane> planes;
  std::vector<std::pair<std::size_t, std::size_t>> boundary_segments;
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      for (std::size_t c = b + 1; c < n; ++c) {
        Vec3d normal = (p[b] - p[a]).cross(p[c] - p[a]);
        if (normal.norm() < 1e-12) continue;
        normal.normalize();
        int above = 0, below = 0;
        for (const Vec3d& x : p) {
          const double s = normal.dot(x - p[a]);
          above += s > scale, below += s < -scale;
        }
        if (above && below) continue;
        if (above) normal = -normal;
        planes.push_back({normal, normal.dot(p[a])});
        boundary_segments.insert(boundary_segments.end(), {{a, b}, {a, c}, {b, c}});
      }
  const auto in_hull = [&](const Vec3d& q) {
    for (const Plane& h : planes)
      if (h.normal.dot(q) - h.offset > scale) return false;
    return true;
  };
  double best = 0;
  const auto offer = [&](const Vec3d& q) {
    if (std::isfinite(q[0] + q[1] + q[2]) && in_hull(q)) best = std::max(best, nearest_distance(p, q));
  };
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b) {
      // bisector plane of a, b crossing a boundary segment
      const Vec3d m = (p[a] + p[b]) / 2, u = p[b] - p[a];
      for (const auto& [i, j] : boundary_segments) {
        const double si = u.dot(p[i] - m), sj = u.dot(p[j] - m);
        if ((si < 0) != (sj < 0)) offer(p[i] + (p[j] - p[i]) * (si / (si - sj)));
      }
      for (std::size_t c = b + 1; c < n; ++c) {
        // the line of points equidistant to a, b, c crossing a supporting plane
        const Vec3d ab = p[b] - p[a], ac = p[c] - p[a], normal = ab.cross(ac);
        if (normal.squaredNorm() < 1e-24) continue;
        const Vec3d centre =
            p[a] + (ab.squaredNorm() * ac.cross(normal) + ac.squaredNorm() * normal.cross(ab)) / (2 * normal.squaredNorm());
        for (const Plane& h : planes) {
          const double along = h.normal.dot(normal);
          if (std::abs(along) > 1e-12) offer(centre + normal * ((h.offset - h.normal.dot(centre)) / along));
        }
        for (std::size_t d = c + 1; d < n; ++d) {
          const Vec3d ad = p[d] - p[a];
          const double det = 2 * ab.dot(ac.cross(ad));
          if (std::abs(det) < 1e-12) continue;
          offer(p[a] + (ab.squaredNorm() * ac.cross(ad) + ac.squaredNorm() * ad.cross(ab) + ad.squaredNorm() * ab.cross(ac)) / det);
        }
      }
    }
  return best;
}

TEST(LargestEmptySphere, AgreesWithBruteForceOnRandomAndDegenerateSets) {
  Rng rng(5);
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<Vec3d> p;
    const std::size_t n = 6 + rng.below(9);
    if (trial % 3 == 2) {  // lattice points: cospherical and coplanar subsets
      while (p.size() < n) {
        const Vec3d x(double(rng.below(3)), double(rng.below(3)), double(rng.below(3)));
        if (std::find(p.begin(), p.end(), x) == p.end()) p.push_back(x);
      }
    } else {
      for (std::size_t i = 0; i < n; ++i) p.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
    }
    const Delaunay3 dt(p);
    if (dt.dimension() < 3) continue;
    SCOPED_TRACE("trial " + std::to_string(trial));
    const Sphere s = largest_empty_sphere(dt);
    const double expected = brute_largest_empty_radius(p);
    EXPECT_NEAR(s.radius, expected, 1e-9 * (1 + expected));
    EXPECT_NEAR(nearest_distance(p, s.center), s.radius, 1e-12);
    Vec3d centroid = Vec3d::Zero();  // inside the hull: the centre moved towards it a little is too
    for (const Vec3d& x : p) centroid += x / double(p.size());
    EXPECT_NE(dt.locate(s.center + (centroid - s.center) * 1e-9), Delaunay3::no_index);
  }
}

TEST(LargestEmptySphere, LowerDimensionsAndBadInput) {
  // A unit square's corners: the circle at its centre.
  const std::vector<Vec3d> square = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  Sphere s = largest_empty_sphere(square);
  EXPECT_NEAR(s.radius, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR((s.center - Vec3d(0.5, 0.5, 1)).norm(), 0, 1e-12);
  // Points on a line: half the widest gap, at its middle.
  const std::vector<Vec3d> line = {{0, 0, 0}, {1, 1, 1}, {4, 4, 4}, {3, 3, 3}};
  s = largest_empty_sphere(line);
  EXPECT_NEAR(s.radius, std::sqrt(3.0), 1e-12);
  EXPECT_NEAR((s.center - Vec3d(2, 2, 2)).norm(), 0, 1e-12);
  s = largest_empty_sphere(std::vector<Vec3d>{{1, 2, 3}, {1, 2, 3}});
  EXPECT_EQ(s.radius, 0);
  EXPECT_THROW(largest_empty_sphere(std::vector<Vec3d>{}), Error);
  EXPECT_THROW(largest_empty_sphere(std::vector<Vec3d>{{0, NAN, 0}}), Error);
  // A cube's corners and centre: the largest empty spheres touch a face centre's.
  std::vector<Vec3d> cube;
  for (int k = 0; k < 8; ++k) cube.emplace_back(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  cube.emplace_back(0.5, 0.5, 0.5);
  s = largest_empty_sphere(cube);
  EXPECT_NEAR(s.radius, brute_largest_empty_radius(cube), 1e-12);
}

}  // namespace
}  // namespace geods::voronoi
