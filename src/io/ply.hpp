#pragma once
// A small PLY reader (not public API) for meshes and point sets: every byte of
// the body is parsed, so truncation, bad numbers and bad indices are caught.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace geods::io::detail {

enum class PlyFormat { ascii, binary_le, binary_be };

struct PlyProperty {
  std::string name;
  int size = 0;            // bytes of a scalar (or of a list item)
  bool is_float = false;
  bool is_signed = false;
  int count_size = 0;      // bytes of a list's count; 0 for scalars
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  // first byte after "end_header\n"
};

/// Parses the header and checks that the declared element counts could fit
/// in the bytes that follow it (so later allocations are bounded by the file).
PlyHeader parse_ply_header(const std::filesystem::path& path, std::span<const std::uint8_t> file);

struct PlyData {
  int dim = 3;                        // 2 if the vertices have no z
  std::vector<double> positions;      // dim per vertex
  std::vector<float> normals;         // nx ny nz per vertex, or empty
  std::vector<std::uint32_t> triangles;  // 3 per triangle; polygons are fanned
};

/// Reads the "vertex" element (x, y, optional z and nx, ny, nz) and the
/// "face" element's vertex_indices (or vertex_index) lists; other elements
/// are parsed and skipped. Non-finite positions and out-of-range indices throw.
PlyData read_ply(const std::filesystem::path& path, std::span<const std::uint8_t> file);

}  // namespace geods::io::detail
