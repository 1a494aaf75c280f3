#pragma once
// Reading and writing triangle meshes.
#include <filesystem>

#include "geods/core/tri_mesh.hpp"

namespace geods::io {

/// Reads PLY (ascii/binary), OBJ, STL, OFF or glTF/GLB through Assimp; also
/// .ply.gz/.off.gz. Polygons are triangulated, coincident vertices of
/// unindexed formats (STL) are merged. Throws geods::Error naming the file
/// and the problem (missing, unreadable, malformed, no triangles, out-of-range
/// indices, non-finite coordinates).
TriMesh read_mesh(const std::filesystem::path& path);

enum class MeshEncoding { binary, ascii };

/// Writes PLY, OBJ or STL by the file's extension. PLY and STL honour the
/// encoding (OBJ is always text). Vertex normals are written when present and
/// the format holds them (PLY, OBJ).
void write_mesh(const std::filesystem::path& path, const TriMesh& mesh,
                MeshEncoding encoding = MeshEncoding::binary);

}  // namespace geods::io
