#pragma once
// The static k-d tree that Dyn(k-d) (seed §7.4) is made of: one block V_i of
// the binary structure. Same design as spatial::KdTree (median split on the
// axis of widest spread, flat nodes in depth-first order, low/high gap values),
// plus the two operations the dynamization needs and spatial::KdTree does not
// offer:
//  - weak_delete(slot): a dead mark the queries skip, O(1) (WD_k-d of §7.4);
//  - a build that runs in steps (Builder::step), so the worst-case variant
//    (Theorem 14) can spread it over many inserts. The build is one coroutine
//    that pauses every `work` element visits; run to the end it is the plain
//    O(n log n) build.
// Points are stored in tree order next to their slot, so leaves scan
// contiguous memory. Preconditions (checked by DynamicKdTree, not here):
// finite coordinates, fewer than 2^32 - 1 points.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/dynamic/steps.hpp"

namespace geods::dynamic {

template <typename T, int Dim>
class KdBlock {
  static_assert(Dim >= 1, "KdBlock<T, Dim>: a compile-time dimension");

 public:
  using Item = std::array<T, Dim>;
  static constexpr std::uint32_t kLeafSize = 8;

  struct Node {
    std::uint32_t begin, end;  // the node's points are [begin, end) in tree order
    std::uint32_t right;       // inner node: index of the right child (the left one is next); 0 for a leaf
    std::uint32_t axis;
    T low, high;  // inner node: max on `axis` of the left points, min of the right ones
    bool leaf() const { return right == 0; }
  };

  class Builder;

  static KdBlock build(std::vector<Item> items) {
    Builder builder(std::move(items));
    return builder.finish();
  }

  /// Slots, dead ones included.
  std::size_t size() const { return records_.size(); }
  std::size_t dead() const { return dead_count_; }
  /// Every item, dead ones included, in slot order.
  std::vector<Item> extract() const {
    std::vector<Item> out(records_.size());
    for (const Record& r : records_) out[r.slot] = r.point;
    return out;
  }
  const Item& item(std::size_t slot) const { return records_[position_.at(slot)].point; }
  bool is_dead(std::size_t slot) const { return dead_[position_.at(slot)] != 0; }
  void weak_delete(std::size_t slot) {
    if (slot >= records_.size() || dead_[position_[slot]])
      throw Error("KdBlock::weak_delete: slot " + std::to_string(slot) + " is not a live slot");
    dead_[position_[slot]] = 1;
    ++dead_count_;
  }

  /// Feeds the live points that can still improve `result` to result.insert(slot,
  /// squared distance); result.worst() is the squared distance a point must not
  /// exceed. One result can be shared by all blocks, so each prunes with the
  /// best distances found in the blocks before it.
  template <typename Result>
  void nearest(const T* q, Result& result) const {
    if (dead_count_ == records_.size()) return;
    std::array<T, Dim> dists;
    const T mindist = root_distances(q, dists);
    if (mindist <= result.worst() * kSlack) search_nearest(0, q, mindist, dists, result);
  }

  /// Calls f(slot, squared distance) for every live point within squared distance r2 of q.
  template <typename F>
  void within(const T* q, T r2, const F& f) const {
    if (dead_count_ == records_.size()) return;
    std::array<T, Dim> dists;
    const T mindist = root_distances(q, dists);
    if (mindist <= r2 * kSlack) search_within(0, q, mindist, dists, r2, f);
  }

  /// Calls f(slot) for every live point p with lo <= p <= hi.
  template <typename F>
  void in_box(const T* lo, const T* hi, const F& f) const {
    if (dead_count_ == records_.size()) return;
    Item cell_lo = lo_, cell_hi = hi_;
    search_box(0, lo, hi, cell_lo, cell_hi, f);
  }

  /// Heap bytes held (capacities, so memory that was not returned shows).
  std::size_t bytes() const {
    return records_.capacity() * sizeof(Record) + nodes_.capacity() * sizeof(Node) +
           position_.capacity() * sizeof(std::uint32_t) + dead_.capacity();
  }

  /// Checks the tree (depth-first layout, median splits, leaf sizes, every point
  /// in its leaf's cell), the slot <-> position tables and the dead count.
  void validate() const {
    auto fail = [](const std::string& what) { throw Error("KdBlock::validate: " + what); };
    const std::size_t n = records_.size();
    if (position_.size() != n || dead_.size() != n) fail("tables of the wrong size");
    for (std::size_t s = 0; s < n; ++s)
      if (position_[s] >= n || records_[position_[s]].slot != s) fail("slot " + std::to_string(s) + " misplaced");
    if (std::size_t(std::count(dead_.begin(), dead_.end(), 1)) != dead_count_) fail("dead count is wrong");
    if (n == 0) {
      if (!nodes_.empty()) fail("nodes without points");
      return;
    }
    struct Cell {
      std::uint32_t node;
      Item lo, hi;
    };
    std::vector<Cell> stack{{0, lo_, hi_}};
    std::size_t visited = 0, covered = 0;
    while (!stack.empty()) {
      Cell it = stack.back();
      stack.pop_back();
      if (++visited > nodes_.size() || it.node >= nodes_.size()) fail("nodes do not form a tree");
      const Node& node = nodes_[it.node];
      if (node.begin >= node.end || node.end > n) fail("bad point range");
      if (node.leaf()) {
        if (node.end - node.begin > kLeafSize || node.begin != covered) fail("bad leaf");
        covered = node.end;
        for (std::uint32_t i = node.begin; i < node.end; ++i)
          for (int a = 0; a < Dim; ++a)
            if (!(records_[i].point[a] >= it.lo[a] && records_[i].point[a] <= it.hi[a]))
              fail("a point lies outside its leaf's cell");
        continue;
      }
      const std::uint32_t mid = node.begin + (node.end - node.begin) / 2;
      if (node.end - node.begin <= kLeafSize || node.axis >= std::uint32_t(Dim) || node.right <= it.node + 1 ||
          node.right >= nodes_.size() || !(node.low <= node.high))
        fail("bad inner node " + std::to_string(it.node));
      if (nodes_[it.node + 1].begin != node.begin || nodes_[it.node + 1].end != mid ||
          nodes_[node.right].begin != mid || nodes_[node.right].end != node.end)
        fail("children do not split their parent at the median");
      Cell l{it.node + 1, it.lo, it.hi}, r{node.right, it.lo, it.hi};
      l.hi[node.axis] = node.low;
      r.lo[node.axis] = node.high;
      stack.push_back(r);
      stack.push_back(l);
    }
    if (visited != nodes_.size() || covered != n) fail("nodes do not cover the points");
  }

 private:
  struct Record {
    Item point;
    std::uint32_t slot;
  };
  // Keeps exact ties from being pruned by rounding in the incremental distance (as spatial::KdTree).
  static constexpr T kSlack = T(1) + T(4 * (Dim + 2)) * std::numeric_limits<T>::epsilon();

  static T squared_distance(const T* q, const Item& p) {
    T d = 0;
    for (int a = 0; a < Dim; ++a) d += (q[a] - p[a]) * (q[a] - p[a]);
    return d;
  }

  T root_distances(const T* q, std::array<T, Dim>& dists) const {
    T sum = 0;
    for (int a = 0; a < Dim; ++a) {
      const T t = q[a] < lo_[a] ? lo_[a] - q[a] : q[a] > hi_[a] ? q[a] - hi_[a] : T(0);
      dists[a] = t * t;
      sum += dists[a];
    }
    return sum;
  }

  // mindist bounds the squared distance from q to node v's cell; dists holds its per-axis terms.
  template <typename Result>
  void search_nearest(std::uint32_t v, const T* q, T mindist, std::array<T, Dim>& dists, Result& result) const {
    const Node& node = nodes_[v];
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; ++i)
        if (!dead_[i]) result.insert(records_[i].slot, squared_distance(q, records_[i].point));
      return;
    }
    const T to_low = q[node.axis] - node.low, to_high = node.high - q[node.axis];
    const bool left_first = to_low <= to_high;
    const T cut = left_first ? to_high * to_high : to_low * to_low;
    search_nearest(left_first ? v + 1 : node.right, q, mindist, dists, result);
    const T old = dists[node.axis];
    mindist += cut - old;
    if (mindist <= result.worst() * kSlack) {
      dists[node.axis] = cut;
      search_nearest(left_first ? node.right : v + 1, q, mindist, dists, result);
      dists[node.axis] = old;
    }
  }

  template <typename F>
  void search_within(std::uint32_t v, const T* q, T mindist, std::array<T, Dim>& dists, T r2, const F& f) const {
    const Node& node = nodes_[v];
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        if (dead_[i]) continue;
        const T d = squared_distance(q, records_[i].point);
        if (d <= r2) f(records_[i].slot, d);
      }
      return;
    }
    const T to_low = q[node.axis] - node.low, to_high = node.high - q[node.axis];
    const bool left_first = to_low <= to_high;
    const T cut = left_first ? to_high * to_high : to_low * to_low;
    search_within(left_first ? v + 1 : node.right, q, mindist, dists, r2, f);
    const T old = dists[node.axis];
    mindist += cut - old;
    if (mindist <= r2 * kSlack) {
      dists[node.axis] = cut;
      search_within(left_first ? node.right : v + 1, q, mindist, dists, r2, f);
      dists[node.axis] = old;
    }
  }

  // cell_lo/cell_hi bound node v's points; restored on return.
  template <typename F>
  void search_box(std::uint32_t v, const T* lo, const T* hi, Item& cell_lo, Item& cell_hi, const F& f) const {
    bool inside = true;
    for (int a = 0; a < Dim; ++a) {
      if (cell_lo[a] > hi[a] || cell_hi[a] < lo[a]) return;
      inside = inside && lo[a] <= cell_lo[a] && cell_hi[a] <= hi[a];
    }
    const Node& node = nodes_[v];
    if (inside || node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        if (!dead_[i] && (inside || contains(lo, hi, records_[i].point))) f(records_[i].slot);
      }
      return;
    }
    const T saved_hi = cell_hi[node.axis];
    cell_hi[node.axis] = node.low;
    search_box(v + 1, lo, hi, cell_lo, cell_hi, f);
    cell_hi[node.axis] = saved_hi;
    const T saved_lo = cell_lo[node.axis];
    cell_lo[node.axis] = node.high;
    search_box(node.right, lo, hi, cell_lo, cell_hi, f);
    cell_lo[node.axis] = saved_lo;
  }

  static bool contains(const T* lo, const T* hi, const Item& p) {
    for (int a = 0; a < Dim; ++a)
      if (!(lo[a] <= p[a] && p[a] <= hi[a])) return false;
    return true;
  }

  std::vector<Record> records_;          // tree order
  std::vector<Node> nodes_;              // depth first, root at 0
  std::vector<std::uint32_t> position_;  // slot -> tree order
  std::vector<std::uint8_t> dead_;       // tree order
  std::size_t dead_count_ = 0;
  Item lo_{}, hi_{};  // bounds of all points
};

/// Builds a KdBlock in steps: step(work) visits about `work` points and returns
/// true once the tree is complete; finish() completes it if needed and returns it.
template <typename T, int Dim>
class KdBlock<T, Dim>::Builder {
 public:
  explicit Builder(std::vector<Item> items) : state_(std::make_unique<State>()) {
    if (items.size() >= std::numeric_limits<std::uint32_t>::max()) throw Error("KdBlock: too many points");
    state_->items = std::move(items);
    run_ = run(*state_);
  }

  /// Element visits a full build takes, about: one bounds pass and ~3 partition passes per tree level.
  std::size_t estimated_work() const {
    const std::size_t n = state_->items.size();
    std::size_t levels = 1;
    while ((std::size_t(kLeafSize) << levels) < n) ++levels;
    return 4 * n * levels + 2 * n + 1;
  }

  bool step(std::size_t work) {
    state_->budget = std::max<std::size_t>(work, 1);
    return run_.resume();
  }

  KdBlock finish() {
    while (!step(std::numeric_limits<std::size_t>::max())) {
    }
    return std::move(state_->block);
  }

 private:
  struct State {
    std::vector<Item> items;
    KdBlock block;
    std::size_t budget = 0;
  };

  // The build, top to bottom: the items are copied into records; nodes are made
  // in depth-first order from a stack of point ranges; each is bounded, then split
  // at the median of its widest axis by quickselect (Hoare partitions around a
  // median of three); a node's low/high are set when its children compute their
  // bounds; last, the slot -> position table. Every loop pauses when the budget
  // is spent, so no step does more than about `work` element visits.
  static Steps run(State& s) {
    std::vector<Record>& rec = s.block.records_;
    std::vector<Node>& nodes = s.block.nodes_;
    const std::uint32_t n = std::uint32_t(s.items.size());
    std::size_t used = 0;
    rec.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      rec[i] = {s.items[i], i};
      if (++used >= s.budget) {
        used = 0;
        co_yield Steps::pause;
      }
    }
    s.items = {};
    constexpr std::uint32_t kRoot = std::numeric_limits<std::uint32_t>::max();
    struct Range {
      std::uint32_t begin, end, parent;
      bool right;
    };
    std::vector<Range> stack;
    if (n > 0) stack.push_back({0, n, kRoot, false});
    while (!stack.empty()) {
      const Range r = stack.back();
      stack.pop_back();
      const std::uint32_t v = std::uint32_t(nodes.size());
      nodes.push_back(Node{r.begin, r.end, 0, 0, T(0), T(0)});
      if (r.parent != kRoot && r.right) nodes[r.parent].right = v;

      Item lo = rec[r.begin].point, hi = lo;
      for (std::uint32_t i = r.begin + 1; i < r.end; ++i) {
        for (int a = 0; a < Dim; ++a) {
          lo[a] = std::min(lo[a], rec[i].point[a]);
          hi[a] = std::max(hi[a], rec[i].point[a]);
        }
        if (++used >= s.budget) {
          used = 0;
          co_yield Steps::pause;
        }
      }
      if (r.parent == kRoot) {
        s.block.lo_ = lo;
        s.block.hi_ = hi;
      } else if (r.right) {
        nodes[r.parent].high = lo[nodes[r.parent].axis];
      } else {
        nodes[r.parent].low = hi[nodes[r.parent].axis];
      }
      if (r.end - r.begin <= kLeafSize) continue;

      std::uint32_t axis = 0;
      for (int a = 1; a < Dim; ++a)
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = std::uint32_t(a);
      nodes[v].axis = axis;
      auto key = [&](std::uint32_t i) { return rec[i].point[axis]; };
      const std::uint32_t mid = r.begin + (r.end - r.begin) / 2;
      std::uint32_t a = r.begin, b = r.end;  // [a, b) holds the median position; left of a is smaller, right of b larger
      while (b - a > 16) {
        const std::uint32_t m = a + (b - a) / 2, z = b - 1;
        const std::uint32_t median = key(a) < key(m) ? (key(m) < key(z) ? m : key(a) < key(z) ? z : a)
                                                     : (key(a) < key(z) ? a : key(m) < key(z) ? z : m);
        std::swap(rec[a], rec[median]);
        const T pivot = key(a);
        std::int64_t i = std::int64_t(a) - 1, j = b;
        while (true) {
          do {
            ++i;
            if (++used >= s.budget) {
              used = 0;
              co_yield Steps::pause;
            }
          } while (key(std::uint32_t(i)) < pivot);
          do {
            --j;
            if (++used >= s.budget) {
              used = 0;
              co_yield Steps::pause;
            }
          } while (key(std::uint32_t(j)) > pivot);
          if (i >= j) break;
          std::swap(rec[i], rec[j]);
        }
        // Now [a, j] <= pivot <= [j + 1, b), both parts non-empty.
        if (mid <= std::uint32_t(j)) {
          b = std::uint32_t(j) + 1;
        } else {
          a = std::uint32_t(j) + 1;
        }
      }
      std::sort(rec.begin() + a, rec.begin() + b, [axis](const Record& x, const Record& y) {
        return x.point[axis] < y.point[axis];
      });
      stack.push_back({mid, r.end, v, true});
      stack.push_back({r.begin, mid, v, false});
    }
    nodes.shrink_to_fit();
    s.block.position_.resize(n);
    s.block.dead_.assign(n, 0);
    for (std::uint32_t i = 0; i < n; ++i) {
      s.block.position_[rec[i].slot] = i;
      if (++used >= s.budget) {
        used = 0;
        co_yield Steps::pause;
      }
    }
  }

  std::unique_ptr<State> state_;  // on the heap: the coroutine keeps a reference across moves of the Builder
  Steps run_;                     // declared after state_, so destroyed before it
};

}  // namespace geods::dynamic
