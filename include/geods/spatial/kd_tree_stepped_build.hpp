#pragma once
// A KdTree build that runs in steps, for the worst-case dynamization (seed §7.3,
// Theorem 14), which builds its next tree a little at every insert.
//
// The tree is KdTree's: median split on the axis of widest spread, nodes in
// depth-first order with low/high gap values. The build is one coroutine
// (core/steps.hpp) that pauses every `work` element visits: the rows are
// checked and copied; nodes are made in depth-first order from a stack of
// point ranges; each is bounded, then split at its median by quickselect
// (Hoare partitions around a median of three, which can pause where
// std::nth_element cannot); a node's low/high are set when its children
// compute their bounds. Last, the points are renumbered in tree order: the
// finished tree owns them once, in that order (leaves read them contiguously,
// its permutation is the identity), and Result::row says which input row each
// one is. Run to the end it is an O(n log n) build on one thread; KdTree's
// constructors build in parallel, and may order points of equal coordinates
// differently.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/steps.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace geods::spatial {

/// std::array<T, Dim>, or std::vector<T> for Dynamic. A specialization rather
/// than std::conditional_t, which would name std::array<T, -1> (clang rejects it).
template <typename T, int Dim>
struct RowOf {
  using type = std::array<T, std::size_t(Dim)>;
};
template <typename T>
struct RowOf<T, Dynamic> {
  using type = std::vector<T>;
};

template <typename T, int Dim>
class KdTreeSteppedBuild {
 public:
  using Tree = KdTree<T, Dim>;
  /// One input point: std::array<T, Dim>, or std::vector<T> for a run-time dimension.
  using Row = typename RowOf<T, Dim>::type;

  /// A finished build: tree point i is input row row[i].
  struct Result {
    Tree tree;
    std::vector<std::uint32_t> row;
  };

  /// Starts a build over the rows in O(1). The rows are checked during the
  /// steps: a row of another dimension or with a NaN/inf coordinate makes
  /// step() throw geods::Error.
  explicit KdTreeSteppedBuild(std::vector<Row> rows, std::size_t dim = Dim == Dynamic ? 0 : std::size_t(Dim),
                              std::size_t leaf_size = Tree::kDefaultLeafSize)
      : state_(std::make_unique<State>()) {
    if (dim == 0 || (Dim != Dynamic && dim != std::size_t(Dim)))
      throw Error("KdTree: points of dimension " + std::to_string(dim) + ", expected " +
                  (Dim == Dynamic ? std::string(">= 1") : std::to_string(Dim)));
    if (leaf_size == 0 || leaf_size > std::numeric_limits<std::uint32_t>::max())
      throw Error("KdTree: leaf_size must be >= 1");
    if (rows.size() >= std::numeric_limits<std::uint32_t>::max())
      throw Error("KdTree: " + std::to_string(rows.size()) + " points, at most 2^32 - 2 are supported");
    state_->rows = std::move(rows);
    state_->dim = dim;
    state_->leaf_size = leaf_size;
  }

  /// Throws geods::Error unless row i has `dim` finite coordinates (what step() checks of every row).
  static void check_row(const Row& row, std::size_t i, std::size_t dim) {
    if (row.size() != dim)
      throw Error("KdTree: point " + std::to_string(i) + " of dimension " + std::to_string(row.size()) +
                  ", expected " + std::to_string(dim));
    for (std::size_t a = 0; a < dim; ++a)
      if (!std::isfinite(row[a]))
        throw Error("KdTree: point " + std::to_string(i) + " has a non-finite coordinate (axis " +
                    std::to_string(a) + ")");
  }

  /// Element visits a whole build takes, about: one bounds pass and ~3 partition passes per tree level.
  std::size_t estimated_work() const {
    const std::size_t n = state_->rows.size();
    std::size_t levels = 1;
    while ((state_->leaf_size << levels) < n) ++levels;
    return 4 * n * levels + 2 * n + 1;
  }

  /// Does about `work` element visits; returns true once the tree is complete.
  bool step(std::size_t work) {
    if (!started_) run_ = run(*state_), started_ = true;
    state_->budget = std::max<std::size_t>(work, 1);
    return run_.resume();
  }

  /// Completes the build if needed and hands the tree over. If no step ran,
  /// the whole build runs at once without pauses: KdTree's own recursion
  /// (its median selection), about three times faster than the steps, the same
  /// tree up to the order of points of equal coordinates.
  Result finish() {
    if (!started_) return build_at_once(*state_);
    while (!step(std::numeric_limits<std::size_t>::max())) {
    }
    return {std::move(state_->tree), std::move(state_->row)};
  }

 private:
  struct State {
    std::vector<Row> rows;
    std::size_t dim = 0, leaf_size = 0;
    Tree tree;
    std::vector<std::uint32_t> row;
    std::size_t budget = 0;
  };
  // What the ranges are partitioned over: copies of the points with their row
  // for a compile-time dimension (they stream through memory, as in KdTree's own
  // build), row indices into the packed rows for a run-time one.
  struct Record {
    Row p;
    std::uint32_t index;
  };
  using Item = std::conditional_t<Dim == Dynamic, std::uint32_t, Record>;

  // finish() without steps: checks and copies the rows as run() does, then
  // KdTree::Builder (one thread) over them, then the points in tree order.
  static Result build_at_once(State& s) {
    Tree tree;
    tree.leaf_size_ = s.leaf_size;
    const std::size_t dim = Dim == Dynamic ? s.dim : std::size_t(Dim);
    const std::uint32_t n = std::uint32_t(s.rows.size());
    std::vector<std::uint32_t> row(n);
    std::vector<T> ordered(std::size_t(n) * dim);
    if (n > 0) {
      std::map<std::size_t, std::uint32_t> subtree_nodes;
      std::vector<typename Tree::Node> nodes(tree.count_nodes(n, subtree_nodes));
      tree.root_lo_.assign(dim, T(0));
      tree.root_hi_.assign(dim, T(0));
      if constexpr (Dim != Dynamic) {
        std::vector<Record> items(n);
        for (std::uint32_t i = 0; i < n; ++i) {
          check_row(s.rows[i], i, dim);
          items[i] = Record{s.rows[i], i};
        }
        s.rows = {};
        const typename Tree::Builder builder{&tree, nodes.data(), subtree_nodes, false};
        builder.node(items.data(), [](const Record& r) { return r.p.data(); }, 0, 0, n, tree.root_lo_.data(),
                     tree.root_hi_.data());
        for (std::uint32_t i = 0; i < n; ++i) {
          row[i] = items[i].index;
          std::copy_n(items[i].p.data(), dim, ordered.data() + std::size_t(i) * dim);
        }
      } else {
        std::vector<T> packed;
        packed.reserve(std::size_t(n) * dim);
        for (std::uint32_t i = 0; i < n; ++i) {
          check_row(s.rows[i], i, dim);
          packed.insert(packed.end(), s.rows[i].begin(), s.rows[i].end());
        }
        s.rows = {};
        tree.adopt(std::move(packed), dim);  // Builder reads the dimension off the tree's points
        std::iota(row.begin(), row.end(), 0u);
        const typename Tree::Builder builder{&tree, nodes.data(), subtree_nodes, false};
        builder.node(row.data(), [&](std::uint32_t i) { return tree.point(i); }, 0, 0, n, tree.root_lo_.data(),
                     tree.root_hi_.data());
        for (std::uint32_t i = 0; i < n; ++i) std::copy_n(tree.point(row[i]), dim, ordered.data() + std::size_t(i) * dim);
      }
      tree.nodes_ = std::move(nodes);
    }
    std::vector<std::uint32_t> identity(n);
    std::iota(identity.begin(), identity.end(), 0u);
    tree.perm_ = std::move(identity);
    tree.adopt(std::move(ordered), dim);
    return {std::move(tree), std::move(row)};
  }

  static Steps run(State& s) {
    Tree& tree = s.tree;
    const std::size_t dim = Dim == Dynamic ? s.dim : std::size_t(Dim);  // a constant the loops unroll on
    const std::uint32_t n = std::uint32_t(s.rows.size());
    std::size_t used = 0;
    std::vector<T> packed;  // run-time dimension: the rows, which the items index
    std::vector<Item> items;
    if constexpr (Dim == Dynamic) packed.reserve(std::size_t(n) * dim);
    items.reserve(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      const Row& row = s.rows[i];
      check_row(row, i, dim);
      if constexpr (Dim == Dynamic) {
        packed.insert(packed.end(), row.begin(), row.end());
        items.push_back(i);
      } else {
        items.push_back(Record{row, i});
      }
      if (++used >= s.budget) {
        used = 0;
        co_yield Steps::pause;
      }
    }
    s.rows = {};
    tree.leaf_size_ = s.leaf_size;
    auto coords = [&](const Item& item) -> const T* {
      if constexpr (Dim == Dynamic)
        return packed.data() + std::size_t(item) * dim;
      else
        return item.p.data();
    };
    // Built here, handed to the tree at the end.
    std::vector<typename Tree::Node> nodes;
    std::map<std::size_t, std::uint32_t> subtree_nodes;
    if (n > 0) nodes.reserve(tree.count_nodes(n, subtree_nodes));

    constexpr std::uint32_t kRoot = std::numeric_limits<std::uint32_t>::max();
    struct Range {
      std::uint32_t begin, end, parent;
      bool right;
    };
    std::vector<Range> stack;
    if (n > 0) stack.push_back({0, n, kRoot, false});
    std::conditional_t<Dim == Dynamic, std::vector<T>, std::array<T, std::size_t(Dim == Dynamic ? 1 : Dim)>> lo{}, hi{};
    if constexpr (Dim == Dynamic) lo.resize(dim), hi.resize(dim);
    while (!stack.empty()) {
      const Range r = stack.back();
      stack.pop_back();
      const std::uint32_t v = std::uint32_t(nodes.size());
      nodes.push_back(typename Tree::Node{r.begin, r.end, 0, 0, T(0), T(0)});
      if (r.parent != kRoot && r.right) nodes[r.parent].right = v;

      const T* first = coords(items[r.begin]);
      std::copy(first, first + dim, lo.begin());
      std::copy(first, first + dim, hi.begin());
      for (std::uint32_t i = r.begin + 1; i < r.end; ++i) {
        const T* p = coords(items[i]);
        for (std::size_t a = 0; a < dim; ++a) {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
        if (++used >= s.budget) {
          used = 0;
          co_yield Steps::pause;
        }
      }
      if (r.parent == kRoot) {
        tree.root_lo_.assign(lo.begin(), lo.end());
        tree.root_hi_.assign(hi.begin(), hi.end());
      } else if (r.right) {
        nodes[r.parent].high = lo[nodes[r.parent].axis];
      } else {
        nodes[r.parent].low = hi[nodes[r.parent].axis];
      }
      if (r.end - r.begin <= s.leaf_size) continue;

      const std::uint32_t axis = Tree::widest_axis(lo.data(), hi.data(), dim);
      nodes[v].axis = axis;
      auto key = [&](std::uint32_t i) { return coords(items[i])[axis]; };
      const std::uint32_t mid = r.begin + (r.end - r.begin) / 2;
      std::uint32_t a = r.begin, b = r.end;  // [a, b) holds the median position; left of a is smaller, right of b larger
      while (b - a > 16) {
        const std::uint32_t m = a + (b - a) / 2, z = b - 1;
        const std::uint32_t median = key(a) < key(m) ? (key(m) < key(z) ? m : key(a) < key(z) ? z : a)
                                                     : (key(a) < key(z) ? a : key(m) < key(z) ? z : m);
        std::swap(items[a], items[median]);
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
          std::swap(items[i], items[j]);
        }
        // Now [a, j] <= pivot <= [j + 1, b), both parts non-empty.
        if (mid <= std::uint32_t(j)) {
          b = std::uint32_t(j) + 1;
        } else {
          a = std::uint32_t(j) + 1;
        }
      }
      std::sort(items.begin() + a, items.begin() + b,
                [&](const Item& x, const Item& y) { return coords(x)[axis] < coords(y)[axis]; });
      stack.push_back({mid, r.end, v, true});
      stack.push_back({r.begin, mid, v, false});
    }
    std::vector<T> ordered(std::size_t(n) * dim);
    s.row.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      if constexpr (Dim == Dynamic)
        s.row[i] = items[i];
      else
        s.row[i] = items[i].index;
      std::copy_n(coords(items[i]), dim, ordered.data() + std::size_t(i) * dim);
      if (++used >= s.budget) {
        used = 0;
        co_yield Steps::pause;
      }
    }
    std::vector<std::uint32_t> identity(n);
    std::iota(identity.begin(), identity.end(), 0u);
    tree.nodes_ = std::move(nodes);
    tree.perm_ = std::move(identity);
    tree.adopt(std::move(ordered), dim);
  }

  std::unique_ptr<State> state_;  // on the heap: the coroutine keeps a reference across moves of the builder
  Steps run_;                     // declared after state_, so destroyed before it
  bool started_ = false;          // run_ starts at the first step
};

}  // namespace geods::spatial
