#pragma once
// Triangles of zero area that floats hold exactly (corners on lattice lines),
// and rays aimed at points along them: the rounded watertight test "hit" about
// one in twelve such rays before it decided zero area exactly.
#include <cstdint>
#include <vector>

#include "geods/core/ray.hpp"
#include "geods/core/rng.hpp"
#include "geods/core/tri_mesh.hpp"

namespace geods::test {

/// n triangles in about [-2, 2]^3: every other one has exactly collinear
/// corners (a + i d, a + j d with a on a 1/64 lattice and d a small lattice
/// step; now and then a repeated corner), the others are ordinary triangles
/// around the same points.
inline TriMesh collinear_soup(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  const auto lattice = [&](int range) { return float(int(rng.below(std::uint64_t(2 * range + 1))) - range) / 64.0f; };
  TriMesh mesh;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f a(lattice(64), lattice(64), lattice(64));
    Vec3f b, c;
    if (i % 2 == 0) {
      Vec3f d;
      do d = Vec3f(lattice(7), lattice(7), lattice(7));
      while (d.isZero(0));
      const int j = int(rng.below(17)) - 8, k = int(rng.below(17)) - 8;
      b = a + float(j) * d;
      c = rng.below(8) == 0 ? b : Vec3f(a + float(k) * d);
    } else {
      b = a + Vec3f(lattice(16), lattice(16), lattice(16));
      c = a + Vec3f(lattice(16), lattice(16), lattice(16));
    }
    const auto base = std::uint32_t(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

/// Rays from random points of [-3, 3]^3, ray i towards a random point of the
/// segment between the second and third corner of triangle i mod n of `mesh`.
inline std::vector<Ray3f> rays_along_triangles(const TriMesh& mesh, std::size_t count, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Ray3f> rays(count);
  for (std::size_t i = 0; i < count; ++i) {
    Ray3f& ray = rays[i];
    const auto& t = mesh.triangles[i % mesh.num_triangles()];
    const Vec3f& b = mesh.vertices[t[1]];
    const Vec3f& c = mesh.vertices[t[2]];
    ray.origin = Vec3f(float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)));
    ray.direction = b + float(rng.uniform(0, 1)) * (c - b) - ray.origin;
  }
  return rays;
}

}  // namespace geods::test
