#pragma once
// Traversal of hierarchies, generic over what happens at inner nodes and
// leaves (madmann91/bvh v2's shape): one depth-first loop, `traverse`, over
// any node layout (the Topology of any bounding volume through
// `traverse_topology`, the wide SIMD nodes of TriangleBvh), every query a
// small callback on it; and the simultaneous traversal of two hierarchies
// (seed §4.2's traverse(A, B)) that collision detection builds on.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/bvh/topology.hpp"

// The traversal loops and their callbacks are the hot path of the ray
// queries: they must melt into one function.
// GEODS_BVH_INLINE_LAMBDA goes after a lambda's parameter list.
#if defined(__GNUC__)
#define GEODS_BVH_INLINE_LAMBDA __attribute__((always_inline))
#else
#define GEODS_BVH_INLINE_LAMBDA
#endif
#define GEODS_BVH_INLINE inline GEODS_BVH_INLINE_LAMBDA

namespace geods::bvh {

/// The stack a caller hands to `traverse`: an inline buffer for the usual
/// depths, the heap for the deep trees the insertion builder can make.
/// `capacity` must bound the pending entries: (depth + 2) x arity suffices.
template <typename Entry>
class TraversalStack {
 public:
  explicit TraversalStack(std::size_t capacity) {
    if (capacity > inline_.size()) {
      heap_.resize(capacity);
      data_ = heap_.data();
    }
  }
  TraversalStack(const TraversalStack&) = delete;
  TraversalStack& operator=(const TraversalStack&) = delete;
  /// The bottom of the stack; `traverse` keeps its top in a local pointer
  /// (kept in the object, GCC stored and reloaded it at every push: an
  /// entry's store might alias it).
  Entry* data() { return data_; }

 private:
  std::array<Entry, 256> inline_;
  std::vector<Entry> heap_;
  Entry* data_ = inline_.data();
};

namespace detail {
// A callback returning void never stops; one returning bool stops on false.
template <typename Fn, typename... Args>
GEODS_BVH_INLINE bool keep_going(Fn& fn, Args&&... args) {
  if constexpr (std::is_same_v<decltype(fn(std::forward<Args>(args)...)), bool>) {
    return fn(std::forward<Args>(args)...);
  } else {
    fn(std::forward<Args>(args)...);
    return true;
  }
}
}  // namespace detail

/// Depth-first traversal from `root` (already accepted), on `stack` (its
/// storage: it starts empty), over any node layout
/// whose entries (the nodes waiting to be visited) have a float `key`:
/// - is_leaf(e): whether entry e is a leaf;
/// - children(e, keys): the children of inner node e to visit, as a bit mask
///   (bit i: child i, at most MaxChildren), keys[i] the key child i is
///   ordered by (an entry distance, ...);
/// - child(e, i, key): the entry of child i of e (a good place to prefetch it).
/// With Ordered the nearest child (smallest key) is visited next, the others
/// wait on `stack` farthest first; children of equal keys, and all children
/// without Ordered, are visited last first. A node with one child to visit
/// goes on to it without stack traffic. A leaf goes to leaf(e), which returns
/// void, or bool: false stops the traversal. A waiting entry is visited only
/// if still_needed(e) when its turn comes (a closer hit may have been found
/// since). Returns false if leaf stopped it. `stack` must hold (depth + 2) x
/// MaxChildren entries. Cost: proportional to the nodes visited.
template <int MaxChildren, bool Ordered, typename Entry, typename IsLeaf, typename Children, typename Child,
          typename Leaf, typename StillNeeded>
GEODS_BVH_INLINE bool traverse(Entry root, TraversalStack<Entry>& stack, IsLeaf&& is_leaf, Children&& children,
                               Child&& child, Leaf&& leaf, StillNeeded&& still_needed) {
  static_assert(MaxChildren >= 2 && MaxChildren <= 32, "children are reported as 32-bit masks");
  Entry* const bottom = stack.data();
  Entry* top = bottom;  // one past the last waiting entry
  Entry cur = root;
  for (;;) {
    if (!is_leaf(cur)) {
      float keys[MaxChildren];
      unsigned bits = children(cur, keys);
      if (bits != 0) {
        const int first = __builtin_ctz(bits);
        bits &= bits - 1;
        if (bits == 0) {
          cur = child(cur, first, keys[first]);
          continue;
        }
        if ((bits & (bits - 1)) == 0) {  // two children, the usual case after one: no sort
          const int second = __builtin_ctz(bits);
          const Entry a = child(cur, first, keys[first]);
          const Entry b = child(cur, second, keys[second]);
          // As the general case below: farthest first, equal keys the later
          // child first. (A branch: it mispredicts on about half the
          // incoherent rays, but chosen without one, by a mask on the
          // indices, the next node waited for the keys' comparison: faster
          // on incoherent rays, slower on coherent ones; docs/bvh.md.)
          if (Ordered && a.key < b.key) {
            *top++ = b;
            cur = a;
          } else {
            *top++ = a;
            cur = b;
          }
          continue;
        }
        // Sorted in place on the stack, farthest first, and the last one (the
        // nearest) popped to be visited next. (Sorted in an array first, the
        // copy onto the stack became a memcpy: rep movsq, slow to start.)
        Entry* const start = top;
        *top++ = child(cur, first, keys[first]);
        for (; bits != 0; bits &= bits - 1) {
          const int i = __builtin_ctz(bits);
          const Entry e = child(cur, i, keys[i]);
          Entry* k = top++;
          if constexpr (Ordered) {  // insertion sort: at most MaxChildren
            while (k > start && k[-1].key < keys[i]) {
              *k = k[-1];
              --k;
            }
          }
          *k = e;
        }
        cur = *--top;
        continue;
      }
    } else if (!detail::keep_going(leaf, cur)) {
      return false;
    }
    bool more = false;
    while (!more && top != bottom) {
      cur = *--top;
      more = still_needed(cur);
    }
    if (!more) return true;
  }
}

/// Best-first traversal (branch and bound), the callbacks of `traverse`:
/// every waiting entry is on a min-heap by key, and the entry of smallest
/// key is visited next, so that with keys that are lower bounds of what a
/// subtree can give, no entry is visited whose key is above the final bound
/// (the depth-first order of `traverse` opens many such entries before its
/// bound is tight). still_needed(e) must be monotone in the key: false for the
/// entry taken ends the traversal (every other waiting entry has a key at
/// least as large). `heap` is cleared first and grows as needed. Returns
/// false if leaf stopped it. Cost: O(log n) heap work per entry visited.
template <int MaxChildren, typename Entry, typename IsLeaf, typename Children, typename Child, typename Leaf,
          typename StillNeeded>
GEODS_BVH_INLINE bool traverse_best_first(Entry root, std::vector<Entry>& heap, IsLeaf&& is_leaf, Children&& children,
                                          Child&& child, Leaf&& leaf, StillNeeded&& still_needed) {
  static_assert(MaxChildren >= 2 && MaxChildren <= 32, "children are reported as 32-bit masks");
  const auto later = [](const Entry& x, const Entry& y) { return x.key > y.key; };  // min-heap
  heap.clear();
  Entry cur = root;
  for (;;) {
    if (!is_leaf(cur)) {
      float keys[MaxChildren];
      unsigned bits = children(cur, keys);
      if (bits != 0) {
        // The nearest child goes on without heap traffic if nothing waiting is nearer.
        int near = __builtin_ctz(bits);
        for (unsigned b = bits & (bits - 1); b != 0; b &= b - 1)
          if (keys[__builtin_ctz(b)] < keys[near]) near = __builtin_ctz(b);
        for (unsigned b = bits & ~(1u << near); b != 0; b &= b - 1) {
          const int i = __builtin_ctz(b);
          heap.push_back(child(cur, i, keys[i]));
          std::push_heap(heap.begin(), heap.end(), later);
        }
        const Entry next = child(cur, near, keys[near]);
        if (heap.empty() || !(heap.front().key < next.key)) {
          cur = next;
          continue;
        }
        heap.push_back(next);
        std::push_heap(heap.begin(), heap.end(), later);
      }
    } else if (!detail::keep_going(leaf, cur)) {
      return false;
    }
    if (heap.empty()) return true;
    std::pop_heap(heap.begin(), heap.end(), later);
    cur = heap.back();
    heap.pop_back();
    if (!still_needed(cur)) return true;
  }
}

/// A node of a Topology waiting to be visited, with the key it is ordered by
/// (the entry distance along a ray, a squared distance to a point, ...).
struct NodeRef {
  std::uint32_t node;
  float key;
};

/// Stack capacity for `traverse` over a tree of this depth (Topology::depth())
/// and arity (at most arity - 1 entries wait per level).
inline std::size_t traversal_stack_size(int depth, int arity) { return std::size_t(depth + 2) * std::size_t(arity); }

/// `traverse` over a Topology from node `start` (0: the root). accept(node,
/// key) says whether a node may matter (testing its bounding volume; the
/// root too) and sets its key; with Ordered the accepted children are visited
/// nearest (smallest key) first. leaf(const TopoNode&) sees the leaf's
/// primitive range and returns void or bool (false stops); still_needed(key)
/// re-checks a waiting node. Returns false if leaf stopped the traversal.
template <bool Ordered, typename Accept, typename Leaf, typename StillNeeded>
GEODS_BVH_INLINE bool traverse_topology(const Topology& topology, std::uint32_t start, TraversalStack<NodeRef>& stack,
                                        Accept&& accept, Leaf&& leaf, StillNeeded&& still_needed) {
  NodeRef root{start, 0.0f};
  if (topology.nodes.empty() || !accept(start, root.key)) return true;
  const TopoNode* nodes = topology.nodes.data();
  return traverse<8, Ordered>(
      root, stack, [&](const NodeRef& e) GEODS_BVH_INLINE_LAMBDA { return nodes[e.node].leaf(); },
      [&](const NodeRef& e, float* keys) GEODS_BVH_INLINE_LAMBDA {
        const TopoNode& node = nodes[e.node];
        unsigned bits = 0;
        for (std::uint32_t c = 0; c < node.num_children; ++c) {
          keys[c] = 0.0f;  // for an accept that leaves the key alone
          if (accept(node.first_child + c, keys[c])) bits |= 1u << c;
        }
        return bits;
      },
      [&](const NodeRef& e, int i, float key) GEODS_BVH_INLINE_LAMBDA {
        return NodeRef{nodes[e.node].first_child + std::uint32_t(i), key};
      },
      [&](const NodeRef& e) GEODS_BVH_INLINE_LAMBDA { return leaf(nodes[e.node]); },
      [&](const NodeRef& e) GEODS_BVH_INLINE_LAMBDA { return still_needed(e.key); });
}

/// Calls node_pair(i, j) for node i of `a` and node j of `b`, starting at the
/// roots; a pair it accepts is refined (the node covering more primitives is
/// opened; two leaves go to leaf_pair(i, j)). leaf_pair returns void, or bool:
/// false stops the whole traversal. Returns false if it was stopped.
/// A loop of its own: it walks pairs, in no order, to an unknown depth.
/// Cost: proportional to the accepted node pairs.
template <typename NodePair, typename LeafPair>
bool traverse_simultaneously(const Topology& a, const Topology& b, NodePair&& node_pair, LeafPair&& leaf_pair) {
  if (a.nodes.empty() || b.nodes.empty()) return true;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0u, 0u}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (!node_pair(i, j)) continue;
    const TopoNode& na = a.nodes[i];
    const TopoNode& nb = b.nodes[j];
    if (na.leaf() && nb.leaf()) {
      if (!detail::keep_going(leaf_pair, i, j)) return false;
      continue;
    }
    const bool open_a = !na.leaf() && (nb.leaf() || na.prim_count >= nb.prim_count);
    if (open_a) {
      for (std::uint32_t c = na.num_children; c-- > 0;) stack.push_back({na.first_child + c, j});
    } else {
      for (std::uint32_t c = nb.num_children; c-- > 0;) stack.push_back({i, nb.first_child + c});
    }
  }
  return true;
}

}  // namespace geods::bvh
