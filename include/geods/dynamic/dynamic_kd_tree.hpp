#pragma once
// Dyn(k-d) (seed §7.4): a k-d tree with insert and delete, made of static
// k-d blocks (kd_block.hpp) by the generic dynamization (dynamized.hpp).
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
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/dynamic/dynamized.hpp"
#include "geods/dynamic/kd_block.hpp"
#include "geods/spatial/point_view.hpp"

namespace geods::dynamic {

struct DynamicKdTreeStats {
  DynamizedStats structure;
  std::size_t bytes = 0;  // blocks and locator
};

template <typename T, int Dim>
class DynamicKdTree {
 public:
  using Block = KdBlock<T, Dim>;
  using Point = typename Block::Item;

  /// An item and its squared distance; results are sorted by distance, ties by id.
  struct Neighbor {
    Id id = kNoId;
    T squared_distance = std::numeric_limits<T>::infinity();
    friend bool operator<(const Neighbor& a, const Neighbor& b) {
      return a.squared_distance < b.squared_distance || (a.squared_distance == b.squared_distance && a.id < b.id);
    }
    friend bool operator==(const Neighbor&, const Neighbor&) = default;
  };

  explicit DynamicKdTree(DynamizeOptions options = {}) : tree_(options) {}

  std::size_t size() const { return tree_.size(); }
  bool empty() const { return tree_.size() == 0; }
  static constexpr std::size_t dim() { return Dim; }
  bool contains(Id id) const { return tree_.contains(id); }
  /// The coordinates of a stored item; throws for an id not stored.
  Point point(Id id) const {
    const auto [block, slot] = tree_.locate(id);
    if (!block) throw Error("DynamicKdTree::point: id " + std::to_string(id) + " is not stored");
    return block->item(slot);
  }

  /// Inserts the points (rows of a view of dimension Dim); returns their ids.
  /// All are checked first: a wrong dimension or a NaN/inf coordinate throws
  /// geods::Error and inserts nothing.
  std::vector<Id> insert(spatial::PointView<T> points) {
    if (points.dim != std::size_t(Dim))
      throw Error("DynamicKdTree::insert: points of dimension " + std::to_string(points.dim) + ", the tree has " +
                  std::to_string(Dim));
    if (points.count > 0 && (points.data == nullptr || points.stride < points.dim))
      throw Error("DynamicKdTree::insert: bad point array");
    if (size() + tree_.dead() + points.count >= std::numeric_limits<std::uint32_t>::max())
      throw Error("DynamicKdTree::insert: more than 2^32 - 2 points");
    std::vector<Point> items(points.count);
    for (std::size_t i = 0; i < points.count; ++i)
      for (int a = 0; a < Dim; ++a) {
        if (!std::isfinite(points[i][a]))
          throw Error("DynamicKdTree::insert: point " + std::to_string(i) + " has a non-finite coordinate (axis " +
                      std::to_string(a) + ")");
        items[i][a] = points[i][a];
      }
    return tree_.insert(std::move(items));
  }
  Id insert(const Point& p) { return insert(spatial::PointView<T>(p.data(), 1, Dim)).front(); }

  /// Removes the items; throws geods::Error (removing nothing) for an id not stored or given twice.
  void remove(std::span<const Id> ids) { tree_.remove(ids); }
  void remove(Id id) { tree_.remove(id); }
  /// Global reconstruction now: drops dead points and returns their memory.
  void rebuild() { tree_.rebuild(); }

  /// The k nearest stored points to q, sorted by distance, ties by id (fewer if fewer are stored).
  /// All blocks share one k-best list, so later blocks prune with what earlier ones found.
  std::vector<Neighbor> query(std::span<const T> q, std::size_t k) const {
    if (k == 0) throw Error("DynamicKdTree::query: k must be >= 1");
    std::vector<Neighbor> out(k);
    out.resize(query_into(q, k, out.data()));
    return out;
  }
  std::vector<Neighbor> query(const Point& q, std::size_t k) const { return query(std::span<const T>(q), k); }

  /// Writes k slots (unused ones {kNoId, +inf}); returns how many were found.
  std::size_t query_into(std::span<const T> q, std::size_t k, Neighbor* out) const {
    check_point(q, "query point");
    Best best{out, k};
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      BlockResult result{best, ids.data()};
      block.nearest(q.data(), result);
    });
    for (std::size_t i = best.size; i < k; ++i) out[i] = Neighbor{};
    return best.size;
  }

  /// k slots per query, query i at [i * k, (i + 1) * k); queries run in parallel.
  std::vector<Neighbor> query_batch(spatial::PointView<T> queries, std::size_t k) const {
    if (k == 0) throw Error("DynamicKdTree::query: k must be >= 1");
    if (queries.dim != std::size_t(Dim) || (queries.count > 0 && (!queries.data || queries.stride < queries.dim)))
      throw Error("DynamicKdTree::query: queries of dimension " + std::to_string(queries.dim) + ", the tree has " +
                  std::to_string(Dim));
    std::vector<Neighbor> out(queries.count * k);
    parallel_for(0, queries.count, 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) query_into(std::span<const T>(queries[i], Dim), k, out.data() + i * k);
    });
    return out;
  }

  /// Every stored point within distance r of q (inclusive), sorted like query.
  std::vector<Neighbor> query_radius(std::span<const T> q, double r) const {
    check_point(q, "query point");
    if (!(r >= 0)) throw Error("DynamicKdTree::query_radius: radius must be >= 0, got " + std::to_string(r));
    const T r2 = r * r >= double(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::infinity() : T(r * r);
    std::vector<Neighbor> out;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      block.within(q.data(), r2, [&](std::size_t slot, T d) { out.push_back({ids[slot], d}); });
    });
    std::sort(out.begin(), out.end());
    return out;
  }

  /// Ids (ascending) of the stored points p with lo <= p <= hi on every axis.
  std::vector<Id> query_box(std::span<const T> lo, std::span<const T> hi) const {
    check_point(lo, "box low corner");
    check_point(hi, "box high corner");
    std::vector<Id> out;
    tree_.for_each([&](const Block& block, std::span<const Id> ids) {
      block.in_box(lo.data(), hi.data(), [&](std::size_t slot) { out.push_back(ids[slot]); });
    });
    std::sort(out.begin(), out.end());
    return out;
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
  // The k best so far in a caller's array, sorted; k is small, so insertion beats a heap.
  struct Best {
    Neighbor* slots;
    std::size_t k;
    std::size_t size = 0;
    T worst() const { return size == k ? slots[k - 1].squared_distance : std::numeric_limits<T>::infinity(); }
    void insert(Id id, T d) {
      const Neighbor candidate{id, d};
      std::size_t pos;
      if (size < k) {
        pos = size++;
      } else if (candidate < slots[k - 1]) {
        pos = k - 1;
      } else {
        return;
      }
      for (; pos > 0 && candidate < slots[pos - 1]; --pos) slots[pos] = slots[pos - 1];
      slots[pos] = candidate;
    }
  };
  // What KdBlock::nearest talks to: slots of one block mapped to ids.
  struct BlockResult {
    Best& best;
    const Id* ids;
    T worst() const { return best.worst(); }
    void insert(std::size_t slot, T d) { best.insert(ids[slot], d); }
  };

  static void check_point(std::span<const T> q, const char* what) {
    if (q.size() != std::size_t(Dim))
      throw Error(std::string("DynamicKdTree: ") + what + " of dimension " + std::to_string(q.size()) +
                  ", the tree has " + std::to_string(Dim));
    for (T x : q)
      if (!std::isfinite(x)) throw Error(std::string("DynamicKdTree: ") + what + " has a non-finite coordinate");
  }

  Dynamized<Block> tree_;
};

}  // namespace geods::dynamic
