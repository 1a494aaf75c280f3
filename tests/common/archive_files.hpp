#pragma once
// Bad archive files for the save/load tests of every structure: a saved file
// truncated, with a flipped byte, or with another kind version, each of which
// the structure's load() must refuse with geods::Error; and where a section
// lies, to corrupt one array past the checksums.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "geods/core/error.hpp"

namespace geods::test {

inline std::filesystem::path temp_archive(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("geods_test_" + name + ".geods");
}

inline std::vector<char> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
inline void write_bytes(const std::filesystem::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

/// Where the payload of section `name` starts in a saved archive's bytes (the
/// section table layout of core/archive.hpp), so that a test can corrupt one
/// array and load with Archive::Verify::structure_only: the checksums are
/// skipped and the structure's own checks must catch it.
inline std::size_t archive_section_offset(const std::vector<char>& bytes, std::string_view name) {
  constexpr std::size_t kHeader = 64, kRecord = 64, kCountAt = 52, kOffsetAt = 40;
  std::uint32_t sections = 0;
  std::memcpy(&sections, bytes.data() + kCountAt, sizeof sections);
  for (std::size_t i = 0; i < sections; ++i) {
    const char* record = bytes.data() + kHeader + i * kRecord;
    if (std::string_view(record, strnlen(record, 32)) != name) continue;
    std::uint64_t offset = 0;
    std::memcpy(&offset, record + kOffsetAt, sizeof offset);
    return std::size_t(offset);
  }
  throw std::runtime_error("no section " + std::string(name));
}

/// load(path) on copies of the archive at `saved` cut short at `cuts` sizes,
/// with one byte flipped at `flips` positions spread over the file, and with
/// another kind version: every one throws geods::Error.
template <typename Load>
void expect_bad_copies_refused(const std::filesystem::path& saved, Load&& load, int cuts = 40, int flips = 120) {
  const std::vector<char> bytes = read_bytes(saved);
  ASSERT_GT(bytes.size(), 64u);
  const std::filesystem::path bad = saved.string() + ".bad";
  for (int i = 0; i < cuts; ++i) {
    const std::size_t size = bytes.size() * std::size_t(i) / std::size_t(cuts);
    write_bytes(bad, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(size)));
    EXPECT_THROW(load(bad), Error) << "truncated to " << size << " of " << bytes.size() << " bytes";
  }
  for (int i = 0; i < flips; ++i) {
    // Spread over the file, the header and section table included; positions in
    // the padding between sections are not covered by a checksum, so skip zeros.
    const std::size_t at = (bytes.size() - 1) * std::size_t(i) / std::size_t(flips - 1);
    std::vector<char> copy = bytes;
    if (copy[at] == 0 && at >= 64) continue;
    copy[at] = char(copy[at] ^ 0x10);
    write_bytes(bad, copy);
    EXPECT_THROW(load(bad), Error) << "byte " << at << " of " << bytes.size() << " flipped";
  }
  std::vector<char> version = bytes;
  std::uint32_t v;
  std::memcpy(&v, version.data() + 48, 4);  // the header's kind version
  ++v;
  std::memcpy(version.data() + 48, &v, 4);
  write_bytes(bad, version);
  EXPECT_THROW(load(bad), Error) << "another kind version";
  std::filesystem::remove(bad);
}

/// load(path) must throw geods::Error whose message holds each of `parts`.
template <typename Load>
void expect_load_error(const std::filesystem::path& path, Load&& load, std::initializer_list<std::string_view> parts) {
  try {
    load(path);
    ADD_FAILURE() << path << " loaded; expected an error";
  } catch (const Error& e) {
    for (std::string_view part : parts)
      EXPECT_NE(std::string_view(e.what()).find(part), std::string_view::npos) << e.what() << " lacks " << part;
  }
}

}  // namespace geods::test
