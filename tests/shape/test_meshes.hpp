#pragma once
// Meshes of analytic shapes and transformed copies for the shape tests.
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "geods/core/tri_mesh.hpp"

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

// Icosahedron subdivided `levels` times, vertices pushed onto the sphere of radius r.
inline TriMesh icosphere(int levels, float r = 1) {
  const float p = (1 + std::sqrt(5.0f)) / 2;
  TriMesh m;
  m.vertices = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int i = 0; i < levels; ++i) m = subdivide(m);
  for (auto& v : m.vertices) v = v.normalized() * r;
  return m;
}

// Axis-aligned cube [0, s]^3 of 12 triangles.
inline TriMesh cube(float s = 1) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({s * float(i & 1), s * float((i >> 1) & 1), s * float((i >> 2) & 1)});
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// Closed cylinder of radius r and height h around the z axis, `segments` facets.
inline TriMesh cylinder(int segments, float r = 1, float h = 2) {
  TriMesh m;
  for (int i = 0; i < segments; ++i) {
    const float a = 2 * std::numbers::pi_v<float> * float(i) / float(segments);
    m.vertices.push_back({r * std::cos(a), r * std::sin(a), 0});
    m.vertices.push_back({r * std::cos(a), r * std::sin(a), h});
  }
  const auto bottom = std::uint32_t(m.vertices.size());
  m.vertices.push_back({0, 0, 0});
  m.vertices.push_back({0, 0, h});
  for (int i = 0; i < segments; ++i) {
    const auto a = std::uint32_t(2 * i), b = std::uint32_t(2 * ((i + 1) % segments));
    m.triangles.push_back({a, b, a + 1});
    m.triangles.push_back({b, b + 1, a + 1});
    m.triangles.push_back({bottom, b, a});
    m.triangles.push_back({bottom + 1, a + 1, b + 1});
  }
  return m;
}

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
