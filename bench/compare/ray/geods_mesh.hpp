#pragma once
// The geods programs of the ray comparison take a TriMesh as input, as a PLY
// reader would give it; copying the PLY arrays into it is part of their build.
#include <cstdint>

#include "common.hpp"
#include "geods/core/tri_mesh.hpp"

namespace compare::ray {

/// The mesh as a geods::TriMesh, filled once per thread and mesh size.
inline const geods::TriMesh& geods_mesh(const PlyMesh& ply) {
  static thread_local geods::TriMesh mesh;
  if (mesh.num_triangles() != ply.triangles()) {
    mesh.vertices.resize(ply.vertices());
    for (std::size_t i = 0; i < ply.vertices(); ++i)
      mesh.vertices[i] = {ply.xyz[3 * i], ply.xyz[3 * i + 1], ply.xyz[3 * i + 2]};
    mesh.triangles.resize(ply.triangles());
    for (std::size_t i = 0; i < ply.triangles(); ++i)
      mesh.triangles[i] = {std::uint32_t(ply.tris[3 * i]), std::uint32_t(ply.tris[3 * i + 1]),
                           std::uint32_t(ply.tris[3 * i + 2])};
  }
  return mesh;
}

}  // namespace compare::ray
