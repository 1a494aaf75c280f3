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
#include <optional>
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

/// One block V_i of Dyn(k-d): a spatial::KdTree over its items, built in steps
/// (KdTreeSteppedBuild), and one flag per item for the weak delete (WD_k-d of
/// §7.4), which its searches skip. The tree numbers its points in tree order
/// (so it stores them once, leaves contiguous); the block maps them to slots.
///
/// A block of at most kLeafSize items would be a tree of one leaf: it keeps
/// only its points, in slot order, and its searches scan them as that leaf
/// would (same distances). Thirty-one of every thirty-two builds of Dyn (one
/// insert at a time) are of such blocks (its levels 0 to 4), which so skip
/// the tree's arrays. Leaves of 16 points (nanoflann's adaptor: 10) make a
/// build one median split shallower than 8 would, and the queries, which
/// read a leaf's points contiguously, are faster too.
template <typename T, int Dim>
class KdTreeBlock {
 public:
  using Tree = spatial::KdTree<T, Dim>;
  using Item = typename spatial::KdTreeSteppedBuild<T, Dim>::Row;
  static constexpr std::size_t kLeafSize = 16;

  class Builder {
   public:
    explicit Builder(std::vector<Item> items) : dim_(item_dim(items)) {
      if (items.size() <= kLeafSize)
        small_ = pack(items, dim_);
      else
        build_.emplace(std::move(items), dim_, kLeafSize);
    }
    std::size_t estimated_work() const { return build_ ? build_->estimated_work() : small_.size() + 1; }
    bool step(std::size_t work) { return build_ ? build_->step(work) : true; }
    KdTreeBlock finish() {
      if (!build_) return KdTreeBlock(dim_, std::move(small_));
      auto [tree, row] = build_->finish();
      return KdTreeBlock(std::move(tree), FlatArray<std::uint32_t>(std::move(row)));
    }

   private:
    // A block of a run-time dimension takes it from its items (an empty one has none).
    static std::size_t item_dim(const std::vector<Item>& items) {
      if constexpr (Dim == spatial::Dynamic)
        return items.empty() ? 1 : items.front().size();
      else
        return std::size_t(Dim);
    }
    // A small block's points, checked as KdTreeSteppedBuild checks its rows.
    static std::vector<T> pack(const std::vector<Item>& items, std::size_t dim) {
      std::vector<T> packed(items.size() * dim);
      for (std::size_t i = 0; i < items.size(); ++i) {
        spatial::KdTreeSteppedBuild<T, Dim>::check_row(items[i], i, dim);
        std::copy_n(items[i].data(), dim, packed.data() + i * dim);
      }
      return packed;
    }
    std::size_t dim_;
    std::vector<T> small_;
    std::optional<spatial::KdTreeSteppedBuild<T, Dim>> build_;
  };

  static KdTreeBlock build(std::vector<Item> items) { return Builder(std::move(items)).finish(); }
  /// A block read from a file, no slot dead yet: a tree whose point i is in
  /// slot slots[i]. Throws geods::Error if slots is not a permutation of the
  /// tree's points or the tree is small enough to be a small block.
  static KdTreeBlock adopt(Tree tree, FlatArray<std::uint32_t> slots) {
    spatial::require_permutation(slots, tree.size(), "KdTreeBlock: slots");
    if (tree.size() <= kLeafSize) throw Error("KdTreeBlock: a tree of " + std::to_string(tree.size()) + " points");
    return KdTreeBlock(std::move(tree), std::move(slots));
  }
  /// A small block read from a file: at most kLeafSize points (n x dim, in slot order).
  static KdTreeBlock adopt_small(std::size_t dim, std::span<const T> points) {
    if (points.size() % dim != 0 || points.size() / dim > kLeafSize)
      throw Error("KdTreeBlock: " + std::to_string(points.size()) + " coordinates are not a small block");
    return KdTreeBlock(dim, std::vector<T>(points.begin(), points.end()));
  }

  /// Slots, dead ones included.
  std::size_t size() const { return dead_.size(); }
  std::size_t dead() const { return dead_count_; }
  bool all_dead() const { return dead_count_ == size(); }
  /// Whether the block keeps only its points (at most kLeafSize), not a tree.
  bool small() const { return size() <= kLeafSize; }
  /// Every item, dead ones included, in slot order.
  std::vector<Item> extract() const {
    std::vector<Item> out(size());
    for (std::size_t i = 0; i < size(); ++i) out[small() ? i : slot_[i]] = item_at(i);
    return out;
  }
  Item item(std::size_t slot) const { return item_at(position(slot)); }
  bool is_dead(std::size_t slot) const { return dead_.at(position(slot)) != 0; }
  void weak_delete(std::size_t slot) {
    if (slot >= size() || dead_[position(slot)])
      throw Error("KdTreeBlock::weak_delete: slot " + std::to_string(slot) + " is not a live slot");
    dead_[position(slot)] = 1;
    ++dead_count_;
  }

  // The tree's searches (spatial::KdTree) over the live slots, reporting slots.
  /// Feeds result.insert(slot, squared distance) the live points that may improve result.
  template <typename Result>
  void search_nearest(const T* q, Result& result, double eps = 0) const {
    if (small()) {
      for (std::uint32_t slot = 0; slot < size(); ++slot) {
        if (dead_[slot]) continue;
        const T d = spatial::squared_distance(q, point_at(slot), dim());
        if (d <= result.worst()) result.insert(slot, d);
      }
      return;
    }
    struct BySlot {
      Result& result;
      const std::uint32_t* slot;
      T worst() const { return result.worst(); }
      bool full() const { return result.full(); }
      void insert(std::uint32_t i, T d) { result.insert(slot[i], d); }
    } by_slot{result, slot_.data()};
    tree_.search_nearest(q, by_slot, eps, live());
  }
  /// Calls f(slot, squared distance) for every live point within squared distance r2 of q.
  template <typename F>
  void search_radius(const T* q, T r2, const F& f) const {
    if (small()) {
      for (std::uint32_t slot = 0; slot < size(); ++slot) {
        if (dead_[slot]) continue;
        const T d = spatial::squared_distance(q, point_at(slot), dim());
        if (d <= r2) f(slot, d);
      }
      return;
    }
    tree_.search_radius(q, r2, [&](std::uint32_t i, T d) { f(slot_[i], d); }, live());
  }
  /// Calls f(slot) for every live point p with lo <= p <= hi on every axis.
  template <typename F>
  void search_box(const T* lo, const T* hi, const F& f) const {
    if (small()) {
      for (std::uint32_t slot = 0; slot < size(); ++slot) {
        const T* p = point_at(slot);
        bool in = !dead_[slot];
        for (std::size_t a = 0; a < dim() && in; ++a) in = lo[a] <= p[a] && p[a] <= hi[a];
        if (in) f(slot);
      }
      return;
    }
    tree_.search_box(lo, hi, [&](std::uint32_t i) { f(slot_[i]); }, live());
  }

  /// A block that is not small: its tree, whose point i is in slot slots()[i].
  const Tree& tree() const { return tree_; }
  const FlatArray<std::uint32_t>& slots() const { return slot_; }
  /// A small block: its points, n x dim in slot order.
  const std::vector<T>& small_points() const { return small_; }

  /// Heap bytes held.
  std::size_t bytes() const {
    return tree_.bytes() + small_.capacity() * sizeof(T) +
           (slot_.size() + position_.capacity()) * sizeof(std::uint32_t) + dead_.capacity();
  }

  /// The tree's invariants (or a small block's size), the slot maps (inverse
  /// permutations) and the dead flags.
  void validate() const {
    if (small()) {
      if (small_.size() != size() * dim_ || !tree_.empty() || !slot_.empty())
        throw Error("KdTreeBlock::validate: a small block with a tree or points of the wrong size");
    } else {
      tree_.validate();
      if (tree_.size() != size() || slot_.size() != size() || position_.size() != size())
        throw Error("KdTreeBlock::validate: tree or slot maps of the wrong size");
      for (std::size_t i = 0; i < size(); ++i)
        if (slot_[i] >= size() || position_[slot_[i]] != i) throw Error("KdTreeBlock::validate: slot maps disagree");
    }
    if (std::size_t(std::count(dead_.begin(), dead_.end(), 1)) != dead_count_)
      throw Error("KdTreeBlock::validate: dead count is wrong");
  }

 private:
  KdTreeBlock(Tree tree, FlatArray<std::uint32_t> slots)
      : dim_(tree.dim()), tree_(std::move(tree)), slot_(std::move(slots)), position_(tree_.size()),
        dead_(tree_.size(), 0) {
    for (std::size_t i = 0; i < slot_.size(); ++i) position_[slot_[i]] = std::uint32_t(i);
  }
  KdTreeBlock(std::size_t dim, std::vector<T> points)
      : dim_(dim), small_(std::move(points)), dead_(small_.size() / dim, 0) {}

  // Points are addressed by their place in the tree (a small block's: its slot).
  std::size_t position(std::size_t slot) const { return small() ? slot : position_.at(slot); }
  const T* point_at(std::size_t i) const { return small() ? small_.data() + i * dim() : tree_.point(i); }
  std::size_t dim() const { return Dim == spatial::Dynamic ? dim_ : std::size_t(Dim); }
  Item item_at(std::size_t i) const {
    const T* p = point_at(i);
    Item out;
    if constexpr (Dim == spatial::Dynamic) out.resize(dim());
    std::copy(p, p + dim(), out.begin());
    return out;
  }
  spatial::SkipFlagged live() const { return {dead_.data()}; }

  std::size_t dim_ = Dim == spatial::Dynamic ? 1 : std::size_t(Dim);
  Tree tree_;                            // empty in a small block
  std::vector<T> small_;                 // a small block's points, by slot
  FlatArray<std::uint32_t> slot_;        // by tree point: its slot (empty in a small block)
  std::vector<std::uint32_t> position_;  // by slot: its tree point (empty in a small block)
  std::vector<std::uint8_t> dead_;       // by tree point (small block: by slot)
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
  static constexpr std::uint32_t kArchiveVersion = 2;

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
      block.search_nearest(q.data(), result, request.eps);
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
    if (!(r >= 0)) throw Error("DynamicKdTree::query_radius: radius must be >= 0, got " + format_number(r));
    const T r2 = spatial::squared_limit<T>(r);
    std::vector<Neighbor> out;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      if (block.all_dead()) return;
      block.search_radius(q.data(), r2, [&](std::uint32_t slot, T d) { out.push_back({ids[slot], d}); });
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
      block.search_box(lo.data(), hi.data(), [&](std::uint32_t slot) { out.push_back(ids[slot]); });
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
  /// per block k, under the prefix "b<k>.", its ids (slot -> id, kNoId if
  /// deleted), then for a small block (KdTreeBlock) its points, for another
  /// the k-d tree's sections (KdTree::add_sections) and its slots (tree point
  /// -> slot). Builds and reconstructions under way are not saved: their
  /// items are in the blocks that answer queries, and load() starts them again.
  void save(const std::filesystem::path& path) const {
    ArchiveWriter w(std::string(kArchiveKind), kArchiveVersion);
    add_sections(w, "");
    w.write(path);
  }

  /// Adds the tree's sections (those save() writes) to an archive under names
  /// that start with `prefix`, so that another structure's archive can hold
  /// it (shape.ShapeDatabase). The blocks are not copied: the tree must live
  /// until w.write().
  void add_sections(ArchiveWriter& w, const std::string& prefix) const {
    w.add_dtype(prefix + "scalar", dtype_of<T>());
    w.add_value(prefix + "dim", std::uint64_t(dim_));
    w.add_value(prefix + "variant", std::uint32_t(tree_.options().variant));
    w.add_value(prefix + "max_dead_fraction", tree_.options().max_dead_fraction);
    w.add_value(prefix + "next_id", std::uint64_t(tree_.next_id()));
    std::uint64_t blocks = 0;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      const std::string block_prefix = prefix + "b" + std::to_string(blocks++) + ".";
      w.add(block_prefix + "ids", ids);
      if (block.small()) {
        w.add(block_prefix + "points", block.small_points());
      } else {
        block.tree().add_sections(w, block_prefix);
        w.add(block_prefix + "slots", block.slots());
      }
    });
    w.add_value(prefix + "blocks", blocks);
  }

  /// Reads a tree written by save(): same ids, points, deletions and answers;
  /// later inserts continue the ids. The file is mapped while it is read.
  /// Throws geods::Error naming the file for another scalar type or
  /// dimension, a truncated or corrupt file or contents that fail validate().
  static DynamicKdTree load(const std::filesystem::path& path) {
    return from_sections(Archive::open(path, kArchiveKind, kArchiveVersion), "");
  }

  /// The tree add_sections wrote under `prefix`; the blocks' k-d trees are
  /// read in place from the mapped file (KdTree::from_sections). Throws as load().
  static DynamicKdTree from_sections(const Archive& a, const std::string& prefix) {
    a.require_dtype<T>(prefix + "scalar", "dynamic k-d tree");
    const std::uint64_t dim = a.value<std::uint64_t>(prefix + "dim");
    if (dim == 0 || dim > (1u << 16) || (Dim != spatial::Dynamic && dim != std::uint64_t(Dim)))
      throw a.error("a dynamic k-d tree of dimension " + std::to_string(dim) + ", expected " +
                    (Dim == spatial::Dynamic ? std::string("1 to 65536") : std::to_string(Dim)));
    const std::uint32_t variant = a.value<std::uint32_t>(prefix + "variant");
    if (variant > std::uint32_t(Variant::worst_case)) throw a.error("bad variant " + std::to_string(variant));
    const DynamizeOptions options{Variant(variant), a.value<double>(prefix + "max_dead_fraction")};
    const std::uint64_t blocks = a.value<std::uint64_t>(prefix + "blocks");
    std::vector<std::pair<Block, std::vector<Id>>> parts;
    for (std::uint64_t k = 0; k < blocks; ++k) {
      const std::string block_prefix = prefix + "b" + std::to_string(k) + ".";
      std::vector<Id> ids = a.array<Id>(block_prefix + "ids").to_vector();
      std::optional<Block> block;
      if (ids.size() <= Block::kLeafSize && a.has(block_prefix + "nodes")) {
        // Written when blocks of this size were trees (leaves of 8 points): its points by slot make a small block.
        const spatial::KdTree<T, Dim> tree = spatial::KdTree<T, Dim>::from_sections(a, block_prefix, std::size_t(dim));
        const FlatArray<std::uint32_t> slots = a.array<std::uint32_t>(block_prefix + "slots", ids.size());
        a.check([&] {
          spatial::require_permutation(slots, tree.size(), "KdTreeBlock: slots");
          std::vector<T> points(ids.size() * dim);
          for (std::size_t i = 0; i < tree.size(); ++i)
            std::copy_n(tree.point(i), dim, points.data() + std::size_t(slots[i]) * dim);
          block.emplace(Block::adopt_small(std::size_t(dim), points));
        });
      } else if (ids.size() <= Block::kLeafSize) {
        const FlatArray<T> points = a.array<T>(block_prefix + "points", ids.size() * dim);
        a.check([&] { block.emplace(Block::adopt_small(std::size_t(dim), points)); });
      } else {
        spatial::KdTree<T, Dim> tree = spatial::KdTree<T, Dim>::from_sections(a, block_prefix, std::size_t(dim));
        FlatArray<std::uint32_t> slots = a.array<std::uint32_t>(block_prefix + "slots", ids.size());
        a.check([&] { block.emplace(Block::adopt(std::move(tree), std::move(slots))); });
      }
      parts.emplace_back(std::move(*block), std::move(ids));
    }
    try {
      DynamicKdTree tree(std::size_t(dim), options);
      tree.tree_ = Dynamized<Block>::restore(options, std::move(parts), a.value<std::uint64_t>(prefix + "next_id"));
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
