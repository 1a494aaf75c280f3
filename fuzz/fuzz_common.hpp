#pragma once
// Shared by the libFuzzer targets: the readers take paths, so each input is
// written to a file in a per-process temp directory and read back. A reader
// may succeed or throw geods::Error; any other exception escapes and libFuzzer
// reports it as a crash.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "geods/core/error.hpp"

namespace geods::fuzz {

inline std::filesystem::path input_path(const std::string& name) {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("geods_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir / name;
}

template <typename Read>
int read_as(const std::uint8_t* data, std::size_t size, const std::string& name, Read read) {
  const auto path = input_path(name);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    read(path);
  } catch (const geods::Error&) {
  }
  return 0;
}

}  // namespace geods::fuzz
