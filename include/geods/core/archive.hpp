#pragma once
// The one binary file format of geods: every structure's save()/load() writes and
// reads an archive of named, typed, aligned sections, and loading maps the file
// so that the sections are read in place (FlatArray views, no parse, no copy).
//
// Layout (little-endian; a big-endian host refuses to write or read):
//   header (64 bytes): magic "GEODSARC", uint32 container version, uint32 byte
//     order mark 0x01020304, char kind[32] (the structure, e.g. "spatial.KdTree",
//     NUL-padded), uint32 kind version, uint32 section count, uint64 checksum of
//     the section table;
//   section table: per section 64 bytes: char name[32] (NUL-padded), uint32 dtype
//     (a DType code, or 255 for a record such as a node struct), uint32 element
//     bytes, uint64 offset from the file start, uint64 element count, uint64
//     checksum of the payload;
//   payloads, each starting at a multiple of 64 bytes (so a view is aligned for
//   any element type), zero-padded between.
// Reading checks the magic, the versions, the kind, that every section lies
// inside the file at an aligned offset with its declared element type and size,
// that nothing follows the last one, and (unless told not to) the checksums, so truncated, corrupt, wrong-type and
// wrong-version files raise geods::Error naming the file. A structure still
// validates what it loads (indices in range, finite coordinates).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "geods/core/dtype.hpp"
#include "geods/core/error.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/mapped_file.hpp"

namespace geods {

/// The element type code of a section: a DType, or kRecordType for structs.
inline constexpr std::uint32_t kRecordType = 255;
template <typename T>
constexpr std::uint32_t archive_type_of() {
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
    return std::uint32_t(dtype_of<T>());
  else
    return kRecordType;
}

/// Collects sections, then writes them in one go.
class ArchiveWriter {
 public:
  /// `kind` names the structure (at most 31 bytes); `kind_version` its layout version.
  ArchiveWriter(std::string kind, std::uint32_t kind_version);

  /// Adds a section of `elements` (not copied: they must live until write()).
  template <typename T>
  void add(std::string_view name, std::span<const T> elements) {
    static_assert(is_bytewise_v<T>, "archive sections hold elements stored as their bytes");
    add_bytes(name, archive_type_of<T>(), sizeof(T), elements.data(), elements.size());
  }
  template <typename T>
  void add(std::string_view name, const std::vector<T>& elements) {
    add(name, std::span<const T>(elements));
  }
  template <typename T>
  void add(std::string_view name, const FlatArray<T>& elements) {
    add(name, elements.span());
  }
  /// Adds a section of one element (a count, a parameter, a header struct), copied.
  template <typename T>
  void add_value(std::string_view name, const T& value) {
    static_assert(is_bytewise_v<T>, "archive sections hold elements stored as their bytes");
    std::vector<std::byte>& copy = values_.emplace_back(sizeof(T));
    std::memcpy(copy.data(), &value, sizeof(T));
    add_bytes(name, archive_type_of<T>(), sizeof(T), copy.data(), 1);
  }

  /// Adds a section recording an element type (a structure's scalar type), read back by Archive::dtype().
  void add_dtype(std::string_view name, DType type) { add_value(name, std::uint32_t(type)); }

  /// Writes the archive; throws geods::Error naming the file on failure.
  void write(const std::filesystem::path& path) const;

 private:
  struct Section {
    std::string name;
    std::uint32_t type, element_bytes;
    const void* data;
    std::uint64_t count;
  };
  void add_bytes(std::string_view name, std::uint32_t type, std::uint32_t element_bytes, const void* data,
                 std::uint64_t count);

  std::string kind_;
  std::uint32_t kind_version_;
  std::vector<Section> sections_;
  std::deque<std::vector<std::byte>> values_;  // add_value's copies (a deque never moves them)
};

/// A mapped archive; its sections are read in place.
class Archive {
 public:
  /// What a load verifies. checksums: the payload checksums (one pass over the
  /// file), which prove the contents are what save() wrote, and the
  /// structure's own cheap checks (index ranges, links: what keeps queries in
  /// bounds). structure_only: no checksums, so every check the structure has,
  /// also those costing as much as a build (Delaunay2's empty circles,
  /// Voronoi2's equidistant vertices, MinMaxOctree's leaves against the
  /// samples). full: the checksums and every check.
  enum class Verify { checksums, structure_only, full };
  /// Whether a load under `verify` runs the checks that the checksums make redundant.
  static bool checks_everything(Verify verify) { return verify != Verify::checksums; }

  /// Maps and checks `path`, which must hold a `kind` archive of `kind_version`.
  static Archive open(const std::filesystem::path& path, std::string_view kind, std::uint32_t kind_version,
                      Verify verify = Verify::checksums);
  /// The kind and kind version of the archive at `path` (to pick a type before loading).
  struct Kind {
    std::string kind;
    std::uint32_t version;
  };
  static Kind peek(const std::filesystem::path& path);

  const std::filesystem::path& path() const { return file_->path(); }
  bool has(std::string_view name) const;

  /// The section `name` viewed in place. Throws geods::Error if it is missing,
  /// holds another element type, or (when given) not `expected_count` elements.
  template <typename T>
  FlatArray<T> array(std::string_view name) const {
    const Entry& e = entry(name, archive_type_of<T>(), sizeof(T));
    return FlatArray<T>(std::span<const T>(reinterpret_cast<const T*>(file_->data() + e.offset), e.count), file_);
  }
  template <typename T>
  FlatArray<T> array(std::string_view name, std::uint64_t expected_count) const {
    FlatArray<T> a = array<T>(name);
    if (a.size() != expected_count) fail_count(name, a.size(), expected_count);
    return a;
  }
  /// The section `name` of `Element`s viewed in place as `T`s of
  /// sizeof(T) / sizeof(Element) elements each (say coordinate pairs as points).
  template <typename T, typename Element>
  FlatArray<T> grouped(std::string_view name) const {
    static_assert(sizeof(T) % sizeof(Element) == 0 && alignof(T) <= 64, "T is a group of Elements");
    constexpr std::size_t group = sizeof(T) / sizeof(Element);
    const FlatArray<Element> elements = array<Element>(name);
    if (elements.size() % group != 0)
      throw error(std::string(name) + ": " + std::to_string(elements.size()) + " elements, not groups of " +
                  std::to_string(group));
    return FlatArray<T>(std::span<const T>(reinterpret_cast<const T*>(elements.data()), elements.size() / group), file_);
  }
  /// The one element of section `name`.
  template <typename T>
  T value(std::string_view name) const {
    return array<T>(name, 1)[0];
  }

  /// The element type recorded by ArchiveWriter::add_dtype (geods::Error if it is not a DType).
  DType dtype(std::string_view name) const;
  /// Throws "PATH: a <what> of f32, expected f64" unless section `name` records dtype_of<T>().
  template <typename T>
  void require_dtype(std::string_view name, std::string_view what) const {
    const DType recorded = dtype(name);
    if (recorded != dtype_of<T>())
      throw error("a " + std::string(what) + " of " + std::string(dtype_name(recorded)) + ", expected " +
                  std::string(dtype_name(dtype_of<T>())));
  }

  /// A geods::Error "PATH: what" for a structure's own checks of what it loaded.
  Error error(const std::string& what) const;
  /// Runs `checks` (say a structure's validate() on what it loaded); a
  /// geods::Error they throw is thrown again as error(its message).
  template <typename Checks>
  void check(Checks&& checks) const {
    try {
      checks();
    } catch (const Error& e) {
      throw error(e.what());
    }
  }

 private:
  struct Entry {
    std::string name;
    std::uint32_t type, element_bytes;
    std::uint64_t offset, count;
  };
  Archive(std::shared_ptr<const MappedFile> file, std::vector<Entry> entries)
      : file_(std::move(file)), entries_(std::move(entries)) {}
  const Entry& entry(std::string_view name, std::uint32_t type, std::uint32_t element_bytes) const;
  [[noreturn]] void fail_count(std::string_view name, std::uint64_t count, std::uint64_t expected) const;

  std::shared_ptr<const MappedFile> file_;
  std::vector<Entry> entries_;
};

}  // namespace geods
