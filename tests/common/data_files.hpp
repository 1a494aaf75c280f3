#pragma once
// The project's data sets (data/, provenance in data/PROVENANCE.md) for the tests
// that read real data: one way to name them.
#include <filesystem>
#include <string>

#include "geods/core/tri_mesh.hpp"
#include "geods/io/mesh_io.hpp"

namespace geods::test {

/// data/<name> in the source tree.
inline std::filesystem::path data_path(const std::string& name) { return std::filesystem::path(GEODS_DATA_DIR) / name; }

/// The mesh data/<name> (io::read_mesh: .ply, .obj, ...).
inline TriMesh data_mesh(const std::string& name) { return io::read_mesh(data_path(name)); }

}  // namespace geods::test
