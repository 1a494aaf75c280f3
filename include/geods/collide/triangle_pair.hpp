#pragma once
// Two triangles in space: the exact intersection decision and their distance.
//
// triangles_intersect decides whether two closed triangles share a point with
// exact orientation predicates (core/predicates.hpp) on the given double
// coordinates: touching at a vertex or along an edge, coplanar overlap and
// degenerate triangles (segments, points) included. Its answer is symmetric:
// triangles_intersect(s, t) == triangles_intersect(t, s) for all inputs.
#include <array>

#include "geods/core/vec.hpp"

namespace geods::collide {

using TriangleD = std::array<Vec3d, 3>;

/// Whether the closed triangles s and t intersect (exact for finite coordinates).
bool triangles_intersect(const TriangleD& s, const TriangleD& t);

/// Whether the closed segment pq meets the closed triangle t (exact).
bool segment_intersects_triangle(const Vec3d& p, const Vec3d& q, const TriangleD& t);

/// Closest points of the segments p0p1 and q0q1 (Ericson 5.1.9, in double);
/// returns the squared distance.
double segment_segment_closest(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0, const Vec3d& q1, Vec3d& on_p,
                               Vec3d& on_q);

struct TrianglePairDistance {
  double distance = 0;
  Vec3d on_s = Vec3d::Zero();  // closest point on s
  Vec3d on_t = Vec3d::Zero();  // closest point on t
};

/// Distance between the closed triangles s and t with closest points, in
/// double: 0 (with a common point) when triangles_intersect says so, else the
/// least of the 6 vertex-triangle and 9 edge-edge distances.
TrianglePairDistance triangle_distance(const TriangleD& s, const TriangleD& t);

}  // namespace geods::collide
