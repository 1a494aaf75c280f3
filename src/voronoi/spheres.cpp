// The largest empty sphere: the best corner of the Voronoi cells clipped to
// the hull; flat and collinear sets go down a dimension.
#include "geods/voronoi/spheres.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/voronoi/circles.hpp"
#include "geods/voronoi/voronoi3.hpp"

namespace geods::voronoi {
namespace {

// The distinct points of a set that does not span space.
std::vector<Vec3d> distinct_points(const Delaunay3& dt) {
  std::vector<Vec3d> out;
  for (std::uint32_t i = 0; i < dt.points().size(); ++i)
    if (dt.representative(i) == i) out.push_back(dt.points()[i]);
  return out;
}

// Collinear points: the midpoint of the widest gap along their line.
Sphere on_a_line(const std::vector<Vec3d>& p) {
  const auto [lo, hi] = std::minmax_element(p.begin(), p.end(), [](const Vec3d& a, const Vec3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  const Vec3d origin = *lo, direction = *hi - *lo;
  std::vector<std::pair<double, Vec3d>> along;
  for (const Vec3d& x : p) along.push_back({(x - origin).dot(direction), x});
  std::sort(along.begin(), along.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  Sphere best{p.front(), 0};
  for (std::size_t k = 1; k < along.size(); ++k) {
    const Vec3d& a = along[k - 1].second;
    const Vec3d& b = along[k].second;
    if ((b - a).norm() / 2 > best.radius) best = {(a + b) / 2, (b - a).norm() / 2};
  }
  return best;
}

// Coplanar points: the largest empty circle in their plane, through an orthonormal frame of it.
Sphere in_a_plane(const std::vector<Vec3d>& p) {
  // The frame from the triangle of p[0] with the farthest point and the point farthest from that line.
  const Vec3d& o = p[0];
  std::size_t far = 0;
  for (std::size_t k = 1; k < p.size(); ++k)
    if ((p[k] - o).squaredNorm() > (p[far] - o).squaredNorm()) far = k;
  const Vec3d u = (p[far] - o).normalized();
  std::size_t side = 0;
  double best_area = 0;
  for (std::size_t k = 1; k < p.size(); ++k)
    if (const double a = u.cross(p[k] - o).squaredNorm(); a > best_area) best_area = a, side = k;
  const Vec3d n = u.cross(p[side] - o).normalized();
  const Vec3d v = n.cross(u);
  std::vector<Vec2d> flat;
  for (const Vec3d& x : p) flat.push_back(Vec2d((x - o).dot(u), (x - o).dot(v)));
  const Circle c = largest_empty_circle(flat);
  const Vec3d center = o + c.center[0] * u + c.center[1] * v;
  double radius = INFINITY;
  for (const Vec3d& x : p) radius = std::min(radius, (x - center).norm());
  return {center, radius};
}

}  // namespace

Sphere largest_empty_sphere(const Delaunay3& dt) {
  if (dt.dimension() < 0) throw Error("largest_empty_sphere: no points");
  if (dt.dimension() < 3) {
    const std::vector<Vec3d> p = distinct_points(dt);
    if (dt.dimension() == 0) return {p.front(), 0};
    return dt.dimension() == 1 ? on_a_line(p) : in_a_plane(p);
  }
  const Voronoi3 cells(dt);
  Sphere best{dt.points()[dt.tetrahedra()[0]], 0};
  for (const Voronoi3Cell& cell : cells.cells()) {
    const Vec3d& site = dt.points()[cell.site];
    for (const Vec3d& x : cell.vertices)
      if (const double r = (x - site).norm(); r > best.radius) best = {x, r};
  }
  // The corner is equidistant to its cell's site and neighbours up to rounding: measure to the nearest.
  best.radius = (dt.points()[dt.nearest_vertex(best.center)] - best.center).norm();
  return best;
}

Sphere largest_empty_sphere(std::span<const Vec3d> points) { return largest_empty_sphere(Delaunay3(points)); }

}  // namespace geods::voronoi
