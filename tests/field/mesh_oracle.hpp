#pragma once
// Independent oracles for the distance fields' tests: the distance of a point
// to a mesh by a search over all faces in double, and inside/outside by the
// parity of ray crossings over all faces.
#include <cmath>
#include <cstdint>
#include <limits>

#include "geods/core/tri_mesh.hpp"
#include "geods/core/triangle.hpp"
#include "geods/field/mesh_distance.hpp"

namespace geods::field {

inline Vec3d corner(const TriMesh& m, std::size_t f, int i) { return m.vertices[m.triangles[f][i]].cast<double>(); }

struct Brute {
  double distance = std::numeric_limits<double>::infinity();
  std::uint32_t face = kNoIndex;
  TriangleRegion region = TriangleRegion::face;
};

// The closest face over all faces, in double (ties: the first).
inline Brute brute_distance(const TriMesh& m, const Vec3f& p) {
  Brute b;
  const Vec3d q = p.cast<double>();
  for (std::size_t f = 0; f < m.num_triangles(); ++f) {
    TriangleRegion region;
    const double d = (closest_point_on_triangle(q, corner(m, f, 0), corner(m, f, 1), corner(m, f, 2), region) - q).norm();
    if (d < b.distance) b = {d, std::uint32_t(f), region};
  }
  return b;
}

// Inside by the parity of crossings of a ray, over all faces (Moeller-Trumbore
// in double); 0 outside, 1 inside, -1 if the ray passes within 1e-9 of an edge.
inline int parity(const TriMesh& m, const Vec3d& p, const Vec3d& dir) {
  int crossings = 0;
  for (std::size_t f = 0; f < m.num_triangles(); ++f) {
    const Vec3d a = corner(m, f, 0), e1 = corner(m, f, 1) - a, e2 = corner(m, f, 2) - a;
    const Vec3d h = dir.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-300) continue;
    const Vec3d s = p - a;
    const double u = s.dot(h) / det;
    const Vec3d qv = s.cross(e1);
    const double v = dir.dot(qv) / det, t = e2.dot(qv) / det;
    if (t <= 0 || u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9) continue;
    if (u < 1e-9 || v < 1e-9 || u + v > 1 - 1e-9) return -1;
    ++crossings;
  }
  return crossings % 2;
}

// Inside by the majority of three rays' parities (-1: undecided).
inline int ray_inside(const TriMesh& m, const Vec3f& p) {
  const Vec3d dirs[3] = {Vec3d(0.5773, 0.6114, 0.5411).normalized(), Vec3d(-0.3139, 0.8716, -0.3767).normalized(),
                         Vec3d(0.7013, -0.2215, -0.6776).normalized()};
  int votes = 0, trusted = 0;
  for (const Vec3d& d : dirs) {
    const int r = parity(m, p.cast<double>(), d);
    if (r < 0) continue;
    votes += r;
    ++trusted;
  }
  if (trusted == 0) return -1;
  return 2 * votes > trusted ? 1 : 0;
}

}  // namespace geods::field
