#pragma once
// The min/max octree of seed §2.4: built once over the cells of a volume,
// queried for many iso-values, visiting only the nodes the surface can cross.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/grid3.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/iso/marching_cubes.hpp"

namespace geods::iso {

/// The archive kind and layout version of a saved min/max octree (MinMaxOctree::save).
inline constexpr std::string_view kMinMaxOctreeArchiveKind = "iso.MinMaxOctree";
inline constexpr std::uint32_t kMinMaxOctreeArchiveVersion = 1;

/// The sample type of the octree saved at `path`, to pick MinMaxOctree<T> before
/// loading (reads only the header and section table). Throws geods::Error naming the file.
DType read_min_max_octree_scalar(const std::filesystem::path& path);

struct MinMaxOctreeStats {
  std::size_t nodes = 0;       // all levels, leaves included
  std::size_t levels = 0;      // leaves to root
  std::size_t leaf_cells = 0;  // cells per leaf along each axis
  std::size_t cells = 0;       // cells of the volume
  std::size_t bytes = 0;       // min/max arrays and level table (the volume not counted)
};

/// How an octree extraction gives the cells around a crossed grid edge its one vertex.
enum class VertexSharing {
  /// The crossed leaves as blocks (the default): a first parallel pass makes,
  /// per leaf, bit masks of the crossed grid edges it owns (those starting at
  /// its samples; the last sample plane belongs to the last leaf) and counts
  /// its vertices and triangles; prefix sums give every leaf its place in the
  /// output; a second pass writes the vertices and triangles in place, finding
  /// an edge owned by a neighbour leaf by the rank of its bit in that leaf's
  /// masks. No hash table and no merge: the output (order included) is the
  /// same for any number of threads.
  block_masks,
  /// The textbook method of seed §2.4: a recursive descent that shares edge
  /// vertices through a hash table keyed by grid edge, from which an edge is
  /// removed after its last visit (the fourth for an interior edge). Subtrees
  /// run in parallel and are merged into the output of the sequential descent.
  hash_table,
};

/// "block_masks" or "hash_table" (the enum value's name; "blocks" and "hash"
/// are the deprecated spellings); throws geods::Error otherwise.
VertexSharing parse_vertex_sharing(std::string_view name);
std::string_view to_string(VertexSharing sharing);

struct OctreeIsoResult {
  TriMesh mesh;
  std::size_t cells_visited = 0;  // cells whose corners were examined
  std::size_t nodes_visited = 0;  // octree nodes whose min/max was tested
};

/// A complete octree over the cells of a volume (any size: the levels are
/// ceil-halved, children beyond the border do not exist), stored as one flat
/// min array and one max array level by level, each node holding the min and
/// max of the samples of its cells. A leaf covers leaf_cells^3 cells (1 gives
/// the textbook octree with one cell per leaf; larger leaves save memory and
/// node tests). The octree holds its volume's samples in a FlatArray: owned
/// after a build (moved in from the Grid3), read in place from the mapped file
/// after load(), so that a loaded volume larger than RAM can be queried.
///
/// isosurface(iso) descends from the root into the children with
/// min < iso <= max (a cell is crossed iff some corner is >= iso and some is
/// not) and runs the cell cases of marching_cubes.hpp in the leaves it
/// reaches, sharing edge vertices as `sharing` says (see VertexSharing). The
/// result has exactly the vertices and triangles of iso::isosurface() on the
/// same volume, in another order; for a given sharing mode the output is the
/// same for any number of threads.
template <typename T>
class MinMaxOctree {
 public:
  static constexpr std::size_t kDefaultLeafCells = 4;
  static constexpr std::size_t kMaxLeafCells = 32;

  /// Takes the volume's samples without copying them. Throws geods::Error for a
  /// NaN or infinite sample or leaf_cells outside [1, 32]. O(samples), parallel.
  explicit MinMaxOctree(Grid3<T> volume, std::size_t leaf_cells = kDefaultLeafCells);

  /// Thread-safe. Throws geods::Error for a non-finite iso or bad positions.
  OctreeIsoResult isosurface(double iso, const IsoOptions& options = {},
                             VertexSharing sharing = VertexSharing::block_masks) const;

  /// The volume, viewed in place (mapped from the file for a loaded octree);
  /// valid while the octree lives. iso::isosurface() scans it without a copy.
  Grid3View<T> volume() const { return {grid_, samples_}; }
  /// The samples, owned or mapped (samples().mapped() after load()).
  const FlatArray<T>& samples() const { return samples_; }
  /// The min and max sample of every node, level by level from the leaves (read
  /// in place from the file for a loaded octree).
  const FlatArray<T>& node_min() const { return min_; }
  const FlatArray<T>& node_max() const { return max_; }
  MinMaxOctreeStats stats() const;
  /// Checks that every node's min/max is that of its cells' samples
  /// (leaves) or of its children; throws geods::Error naming the first bad node.
  void validate() const;

  /// Writes the octree and its volume as an "iso.MinMaxOctree" archive
  /// (core/archive.hpp): value sections scalar, leaf_cells, dims (3 x u64),
  /// origin, spacing (3 x f32); arrays samples, min, max.
  void save(const std::filesystem::path& path) const;
  /// Reads an octree written by save(): the samples and the min/max arrays are
  /// read in place from the mapped file (no parse, no copy; min/max not
  /// recomputed), which stays mapped while the octree lives. Throws
  /// geods::Error naming the file for another sample type, a truncated or
  /// corrupt file (checksums, unless `verify` says structure_only), NaN or infinite samples
  /// (a pass over them), a leaf with min > max or a node whose min/max is not
  /// that of its children (O(nodes)); Verify::full and structure_only (no
  /// checksums to prove the leaves) run all of validate(), the leaves against
  /// the samples too (a pass like the build).
  static MinMaxOctree load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);

 private:
  MinMaxOctree() = default;
  // The level table of a volume: the size of each level and its offset in min_/max_ (sets cells_).
  std::size_t make_levels();

  struct Level {
    std::array<std::size_t, 3> dims;
    std::size_t offset;
  };
  struct Query;
  struct BlockQuery;
  struct SubtreeRoot {
    std::size_t level, x, y, z;
  };

  // The crossed nodes of the highest level with at least `wanted` of them (or
  // the crossed leaves), in the order of the sequential descent; adds the
  // nodes tested to nodes_visited. Empty if the root is not crossed.
  template <typename Threshold>
  std::vector<SubtreeRoot> subtree_roots(const Threshold& thr, std::size_t wanted, std::size_t& nodes_visited) const;
  OctreeIsoResult hash_table_isosurface(double iso, const IsoOptions& options, bool flip) const;
  OctreeIsoResult block_isosurface(double iso, const IsoOptions& options, bool flip) const;

  std::size_t node_index(std::size_t level, std::size_t x, std::size_t y, std::size_t z) const {
    const Level& l = levels_[level];
    return l.offset + x + l.dims[0] * (y + l.dims[1] * z);
  }
  // The least and greatest sample of a leaf; with non_finite, also sets *non_finite when one of
  // them is NaN or infinite (the constructor's check, in the same pass over the samples).
  std::array<T, 2> leaf_range(std::size_t x, std::size_t y, std::size_t z, bool* non_finite = nullptr) const;
  // validate(); without leaves_against_samples the leaves are only checked
  // min <= max (no pass over the volume), the levels above against their children.
  void check_nodes(bool leaves_against_samples) const;

  Grid3Geometry grid_;
  FlatArray<T> samples_;  // in the order of grid_
  std::size_t leaf_cells_ = kDefaultLeafCells;
  std::array<std::size_t, 3> cells_{0, 0, 0};
  std::vector<Level> levels_;  // levels_[0]: leaves, back(): the root
  FlatArray<T> min_, max_;
};

}  // namespace geods::iso
