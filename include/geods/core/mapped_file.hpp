#pragma once
// A read-only memory mapping of a whole file: the pages are read on first touch,
// so a file larger than RAM can be used in place.
#include <cstddef>
#include <filesystem>
#include <memory>

namespace geods {

class MappedFile {
 public:
  /// Maps `path` read-only. Throws geods::Error naming the file if it cannot be
  /// opened or mapped. An empty file maps to size() == 0 and data() == nullptr.
  static std::shared_ptr<const MappedFile> open(const std::filesystem::path& path);

  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();

  const std::byte* data() const { return data_; }
  std::size_t size() const { return size_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  MappedFile(std::filesystem::path path, const std::byte* data, std::size_t size)
      : path_(std::move(path)), data_(data), size_(size) {}

  std::filesystem::path path_;
  const std::byte* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace geods
