#include "geods/spatial/kd_tree_file.hpp"

#include <cstring>
#include <fstream>
#include <string>

#include "geods/core/error.hpp"

namespace geods::spatial {

namespace {

constexpr char kMagic[8] = {'G', 'E', 'O', 'D', 'S', 'K', 'D', 'T'};

Error file_error(const std::filesystem::path& path, const std::string& what) {
  return Error(path.string() + ": " + what);
}

}  // namespace

std::uint64_t KdTreeFileHeader::body_bytes() const {
  const std::uint64_t node_bytes = 16 + 2 * std::uint64_t(scalar_bytes);
  return 2 * std::uint64_t(dim) * scalar_bytes + nodes * node_bytes + points * 4 + points * dim * scalar_bytes;
}

void write_bytes(std::ostream& out, const void* data, std::size_t bytes, const std::filesystem::path& path) {
  out.write(static_cast<const char*>(data), std::streamsize(bytes));
  if (!out) throw file_error(path, "cannot write");
}

void read_bytes(std::istream& in, void* data, std::size_t bytes, const std::filesystem::path& path) {
  in.read(static_cast<char*>(data), std::streamsize(bytes));
  if (std::size_t(in.gcount()) != bytes) throw file_error(path, "truncated k-d tree file");
}

void write_kd_tree_header(std::ostream& out, const KdTreeFileHeader& h, const std::filesystem::path& path) {
  write_bytes(out, kMagic, sizeof kMagic, path);
  const std::uint32_t words[4] = {h.version, h.scalar_bytes, h.dim, h.leaf_size};
  const std::uint64_t counts[2] = {h.points, h.nodes};
  write_bytes(out, words, sizeof words, path);
  write_bytes(out, counts, sizeof counts, path);
}

KdTreeFileHeader read_kd_tree_header(std::istream& in, const std::filesystem::path& path) {
  char magic[sizeof kMagic];
  read_bytes(in, magic, sizeof magic, path);
  if (std::memcmp(magic, kMagic, sizeof magic) != 0) throw file_error(path, "not a geods k-d tree file (bad magic)");
  std::uint32_t words[4];
  std::uint64_t counts[2];
  read_bytes(in, words, sizeof words, path);
  read_bytes(in, counts, sizeof counts, path);
  KdTreeFileHeader h{words[0], words[1], words[2], words[3], counts[0], counts[1]};
  if (h.version != kKdTreeFileVersion)
    throw file_error(path, "k-d tree file version " + std::to_string(h.version) + ", this geods reads version " +
                               std::to_string(kKdTreeFileVersion));
  if (h.scalar_bytes != 4 && h.scalar_bytes != 8)
    throw file_error(path, "bad scalar size " + std::to_string(h.scalar_bytes) + " in k-d tree header");
  // Bounds that keep body_bytes() from overflowing and match what build() accepts.
  if (h.dim == 0 || h.dim > (1u << 16)) throw file_error(path, "bad dimension " + std::to_string(h.dim));
  if (h.leaf_size == 0) throw file_error(path, "bad leaf size 0");
  if (h.points >= std::uint64_t(1) << 32 || h.nodes > 2 * h.points || (h.points > 0) != (h.nodes > 0))
    throw file_error(path, "bad point or node count in k-d tree header");
  const auto here = in.tellg();
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  in.seekg(here);
  if (here < 0 || end < 0) throw file_error(path, "cannot determine the file size");
  const std::uint64_t rest = std::uint64_t(end - here);
  if (rest < h.body_bytes()) throw file_error(path, "truncated k-d tree file");
  if (rest > h.body_bytes()) throw file_error(path, "trailing bytes after the k-d tree");
  return h;
}

KdTreeFileHeader read_kd_tree_header(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw file_error(path, "cannot open");
  return read_kd_tree_header(in, path);
}

}  // namespace geods::spatial
