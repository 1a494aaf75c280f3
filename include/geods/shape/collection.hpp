#pragma once
// Collections of shapes to index: a directory tree of meshes (every format
// io::read_mesh reads), a zip archive of meshes, or a Sweet Home 3D furniture
// library (.sh3f: a zip of OBJ models and a PluginFurnitureCatalog.properties
// whose model#N, name#N and category#N give each model's path, name and
// category). Labels come from the catalog (the category) or from a CSV file of
// `path,label` rows (a header row `path,label` is allowed), which overrides.
//
// Entries are named by their path inside the collection ('/'-separated,
// sorted for directories and zips, catalog order for .sh3f). A member that
// cannot be read or described is skipped by index_collection with a warning
// that names it and says why, and counted; nothing else is silently dropped.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "geods/core/progress.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/shape/shape_database.hpp"

namespace geods::shape {

enum class CollectionKind { directory, zip, sh3f };

struct CollectionEntry {
  std::string name;   // path inside the collection
  std::string label;  // empty: unlabelled
  std::string title;  // .sh3f: the catalog's name#N (else empty)
};

/// Labels of a CSV file: rows `path,label` (fields may be double-quoted; blank
/// lines and lines starting with '#' are ignored; a first row `path,label` is
/// a header). Throws geods::Error naming the file and line for a malformed row.
std::vector<std::pair<std::string, std::string>> read_labels_csv(const std::filesystem::path& path);

class ShapeCollection {
 public:
  /// Opens a directory, a .zip or a .sh3f (by extension) and lists its meshes;
  /// `labels_csv` (optional) labels them. Throws geods::Error for a path that
  /// is none of these, an unreadable archive or catalog, or a CSV that names
  /// no entry at all (a row naming a missing entry is a warning).
  static ShapeCollection open(const std::filesystem::path& path, const std::filesystem::path& labels_csv = {});

  CollectionKind kind() const { return kind_; }
  const std::filesystem::path& path() const { return path_; }
  const std::vector<CollectionEntry>& entries() const { return entries_; }
  std::size_t size() const { return entries_.size(); }
  /// What open() noticed but did not refuse (CSV rows naming no entry, catalog models not in the archive).
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// Entry i's mesh; safe to call from several threads. Throws geods::Error naming the entry.
  TriMesh read(std::size_t i) const;

 private:
  struct Zip;
  CollectionKind kind_ = CollectionKind::directory;
  std::filesystem::path path_;
  std::vector<CollectionEntry> entries_;
  std::vector<std::string> warnings_;
  std::shared_ptr<Zip> zip_;  // zip and sh3f
};

/// A member index_collection skipped, and why.
struct SkippedShape {
  std::string name;
  std::string reason;
};

struct CollectionIndex {
  ShapeDatabase database;
  std::vector<SkippedShape> skipped;  // in entry order
};

/// Reads and describes every entry in parallel and adds them as one batch
/// (one k-d tree built in parallel). An entry that cannot be read or
/// described (unreadable, empty, zero area, non-finite) is skipped and listed.
CollectionIndex index_collection(const ShapeCollection& collection, const DescriptorOptions& options,
                                 const ProgressCallback& progress = {});

}  // namespace geods::shape
