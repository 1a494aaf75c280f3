#pragma once
// Small closed meshes and an independent inside/outside oracle for the bsp tests.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "geods/bsp/bsp_tree.hpp"

namespace bsp_test {

using geods::Vec3d;
using geods::bsp::Triangles;

inline Triangles box(Vec3d lo, Vec3d hi) {
  Triangles m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]});
  // Outward quads (corner bit masks), split into two triangles each.
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.push_back({std::uint32_t(f[0]), std::uint32_t(f[1]), std::uint32_t(f[2])});
    m.triangles.push_back({std::uint32_t(f[0]), std::uint32_t(f[2]), std::uint32_t(f[3])});
  }
  return m;
}

/// A torus around the z axis (major radius R, minor r), n x m quads: closed and not convex.
inline Triangles torus(double R, double r, int n, int m, Vec3d c = {0, 0, 0}) {
  Triangles t;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * pi * i / n, v = 2 * pi * j / m;
      t.vertices.push_back(c + Vec3d{(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  auto id = [&](int i, int j) { return std::uint32_t(((i + n) % n) * m + (j + m) % m); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      t.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return t;
}

/// A UV sphere (closed, convex up to the poles' fans).
inline Triangles sphere(double r, int n, int m, Vec3d c = {0, 0, 0}) {
  Triangles t;
  const double pi = 3.14159265358979323846;
  t.vertices.push_back(c + Vec3d{0, 0, -r});
  for (int i = 1; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double th = pi * i / n, ph = 2 * pi * j / m;
      t.vertices.push_back(c + r * Vec3d{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), -std::cos(th)});
    }
  t.vertices.push_back(c + Vec3d{0, 0, r});
  const auto top = std::uint32_t(t.vertices.size() - 1);
  auto id = [&](int i, int j) { return std::uint32_t(1 + (i - 1) * m + (j + m) % m); };
  for (int j = 0; j < m; ++j) t.triangles.push_back({0, id(1, j + 1), id(1, j)});
  for (int i = 1; i + 1 < n; ++i)
    for (int j = 0; j < m; ++j) {
      t.triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  for (int j = 0; j < m; ++j) t.triangles.push_back({top, id(n - 1, j), id(n - 1, j + 1)});
  return t;
}

/// Generalized winding number (sum of signed solid angles, van Oosterom–Strackee): about 1
/// inside a closed outward mesh, 0 outside. An oracle independent of the BSP.
inline double winding_number(const Triangles& m, const Vec3d& p) {
  double w = 0;
  for (const auto& t : m.triangles) {
    const Vec3d a = m.vertices[t[0]] - p, b = m.vertices[t[1]] - p, c = m.vertices[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    w += 2 * std::atan2(num, den);
  }
  return w / (4 * 3.14159265358979323846);
}

inline Triangles transformed(const Triangles& m, double angle, Vec3d shift) {
  Triangles t = m;
  const double c = std::cos(angle), s = std::sin(angle);
  for (auto& v : t.vertices) v = Vec3d{c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]} + shift;
  return t;
}

}  // namespace bsp_test
