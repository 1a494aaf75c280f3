#pragma once
// Test helper: where a section of a saved archive starts in the file's bytes
// (the section table layout of core/archive.hpp), so that a test can corrupt
// one array of a saved structure and load it with Archive::Verify::structure_only:
// the checksums are skipped and the structure's own checks must catch it.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace geods::testing {

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

}  // namespace geods::testing
