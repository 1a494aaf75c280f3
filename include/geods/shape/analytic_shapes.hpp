#pragma once
// Meshes of the simple shapes of the seed's Figure 55 (sphere, cube, cylinder,
// torus), whose shape distributions are known or easy to sample directly: for
// tests, demos and figures.
#include <cstdint>

#include "geods/core/tri_mesh.hpp"

namespace geods::shape {

/// An icosahedron subdivided `levels` times (20 * 4^levels triangles), its vertices on the sphere of radius r.
TriMesh icosphere(int levels, float r = 1);
/// The axis-aligned box [0, sx] x [0, sy] x [0, sz] of 12 triangles, outward oriented.
TriMesh box_mesh(float sx = 1, float sy = 1, float sz = 1);
/// A closed cylinder of radius r and height h around the z axis (z in [0, h]), `segments` >= 3 facets.
TriMesh cylinder_mesh(int segments, float r = 1, float h = 2);
/// A torus around the z axis: tube radius r around the circle of radius R; nu x nv quads, each 2 triangles.
TriMesh torus_mesh(float R, float r, int nu = 64, int nv = 32);

}  // namespace geods::shape
