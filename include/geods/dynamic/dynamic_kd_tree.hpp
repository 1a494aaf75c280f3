#pragma once
// Dyn(k-d) (seed §7.4): a k-d tree with insert and delete, made of static
// spatial::KdTree blocks by the generic dynamization (dynamized.hpp).
// With the worst-case variant (Theorem 14): build O(n log n), query
// O(sqrt(n) log n + a) for ranges in 2D, insert O(log^2 n), delete O(log n)
// (weak delete plus a share of a global reconstruction that runs in steps),
// all worst case, space O(n). The amortized variant rebuilds in one delete.
//
// Semantics: insert hands out new ids (0, 1, 2, ...), never reused. The same
// coordinates inserted twice are two items; a removed id is gone for good and
// re-inserting its point gives one item with a new id. Removing an id that is
// not stored is an error (geods::Error), and a batch with such an id removes
// nothing. Deleted points leave the blocks, and their memory is returned, at
// the end of the next global reconstruction (which starts when more than half
// of the stored slots are dead, and in the worst-case variant ends within a
// bounded number of later operations), or on rebuild().
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/parallel.hpp"
#include "geods/dynamic/dynamized.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/spatial/kd_tree_stepped_build.hpp"
#include "geods/spatial/knn_result.hpp"
#include "geods/spatial/point_filter.hpp"
#include "geods/spatial/point_view.hpp"

namespace geods::dynamic {

/// One block V_i of Dyn(k-d): a spatial::KdTree over its items (point index =
/// slot), built in steps (KdTreeSteppedBuild), and one flag per slot for the
/// weak delete (WD_k-d of §7.4), which its queries skip.
template <typename T, int Dim>
class KdTreeBlock {
 public:
  using Tree = spatial::KdTree<T, Dim>;
  using Item = typename spatial::KdTreeSteppedBuild<T, Dim>::Row;
  static constexpr std::size_t kLeafSize = 8;

  class Builder {
   public:
    explicit Builder(std::vector<Item> items) : dim_(item_dim(items)), build_(std::move(items), dim_, kLeafSize) {}
    std::size_t estimated_work() const { return build_.estimated_work(); }
    bool step(std::size_t work) { return build_.step(work); }
    KdTreeBlock finish() {
      KdTreeBlock block;
      block.tree_ = build_.finish();
      block.dead_.assign(block.tree_.size(), 0);
      return block;
    }

   private:
    // A block of a run-time dimension takes it from its items (an empty one has none).
    static std::size_t item_dim(const std::vector<Item>& items) {
      if constexpr (Dim == spatial::Dynamic)
        return items.empty() ? 1 : items.front().size();
      else
        return std::size_t(Dim);
    }
    std::size_t dim_;
    spatial::KdTreeSteppedBuild<T, Dim> build_;
  };

  static KdTreeBlock build(std::vector<Item> items) { return Builder(std::move(items)).finish(); }
  /// A block of a tree built elsewhere (read from a file), no slot dead yet.
  static KdTreeBlock adopt(Tree tree) {
    KdTreeBlock block;
    block.tree_ = std::move(tree);
    if (!block.tree_.stores_points_in_tree_order()) block.tree_.store_points_in_tree_order();
    block.dead_.assign(block.tree_.size(), 0);
    return block;
  }

  /// Slots, dead ones included.
  std::size_t size() const { return tree_.size(); }
  std::size_t dead() const { return dead_count_; }
  bool all_dead() const { return dead_count_ == size(); }
  /// Every item, dead ones included, in slot order.
  std::vector<Item> extract() const {
    std::vector<Item> out;
    out.reserve(size());
    for (std::size_t slot = 0; slot < size(); ++slot) out.push_back(item(slot));
    return out;
  }
  Item item(std::size_t slot) const {
    const T* p = tree_.point(slot);
    Item out;
    if constexpr (Dim == spatial::Dynamic) out.resize(tree_.dim());
    std::copy(p, p + tree_.dim(), out.begin());
    return out;
  }
  bool is_dead(std::size_t slot) const { return dead_.at(slot) != 0; }
  void weak_delete(std::size_t slot) {
    if (slot >= size() || dead_[slot])
      throw Error("KdTreeBlock::weak_delete: slot " + std::to_string(slot) + " is not a live slot");
    dead_[slot] = 1;
    ++dead_count_;
  }

  /// The tree (point index = slot) and the filter its queries take to skip dead slots.
  const Tree& tree() const { return tree_; }
  spatial::SkipFlagged dead_slots() const { return {dead_.data()}; }
  /// One byte per slot, 1 if weakly deleted.
  const std::vector<std::uint8_t>& dead_flags() const { return dead_; }

  /// Heap bytes held.
  std::size_t bytes() const { return tree_.bytes() + dead_.capacity(); }

  /// The tree's invariants (it keeps its points in tree order too) and the dead flags.
  void validate() const {
    tree_.validate();
    if (!tree_.stores_points_in_tree_order()) throw Error("KdTreeBlock::validate: points not in tree order");
    if (dead_.size() != size()) throw Error("KdTreeBlock::validate: dead flags of the wrong size");
    if (std::size_t(std::count(dead_.begin(), dead_.end(), 1)) != dead_count_)
      throw Error("KdTreeBlock::validate: dead count is wrong");
  }

 private:
  Tree tree_;
  std::vector<std::uint8_t> dead_;  // by slot
  std::size_t dead_count_ = 0;
};

struct DynamicKdTreeStats {
  DynamizedStats structure;
  std::size_t bytes = 0;  // blocks and locator
};

/// Dim is the dimension, or spatial::Dynamic for one given at run time.
template <typename T, int Dim>
class DynamicKdTree {
 public:
  using Block = KdTreeBlock<T, Dim>;
  /// A point: std::array<T, Dim>, or std::vector<T> for a run-time dimension.
  using Point = typename Block::Item;
  /// An item (index: its id) and its squared distance; results are sorted by distance, ties by id.
  using Neighbor = spatial::Neighbor<T, Id>;
  /// The archive kind and layout version of a saved tree (save / load).
  static constexpr std::string_view kArchiveKind = "dynamic.KdTree";
  static constexpr std::uint32_t kArchiveVersion = 1;

  explicit DynamicKdTree(DynamizeOptions options = {})
    requires(Dim != spatial::Dynamic)
      : dim_(std::size_t(Dim)), tree_(options) {}
  /// A tree of points of dimension `dim` (>= 1), given at run time.
  explicit DynamicKdTree(std::size_t dim, DynamizeOptions options = {})
      : dim_(dim), tree_(options) {
    if (dim == 0 || (Dim != spatial::Dynamic && dim != std::size_t(Dim)))
      throw Error("DynamicKdTree: dim must be " +
                  (Dim == spatial::Dynamic ? std::string(">= 1") : std::to_string(Dim)) + ", got " +
                  std::to_string(dim));
  }

  std::size_t size() const { return tree_.size(); }
  bool empty() const { return tree_.size() == 0; }
  std::size_t dim() const { return dim_; }
  bool contains(Id id) const { return tree_.contains(id); }
  /// The coordinates of a stored item; throws for an id not stored.
  Point point(Id id) const {
    const auto [block, slot] = tree_.locate(id);
    if (!block) throw Error("DynamicKdTree::point: id " + std::to_string(id) + " is not stored");
    return block->item(slot);
  }

  /// Inserts the points (rows of a view of dimension dim()); returns their ids.
  /// All are checked first: a wrong dimension or a NaN/inf coordinate throws
  /// geods::Error and inserts nothing.
  std::vector<Id> insert(spatial::PointView<T> points) {
    if (points.dim != dim_)
      throw Error("DynamicKdTree::insert: points of dimension " + std::to_string(points.dim) + ", the tree has " +
                  std::to_string(dim_));
    if (points.count > 0 && (points.data == nullptr || points.stride < points.dim))
      throw Error("DynamicKdTree::insert: bad point array");
    if (size() + tree_.dead() + points.count >= std::numeric_limits<std::uint32_t>::max())
      throw Error("DynamicKdTree::insert: more than 2^32 - 2 points");
    std::vector<Point> items(points.count);
    for (std::size_t i = 0; i < points.count; ++i) {
      if constexpr (Dim == spatial::Dynamic) items[i].resize(dim_);
      for (std::size_t a = 0; a < dim_; ++a) {
        if (!std::isfinite(points[i][a]))
          throw Error("DynamicKdTree::insert: point " + std::to_string(i) + " has a non-finite coordinate (axis " +
                      std::to_string(a) + ")");
        items[i][a] = points[i][a];
      }
    }
    return tree_.insert(std::move(items));
  }
  Id insert(const Point& p) { return insert(spatial::PointView<T>(p.data(), 1, p.size())).front(); }

  /// Removes the items; throws geods::Error (removing nothing) for an id not stored or given twice.
  void remove(std::span<const Id> ids) { tree_.remove(ids); }
  void remove(Id id) { tree_.remove(id); }
  /// Global reconstruction now: drops dead points and returns their memory.
  void rebuild() { tree_.rebuild(); }

  /// The request.k nearest stored points to q, sorted by distance, ties by id;
  /// fewer if fewer are stored or request.max_distance excludes them; with
  /// request.eps > 0 the i-th distance is within (1 + eps) of the true i-th
  /// (as spatial::KdTree). All blocks share one k-best list, so later blocks
  /// prune with what earlier ones found.
  std::vector<Neighbor> query(std::span<const T> q, const spatial::KnnRequest& request) const {
    std::vector<Neighbor> out(spatial::check_request(request, "DynamicKdTree::query"));
    out.resize(query_into(q, request, out.data()));
    return out;
  }
  std::vector<Neighbor> query(std::span<const T> q, std::size_t k, double eps = 0) const {
    return query(q, spatial::KnnRequest{k, eps});
  }
  std::vector<Neighbor> query(const Point& q, std::size_t k, double eps = 0) const {
    return query(std::span<const T>(q.data(), q.size()), spatial::KnnRequest{k, eps});
  }

  /// Writes request.k slots (unused ones {kNoId, +inf}); returns how many were found.
  std::size_t query_into(std::span<const T> q, const spatial::KnnRequest& request, Neighbor* out) const {
    const std::size_t k = spatial::check_request(request, "DynamicKdTree::query");
    check_point(q, "query point");
    spatial::KnnResultSet<T, Id> best(out, k, spatial::squared_limit<T>(request.max_distance));
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      if (block.all_dead()) return;
      BlockResult result{best, ids.data()};
      block.tree().search_nearest(q.data(), result, request.eps, block.dead_slots());
    });
    best.finish();
    return best.size();
  }

  /// request.k slots per query, query i at [i * k, (i + 1) * k); queries run in parallel.
  std::vector<Neighbor> query_batch(spatial::PointView<T> queries, const spatial::KnnRequest& request) const {
    const std::size_t k = spatial::check_request(request, "DynamicKdTree::query");
    if (queries.dim != dim_ || (queries.count > 0 && (!queries.data || queries.stride < queries.dim)))
      throw Error("DynamicKdTree::query: queries of dimension " + std::to_string(queries.dim) + ", the tree has " +
                  std::to_string(dim_));
    std::vector<Neighbor> out(queries.count * k);
    parallel_for(0, queries.count, 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) query_into(std::span<const T>(queries[i], dim_), request, out.data() + i * k);
    });
    return out;
  }
  std::vector<Neighbor> query_batch(spatial::PointView<T> queries, std::size_t k, double eps = 0) const {
    return query_batch(queries, spatial::KnnRequest{k, eps});
  }

  /// Every stored point within distance r of q (inclusive), sorted like query.
  std::vector<Neighbor> query_radius(std::span<const T> q, double r) const {
    check_point(q, "query point");
    if (!(r >= 0)) throw Error("DynamicKdTree::query_radius: radius must be >= 0, got " + std::to_string(r));
    const T r2 = spatial::squared_limit<T>(r);
    std::vector<Neighbor> out;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      if (block.all_dead()) return;
      block.tree().search_radius(
          q.data(), r2, [&](std::uint32_t slot, T d) { out.push_back({ids[slot], d}); }, block.dead_slots());
    });
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<Neighbor> query_radius(const Point& q, double r) const {
    return query_radius(std::span<const T>(q.data(), q.size()), r);
  }

  /// Ids (ascending) of the stored points p with lo <= p <= hi on every axis.
  std::vector<Id> query_box(std::span<const T> lo, std::span<const T> hi) const {
    check_point(lo, "box low corner");
    check_point(hi, "box high corner");
    std::vector<Id> out;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      if (block.all_dead()) return;
      block.tree().search_box(
          lo.data(), hi.data(), [&](std::uint32_t slot) { out.push_back(ids[slot]); }, block.dead_slots());
    });
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<Id> query_box(const Point& lo, const Point& hi) const {
    return query_box(std::span<const T>(lo.data(), lo.size()), std::span<const T>(hi.data(), hi.size()));
  }

  // ---------------------------------------------------------------- files
  /// Writes the tree as a "dynamic.KdTree" archive (core/archive.hpp): value
  /// sections scalar, dim, variant, max_dead_fraction, next_id, blocks;
  /// per block k, under the prefix "b<k>.", the k-d tree's sections
  /// (KdTree::add_sections), its ids (slot -> id, kNoId if deleted) and its
  /// dead flags. Builds and reconstructions under way are not saved: their
  /// items are in the blocks that answer queries, and load() starts them again.
  void save(const std::filesystem::path& path) const {
    ArchiveWriter w(std::string(kArchiveKind), kArchiveVersion);
    w.add_dtype("scalar", dtype_of<T>());
    w.add_value("dim", std::uint64_t(dim_));
    w.add_value("variant", std::uint32_t(tree_.options().variant));
    w.add_value("max_dead_fraction", tree_.options().max_dead_fraction);
    w.add_value("next_id", std::uint64_t(tree_.next_id()));
    std::uint64_t blocks = 0;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      const std::string prefix = "b" + std::to_string(blocks++) + ".";
      block.tree().add_sections(w, prefix);
      w.add(prefix + "ids", ids);
      w.add(prefix + "dead", block.dead_flags());
    });
    w.add_value("blocks", blocks);
    w.write(path);
  }

  /// Reads a tree written by save(): same ids, points, deletions and answers;
  /// later inserts continue the ids. The file is mapped while it is read.
  /// Throws geods::Error naming the file for another scalar type or
  /// dimension, a truncated or corrupt file or contents that fail validate().
  static DynamicKdTree load(const std::filesystem::path& path) {
    const Archive a = Archive::open(path, kArchiveKind, kArchiveVersion);
    a.require_dtype<T>("scalar", "dynamic k-d tree");
    const std::uint64_t dim = a.value<std::uint64_t>("dim");
    if (dim == 0 || dim > (1u << 16) || (Dim != spatial::Dynamic && dim != std::uint64_t(Dim)))
      throw a.error("a dynamic k-d tree of dimension " + std::to_string(dim) + ", expected " +
                    (Dim == spatial::Dynamic ? std::string("1 to 65536") : std::to_string(Dim)));
    const std::uint32_t variant = a.value<std::uint32_t>("variant");
    if (variant > std::uint32_t(Variant::worst_case)) throw a.error("bad variant " + std::to_string(variant));
    const DynamizeOptions options{Variant(variant), a.value<double>("max_dead_fraction")};
    const std::uint64_t blocks = a.value<std::uint64_t>("blocks");
    std::vector<std::pair<Block, std::vector<Id>>> parts;
    for (std::uint64_t k = 0; k < blocks; ++k) {
      const std::string prefix = "b" + std::to_string(k) + ".";
      Block block = Block::adopt(spatial::KdTree<T, Dim>::from_sections(a, prefix, std::size_t(dim)));
      std::vector<Id> ids = a.array<Id>(prefix + "ids", block.size()).to_vector();
      const FlatArray<std::uint8_t> dead = a.array<std::uint8_t>(prefix + "dead", block.size());
      for (std::size_t slot = 0; slot < ids.size(); ++slot)
        if ((dead[slot] != 0) != (ids[slot] == kNoId))
          throw a.error("block " + std::to_string(k) + ": dead flags and ids disagree at slot " + std::to_string(slot));
      parts.emplace_back(std::move(block), std::move(ids));
    }
    try {
      DynamicKdTree tree(std::size_t(dim), options);
      tree.tree_ = Dynamized<Block>::restore(options, std::move(parts), a.value<std::uint64_t>("next_id"));
      tree.validate();
      return tree;
    } catch (const Error& e) {
      throw a.error(std::string("corrupted dynamic k-d tree: ") + e.what());
    }
  }

  /// The decomposition and the locator (Dynamized::validate), and every block.
  void validate() const { tree_.validate(); }

  DynamicKdTreeStats stats() const {
    DynamicKdTreeStats s;
    s.structure = tree_.stats();
    s.bytes = s.structure.locator_bytes;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) { s.bytes += block.bytes() + ids.size_bytes(); });
    return s;
  }

  const Dynamized<Block>& structure() const { return tree_; }

 private:
  // What a block's search_nearest talks to: its slots mapped to ids in the shared k-best list.
  struct BlockResult {
    spatial::KnnResultSet<T, Id>& best;
    const Id* ids;
    T worst() const { return best.worst(); }
    bool full() const { return best.full(); }
    void insert(std::uint32_t slot, T d) { best.insert(ids[slot], d); }
  };

  void check_point(std::span<const T> q, const char* what) const {
    if (q.size() != dim_)
      throw Error(std::string("DynamicKdTree: ") + what + " of dimension " + std::to_string(q.size()) +
                  ", the tree has " + std::to_string(dim_));
    for (T x : q)
      if (!std::isfinite(x)) throw Error(std::string("DynamicKdTree: ") + what + " has a non-finite coordinate");
  }

  std::size_t dim_;
  Dynamized<Block> tree_;
};

}  // namespace geods::dynamic
