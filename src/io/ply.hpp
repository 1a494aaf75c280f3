#pragma once
// A small PLY parser (not public API): the header for pre-validating meshes
// before Assimp sees them, and the vertex positions for point sets.
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

/// The x, y (and z, if present) columns of the "vertex" element, row-major;
/// `dim` receives 2 or 3. Other elements are parsed and skipped.
std::vector<double> read_ply_vertices(const std::filesystem::path& path, std::span<const std::uint8_t> file, int& dim);

}  // namespace geods::io::detail
