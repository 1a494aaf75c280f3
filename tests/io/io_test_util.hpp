#pragma once
// Shared by the io tests: a temporary directory, file helpers and the
// "throws geods::Error naming the file" check every malformed input must pass.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>
#include <vector>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"

namespace geods::io::test {

using geods::test::data_path;

namespace fs = std::filesystem;

/// A fresh directory under the system temp dir, removed at scope exit.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("geods_io_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + "_" + (info ? info->name() : "x"));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline void write_bytes(const fs::path& p, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}
inline void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}
inline std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
inline std::string read_text(const fs::path& p) {
  const auto b = read_bytes(p);
  return {b.begin(), b.end()};
}

/// Expects fn() to throw geods::Error whose message names `file` (and contains `what`, if given).
inline void expect_error(const fs::path& file, const std::function<void()>& fn, const std::string& what = "") {
  try {
    fn();
    ADD_FAILURE() << "no geods::Error for " << file;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos) << e.what();
    if (!what.empty()) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type for " << file << ": " << e.what();
  }
}

/// Writes prefixes of `bytes` cut at several offsets to files named `name` and
/// expects `read` to throw geods::Error naming each (strict) or to either
/// succeed or throw it (lenient: formats whose prefixes may be valid files).
inline void expect_truncations_fail(const fs::path& dir, const std::string& name, const std::vector<std::uint8_t>& bytes,
                                    const std::function<void(const fs::path&)>& read, bool strict = true) {
  std::vector<std::size_t> cuts = {0, 1, 4, 16, bytes.size() / 3, bytes.size() / 2, bytes.size() - 7, bytes.size() - 1};
  for (std::size_t cut : cuts) {
    if (cut >= bytes.size()) continue;
    const fs::path p = dir / name;
    write_bytes(p, std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + std::ptrdiff_t(cut)));
    SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(bytes.size()));
    if (strict) {
      expect_error(p, [&] { read(p); });
    } else {
      try {
        read(p);
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      }
    }
  }
}

}  // namespace geods::io::test
