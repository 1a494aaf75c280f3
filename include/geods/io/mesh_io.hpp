#pragma once
// Reading and writing triangle meshes.
#include <cstdint>
#include <filesystem>
#include <span>

#include "geods/core/tri_mesh.hpp"

namespace geods::io {

/// Reads PLY (ascii/binary), OFF and STL (ascii/binary; coincident corners
/// merged) with our own strict parsers that keep the file's vertex order, and
/// OBJ and glTF/GLB through Assimp (identical vertices merged, node transforms
/// applied); also any of them gzip-compressed (.ply.gz, .off.gz, ...). Polygons are fan-triangulated; points and lines are skipped.
/// Throws geods::Error naming the file and the problem (missing, unreadable,
/// malformed, truncated, no triangles, out-of-range indices, non-finite
/// coordinates); counts are checked against the file size before allocating.
TriMesh read_mesh(const std::filesystem::path& path);

/// True if read_mesh reads `path` by its name: .ply, .obj, .stl, .off, .gltf,
/// .glb, or one of them gzip-compressed (.stl.gz). `geods info` and every
/// command that reads meshes decide with it.
bool is_mesh_name(const std::filesystem::path& path);

/// Reads a mesh from the bytes of a file called `name` (say a member of a zip
/// archive): its extension picks the format as in read_mesh, and errors name
/// it. Side files (OBJ materials, glTF buffers) are not looked for; the
/// geometry of an OBJ does not need them.
TriMesh read_mesh_from_memory(std::span<const std::uint8_t> bytes, const std::filesystem::path& name);

enum class MeshEncoding { binary, ascii };

/// Writes PLY, OBJ or STL by the file's extension. PLY and STL honour the
/// encoding (OBJ is always text). Vertex normals are written when present and
/// the format holds them (PLY, OBJ).
void write_mesh(const std::filesystem::path& path, const TriMesh& mesh,
                MeshEncoding encoding = MeshEncoding::binary);

}  // namespace geods::io
