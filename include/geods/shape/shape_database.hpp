#pragma once
// A shape retrieval database (seed §5.6, steps 3 and 4): the descriptor
// (shape_distribution.hpp) of every shape in a k-d tree over the feature
// vectors, queried for the k nearest shapes, exactly or (1 + eps)-approximately,
// in the Euclidean distance of the feature vectors.
//
// The vectors live in a dynamic::DynamicKdTree (the logarithmic method over
// static spatial::KdTree blocks, seed §7): a batch of shapes added at once
// (add with many meshes, or add_descriptors) is described in parallel and
// inserted in one go (the blocks of the binary representation of its size, the
// large ones built in parallel); shapes added later go through the
// dynamization (O(log^2 n) amortized per shape) rather than a rebuild. Ids are
// 0, 1, 2, ... in the order of adding.
//
// Files: save() writes a "shape.ShapeDatabase" archive (core/archive.hpp): the
// descriptor options, names and labels, and the dynamic tree's sections under
// "tree." (its blocks' k-d trees are read in place from the mapped file by
// load()). A file of another kind or version, or a corrupt one, raises
// geods::Error naming it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "geods/core/tri_mesh.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/shape/shape_distribution.hpp"

namespace geods::shape {

inline constexpr std::string_view kShapeDatabaseArchiveKind = "shape.ShapeDatabase";
inline constexpr std::uint32_t kShapeDatabaseArchiveVersion = 1;

/// One answer of a query: the shape's id, name and label, and the Euclidean
/// distance between its feature vector and the query's.
struct ShapeMatch {
  std::uint64_t id = 0;
  std::string name, label;
  double distance = 0;
};

struct ShapeDatabaseStats {
  std::size_t shapes = 0;
  std::size_t dimension = 0;   // values per feature vector
  std::size_t labels = 0;      // distinct non-empty labels
  std::size_t structures = 0;  // k-d tree blocks of the dynamization
  std::size_t bytes = 0;       // tree blocks, names and labels
};

class ShapeDatabase {
 public:
  using Tree = dynamic::DynamicKdTree<float, spatial::Dynamic>;

  /// An empty database whose shapes are described by `options` (checked: geods::Error).
  explicit ShapeDatabase(DescriptorOptions options = {});

  const DescriptorOptions& options() const { return options_; }
  std::size_t size() const { return names_.size(); }
  bool empty() const { return names_.empty(); }
  /// Values per feature vector: functions * bins.
  std::size_t dimension() const { return tree_.dim(); }
  const std::string& name(std::uint64_t id) const { return names_.at(id); }
  const std::string& label(std::uint64_t id) const { return labels_.at(id); }
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<std::string>& labels() const { return labels_; }
  /// The feature vector of shape `id`.
  std::vector<float> descriptor(std::uint64_t id) const;

  /// The feature vector of a mesh under this database's options (describe()).
  std::vector<float> describe(const TriMesh& mesh) const;

  /// Adds one shape; returns its id. Throws geods::Error for a mesh describe() refuses.
  std::uint64_t add(std::string name, const TriMesh& mesh, std::string label = {});
  /// Adds shapes whose descriptors are computed in parallel, then inserted as
  /// one batch; labels empty or one per mesh. All are described before any is
  /// added: a mesh describe() refuses throws (naming it) and adds nothing.
  std::vector<std::uint64_t> add(std::span<const std::string> names, std::span<const TriMesh> meshes,
                                 std::span<const std::string> labels = {});
  /// Adds precomputed feature vectors (rows of `descriptors`, dimension() values
  /// each, as describe() makes them) as one batch; labels empty or one per row.
  std::vector<std::uint64_t> add_descriptors(std::span<const std::string> names, std::span<const float> descriptors,
                                             std::span<const std::string> labels = {});

  /// The k nearest shapes to the mesh, nearest first (ties by id); fewer if
  /// the database holds fewer. eps > 0: approximate, the i-th distance within
  /// (1 + eps) of the true i-th.
  std::vector<ShapeMatch> query(const TriMesh& mesh, std::size_t k, double eps = 0) const;
  /// The same for a feature vector of dimension() values.
  std::vector<ShapeMatch> query_descriptor(std::span<const float> descriptor, std::size_t k, double eps = 0) const;

  ShapeDatabaseStats stats() const;
  /// The tree's invariants, and one name and label per stored shape.
  void validate() const;
  const Tree& tree() const { return tree_; }

  /// Writes the database as a "shape.ShapeDatabase" archive.
  void save(const std::filesystem::path& path) const;
  /// Maps a database written by save(). Throws geods::Error naming the file
  /// for another kind or version, a truncated or corrupt file, or contents
  /// that fail validate().
  static ShapeDatabase load(const std::filesystem::path& path);

 private:
  std::vector<std::uint64_t> insert(std::span<const std::string> names, std::span<const float> rows,
                                    std::span<const std::string> labels);

  DescriptorOptions options_;
  Tree tree_;
  std::vector<std::string> names_, labels_;  // by id
};

}  // namespace geods::shape
