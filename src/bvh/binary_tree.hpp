#pragma once
// Private to the builders: the binary tree every builder produces, before it
// is renumbered depth first and collapsed to the requested arity (finalize).
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "geods/bvh/topology.hpp"
#include "geods/core/huge_page_allocator.hpp"

namespace geods::bvh::detail {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

struct BinaryNode {
  AABB3f box;
  std::uint32_t left = kNone, right = kNone;  // kNone: a leaf
  std::uint32_t prim_first = 0;              // leaf: its primitives are prims[prim_first, +prim_count)
  std::uint32_t prim_count = 0;              // leaf: its primitives; inner node: all below it

  bool leaf() const { return left == kNone; }
};

struct BinaryTree {
  // Huge pages: the top-down builders size this for 2 n nodes up front, and
  // page faults on 4 KiB pages were a tenth of a large build.
  std::vector<BinaryNode, HugePageAllocator<BinaryNode>> nodes;
  std::uint32_t root = kNone;
  std::vector<std::uint32_t> prims;
  /// Bottom-up builders make single-primitive leaves: subtrees of at most
  /// leaf_size primitives then become one leaf.
  bool merge_small_subtrees = false;
};

/// A binary tree's nodes and primitives where they are: a BinaryTree's, or the
/// top-down builder's own arrays (no copy into a BinaryTree).
struct BinaryTreeView {
  std::span<const BinaryNode> nodes;
  std::uint32_t root = kNone;
  std::span<const std::uint32_t> prims;
  bool merge_small_subtrees = false;

  BinaryTreeView(std::span<const BinaryNode> n, std::uint32_t r, std::span<const std::uint32_t> p, bool merge)
      : nodes(n), root(r), prims(p), merge_small_subtrees(merge) {}
  BinaryTreeView(const BinaryTree& tree)  // NOLINT(google-explicit-constructor)
      : BinaryTreeView(tree.nodes, tree.root, tree.prims, tree.merge_small_subtrees) {}
};

/// Renumbers depth first and collapses to the arity (topology.cpp).
Topology finalize(const BinaryTreeView& tree, int leaf_size, int arity);

Topology build_top_down(std::span<const AABB3f> boxes, const BuildOptions& options);  // finalized
BinaryTree build_bottom_up(std::span<const AABB3f> boxes, const BuildOptions& options);
BinaryTree build_tiling(std::span<const AABB3f> boxes, const BuildOptions& options);
BinaryTree build_insertion(std::span<const AABB3f> boxes, const BuildOptions& options);

}  // namespace geods::bvh::detail
