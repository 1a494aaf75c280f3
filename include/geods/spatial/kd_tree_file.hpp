#pragma once
// The binary file format of a saved k-d tree (KdTree::save / KdTree::load).
//
// Layout, little-endian: the 40-byte header below, then the root box (dim lows,
// dim highs), the nodes, the permutation (uint32 per point) and the points in
// their original order (row-major), all in the tree's scalar type.
#include <cstdint>
#include <filesystem>
#include <iosfwd>

namespace geods::spatial {

inline constexpr std::uint32_t kKdTreeFileVersion = 1;

struct KdTreeFileHeader {
  std::uint32_t version = kKdTreeFileVersion;
  std::uint32_t scalar_bytes = 0;  // 4: float, 8: double
  std::uint32_t dim = 0;
  std::uint32_t leaf_size = 0;
  std::uint64_t points = 0;
  std::uint64_t nodes = 0;

  /// Bytes after the header that a well-formed file holds (no overflow: checked on read).
  std::uint64_t body_bytes() const;
};

/// Writes the magic and the header.
void write_kd_tree_header(std::ostream& out, const KdTreeFileHeader& header, const std::filesystem::path& path);
/// Reads and checks the magic, version and sizes, including that the rest of the
/// stream holds exactly body_bytes() (so truncation is caught before allocating).
/// Throws geods::Error naming the file.
KdTreeFileHeader read_kd_tree_header(std::istream& in, const std::filesystem::path& path);
/// The header of a saved tree, to pick the tree type (scalar, dimension) before loading.
KdTreeFileHeader read_kd_tree_header(const std::filesystem::path& path);

/// Raw array I/O that throws geods::Error naming the file on failure or truncation.
void write_bytes(std::ostream& out, const void* data, std::size_t bytes, const std::filesystem::path& path);
void read_bytes(std::istream& in, void* data, std::size_t bytes, const std::filesystem::path& path);

}  // namespace geods::spatial
