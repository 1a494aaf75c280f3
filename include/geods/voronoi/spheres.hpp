#pragma once
// The largest empty sphere centred in the convex hull of points in space
// (seed §5.4.3's largest empty circle, which carries over to 3D).
#include <span>

#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay3.hpp"

namespace geods::voronoi {

struct Sphere {
  Vec3d center = Vec3d::Zero();
  double radius = 0;
};

/// The largest sphere whose centre lies in the convex hull of the points and
/// whose interior holds none of them. The distance to the nearest point is
/// convex on each Voronoi cell, so its maximum over the hull is a corner of a
/// cell clipped to the hull (Voronoi3(dt)): a Voronoi vertex inside the hull,
/// a Voronoi edge crossing a hull triangle or a Voronoi face crossing a hull
/// edge. The corners are computed in doubles; the radius is the distance from
/// the returned centre to its nearest point, so no point lies inside. Coplanar
/// points: the largest empty circle in their plane; collinear ones: half the
/// largest gap; one distinct point: radius 0. Throws geods::Error for none.
Sphere largest_empty_sphere(const Delaunay3& dt);
Sphere largest_empty_sphere(std::span<const Vec3d> points);

}  // namespace geods::voronoi
