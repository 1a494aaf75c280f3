#pragma once
// Meshes of analytic shapes and transformed copies for the shape tests.
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "geods/core/tri_mesh.hpp"
#include "geods/shape/analytic_shapes.hpp"

namespace geods::shape::testing {

// Midpoint subdivision: every triangle into four (same surface).
inline TriMesh subdivide(const TriMesh& m) {
  TriMesh out;
  out.vertices = m.vertices;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const auto key = std::minmax(a, b);
    auto [it, fresh] = mid.try_emplace(key, std::uint32_t(out.vertices.size()));
    if (fresh) out.vertices.push_back(0.5f * (m.vertices[a] + m.vertices[b]));
    return it->second;
  };
  for (const auto& t : m.triangles) {
    const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

using shape::icosphere;
inline TriMesh cube(float s = 1) { return shape::box_mesh(s, s, s); }
inline TriMesh cylinder(int segments, float r = 1, float h = 2) { return shape::cylinder_mesh(segments, r, h); }

// x -> scale * R x + t.
inline TriMesh transformed(TriMesh m, const Eigen::Matrix3f& rotation, const Vec3f& t, float scale) {
  for (auto& v : m.vertices) v = scale * (rotation * v) + t;
  return m;
}

inline Eigen::Matrix3f rotation(float angle, Vec3f axis) {
  return Eigen::AngleAxisf(angle, axis.normalized()).toRotationMatrix();
}

// Vertex clustering on a grid of cells of side `cell`: fewer, coarser triangles.
inline TriMesh decimate(const TriMesh& m, float cell) {
  std::map<std::array<long, 3>, std::uint32_t> cluster;
  std::vector<Vec3f> sum;
  std::vector<float> count;
  std::vector<std::uint32_t> of(m.vertices.size());
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const Vec3f& v = m.vertices[i];
    const std::array<long, 3> key{long(std::floor(v.x() / cell)), long(std::floor(v.y() / cell)),
                                  long(std::floor(v.z() / cell))};
    auto [it, fresh] = cluster.try_emplace(key, std::uint32_t(sum.size()));
    if (fresh) sum.push_back(Vec3f::Zero()), count.push_back(0);
    sum[it->second] += v;
    count[it->second] += 1;
    of[i] = it->second;
  }
  TriMesh out;
  for (std::size_t c = 0; c < sum.size(); ++c) out.vertices.push_back(sum[c] / count[c]);
  for (const auto& t : m.triangles) {
    const TriMesh::Triangle u{of[t[0]], of[t[1]], of[t[2]]};
    if (u[0] != u[1] && u[1] != u[2] && u[0] != u[2]) out.triangles.push_back(u);
  }
  return out;
}

}  // namespace geods::shape::testing
