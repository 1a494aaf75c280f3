#pragma once
// Meshes, triangle soups, rays and brute-force oracles for the bvh tests.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "common/data_files.hpp"
#include "common/simd_level_guard.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/rng.hpp"
#include "geods/core/triangle.hpp"

namespace geods::bvh::test {

using geods::test::data_mesh;
using geods::test::LevelGuard;

/// The same hit to the bit: t, u, v and the triangle.
inline bool same_bits(const RayHit& a, const RayHit& b) {
  return std::memcmp(&a.t, &b.t, sizeof(float)) == 0 && std::memcmp(&a.u, &b.u, sizeof(float)) == 0 &&
         std::memcmp(&a.v, &b.v, sizeof(float)) == 0 && a.prim == b.prim;
}

inline Vec3f random_point(Rng& rng, float lo, float hi) {
  return {float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi))};
}

inline Vec3f random_direction(Rng& rng) {
  for (;;) {
    const Vec3f d = random_point(rng, -1, 1);
    if (d.squaredNorm() > 0.01f && d.squaredNorm() <= 1) return d.normalized();
  }
}

/// A soup of n triangles in about [-1, 1]^3: ordinary, tiny (1e-6), huge
/// (spanning 40 units), axis-aligned on integer-ish planes, and degenerate
/// (repeated corner, collinear corners).
inline TriMesh random_soup(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  TriMesh mesh;
  for (std::size_t i = 0; i < n; ++i) {
    Vec3f a = random_point(rng, -1, 1), b, c;
    switch (rng.below(6)) {
      case 0:
      case 1:
        b = a + 0.3f * random_point(rng, -1, 1);
        c = a + 0.3f * random_point(rng, -1, 1);
        break;
      case 2:  // tiny
        b = a + 1e-6f * random_point(rng, -1, 1);
        c = a + 1e-6f * random_point(rng, -1, 1);
        break;
      case 3:  // huge
        b = a + 20.0f * random_point(rng, -1, 1);
        c = a + 20.0f * random_point(rng, -1, 1);
        break;
      case 4: {  // axis-aligned, on a plane at a multiple of 0.25
        const int axis = int(rng.below(3));
        const float level = 0.25f * float(int(rng.below(9)) - 4);
        a[axis] = level;
        b = a + 0.5f * random_point(rng, -1, 1);
        c = a + 0.5f * random_point(rng, -1, 1);
        b[axis] = c[axis] = level;
        if (rng.below(2)) b[(axis + 1) % 3] = a[(axis + 1) % 3];  // an axis-parallel edge too
        break;
      }
      default:  // degenerate
        b = a + 0.2f * random_point(rng, -1, 1);
        c = rng.below(2) ? b : Vec3f(a + 0.5f * (b - a));
        break;
    }
    const auto base = std::uint32_t(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

/// A flat n x n grid of unit squares split into right triangles (z = 0), for
/// rays exactly through shared edges and vertices.
inline TriMesh flat_grid(int n) {
  TriMesh grid;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) grid.vertices.push_back({float(x), float(y), 0.0f});
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::uint32_t a = std::uint32_t(y * (n + 1) + x), b = a + 1, c = a + std::uint32_t(n) + 1, d = c + 1;
      grid.triangles.push_back({a, b, d});
      grid.triangles.push_back({a, d, c});
    }
  return grid;
}

inline Vec3f corner(const TriMesh& mesh, std::size_t tri, int k) { return mesh.vertices[mesh.triangles[tri][k]]; }

/// Brute force closest hit, same watertight test.
inline RayHit brute_intersect(const TriMesh& mesh, const Ray3f& ray) {
  RayHit best;
  const RayTriangleTest<float> test(ray);
  float tmax = ray.tmax;
  for (std::size_t i = 0; i < mesh.num_triangles(); ++i) {
    float t, u, v;
    if (test.intersect(corner(mesh, i, 0), corner(mesh, i, 1), corner(mesh, i, 2), ray.tmin, tmax, t, u, v)) {
      tmax = t;
      best = {t, std::uint32_t(i), u, v};
    }
  }
  return best;
}

/// Whether triangle i is hit at exactly t.
inline bool hits_at(const TriMesh& mesh, std::size_t i, const Ray3f& ray, float t_expected) {
  const RayTriangleTest<float> test(ray);
  float t, u, v;
  return test.intersect(corner(mesh, i, 0), corner(mesh, i, 1), corner(mesh, i, 2), ray.tmin, ray.tmax, t, u, v) &&
         t == t_expected;
}

inline float brute_distance(const TriMesh& mesh, const Vec3f& p) {
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < mesh.num_triangles(); ++i)
    best = std::min(best, (closest_point_on_triangle(p, corner(mesh, i, 0), corner(mesh, i, 1), corner(mesh, i, 2)) - p).norm());
  return best;
}

/// Generalized winding number in double (sum of signed solid angles / 4 pi,
/// Van Oosterom and Strackee): ~1 inside a closed outward mesh, ~0 outside.
inline double winding_number(const TriMesh& mesh, const Vec3f& pf) {
  const Vec3d p = pf.cast<double>();
  double total = 0;
  for (std::size_t i = 0; i < mesh.num_triangles(); ++i) {
    const Vec3d a = corner(mesh, i, 0).cast<double>() - p, b = corner(mesh, i, 1).cast<double>() - p,
                c = corner(mesh, i, 2).cast<double>() - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2 * std::atan2(num, den);
  }
  return total / (4 * M_PI);
}

/// Rays of every hard kind for a mesh: random from outside, aimed at vertices
/// and edge midpoints, starting on the surface, axis-parallel.
inline std::vector<Ray3f> test_rays(const TriMesh& mesh, std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  const AABB3f box = mesh.bounds();
  const Vec3f center = box.center();
  const float radius = box.extent().norm() + 1e-3f;
  std::vector<Ray3f> rays;
  for (std::size_t i = 0; i < n; ++i) {
    Ray3f r;
    const std::size_t tri = rng.below(mesh.num_triangles());
    const Vec3f a = corner(mesh, tri, 0), b = corner(mesh, tri, 1), c = corner(mesh, tri, 2);
    const Vec3f outside = center + radius * random_direction(rng);
    switch (i % 7) {
      case 0:  // random through the box
        r.origin = outside;
        r.direction = (center + 0.5f * box.extent().cwiseProduct(random_point(rng, -1, 1)) - outside).normalized();
        break;
      case 1:  // at a vertex
        r.origin = outside;
        r.direction = a - outside;
        break;
      case 2:  // at an edge midpoint
        r.origin = outside;
        r.direction = 0.5f * (a + b) - outside;
        break;
      case 3: {  // from a point on the surface
        const float u = float(rng.uniform()), v = float(rng.uniform() * (1 - u));
        r.origin = a + u * (b - a) + v * (c - a);
        r.direction = random_direction(rng);
        break;
      }
      case 4: {  // axis-parallel from outside
        const int axis = int(rng.below(3));
        r.origin = center + 0.5f * box.extent().cwiseProduct(random_point(rng, -1, 1));
        r.origin[axis] = rng.below(2) ? box.lo[axis] - 1 : box.hi[axis] + 1;
        r.direction = Vec3f::Zero();
        r.direction[axis] = r.origin[axis] < center[axis] ? 1.0f : -1.0f;
        break;
      }
      case 5: {  // in an axis plane through a vertex (a zero direction component), or from the vertex
        const int axis = int(rng.below(3));
        r.origin = rng.below(2) ? a : Vec3f(outside);
        r.origin[axis] = a[axis];
        r.direction = rng.below(2) ? Vec3f(a - r.origin) : random_direction(rng);
        if (r.direction.isZero(0)) r.direction = random_direction(rng);
        r.direction[axis] = 0;
        break;
      }
      default:  // in the plane of a triangle (parallel to it), through its centroid
        r.origin = (a + b + c) / 3.0f - (b - a);
        r.direction = b - a;
        r.tmax = float(rng.uniform(0.5, 3.0));
        break;
    }
    rays.push_back(r);
  }
  return rays;
}

/// Makes every stride-th ray one with a non-finite direction or origin, in
/// turn: a direction infinite on every axis and a NaN origin (slab distances
/// NaN on every axis, at a node's empty slots too), a NaN origin coordinate
/// with an infinite direction component, a direction infinite on one axis
/// only; every second of them a line (tmin = -inf). None of them hits
/// anything.
inline void make_non_finite_rays(std::vector<Ray3f>& rays, std::size_t stride) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t k = 0, i = 0; i < rays.size(); ++k, i += stride) {
    Ray3f& r = rays[i];
    switch (k % 4) {
      case 0: r.direction = Vec3f(inf, -inf, inf); break;
      case 1: r.origin = Vec3f(nan, nan, nan); break;
      case 2: r.origin[2] = nan, r.direction[1] = -inf; break;
      default: r.direction[k / 4 % 3] = k / 4 % 2 ? -inf : inf; break;
    }
    if ((k + k / 4) % 2) r.tmin = -inf;
  }
}

}  // namespace geods::bvh::test
