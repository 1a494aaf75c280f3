#pragma once
// Simultaneous traversal of two hierarchies (seed §4.2's traverse(A, B)):
// node pairs are opened while a predicate says they may interact, and every
// surviving pair of leaves is handed to a callback. The predicate sees node
// indices, so it can test any volumes under any relative transformation;
// collision detection builds on this.
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/bvh/topology.hpp"

namespace geods::bvh {

/// Calls node_pair(i, j) for node i of `a` and node j of `b`, starting at the
/// roots; a pair it accepts is refined (the node covering more primitives is
/// opened; two leaves go to leaf_pair(i, j)). leaf_pair returns void, or bool:
/// false stops the whole traversal. Returns false if it was stopped.
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
      if constexpr (std::is_same_v<decltype(leaf_pair(i, j)), bool>) {
        if (!leaf_pair(i, j)) return false;
      } else {
        leaf_pair(i, j);
      }
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
