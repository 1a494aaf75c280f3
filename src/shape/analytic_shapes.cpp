#include "geods/shape/analytic_shapes.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "geods/core/error.hpp"

namespace geods::shape {

TriMesh icosphere(int levels, float r) {
  if (levels < 0 || levels > 10) throw Error("icosphere: levels must be in 0..10");
  const float p = (1 + std::sqrt(5.0f)) / 2;
  TriMesh m;
  m.vertices = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto [it, fresh] = mid.try_emplace(std::minmax(a, b), std::uint32_t(m.vertices.size()));
      if (fresh) m.vertices.push_back(0.5f * (m.vertices[a] + m.vertices[b]));
      return it->second;
    };
    std::vector<TriMesh::Triangle> finer;
    for (const auto& t : m.triangles) {
      const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      finer.insert(finer.end(), {{t[0], ab, ca}, {ab, t[1], bc}, {ca, bc, t[2]}, {ab, bc, ca}});
    }
    m.triangles = std::move(finer);
  }
  for (auto& v : m.vertices) v = v.normalized() * r;
  return m;
}

TriMesh box_mesh(float sx, float sy, float sz) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({sx * float(i & 1), sy * float((i >> 1) & 1), sz * float((i >> 2) & 1)});
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TriMesh cylinder_mesh(int segments, float r, float h) {
  if (segments < 3) throw Error("cylinder_mesh: at least 3 segments");
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

TriMesh torus_mesh(float R, float r, int nu, int nv) {
  if (nu < 3 || nv < 3) throw Error("torus_mesh: at least 3 x 3 quads");
  TriMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float u = 2 * std::numbers::pi_v<float> * float(i) / float(nu);
      const float v = 2 * std::numbers::pi_v<float> * float(j) / float(nv);
      m.vertices.push_back({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  auto at = [&](int i, int j) { return std::uint32_t((i % nu) * nv + j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

}  // namespace geods::shape
