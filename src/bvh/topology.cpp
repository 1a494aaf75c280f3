// build_topology: dispatch to a builder, then renumber the binary tree depth
// first and collapse it to the requested arity.
#include "geods/bvh/topology.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "binary_tree.hpp"
#include "geods/core/error.hpp"

namespace geods::bvh {
namespace {

using detail::BinaryNode;
using detail::BinaryTree;

// Appends the primitives of the subtree at `id` in depth-first leaf order.
void gather_prims(const BinaryTree& tree, std::uint32_t id, std::vector<std::uint32_t>& out,
                  std::vector<std::uint32_t>& stack) {
  stack.clear();
  stack.push_back(id);
  while (!stack.empty()) {
    const BinaryNode& n = tree.nodes[stack.back()];
    stack.pop_back();
    if (n.leaf()) {
      out.insert(out.end(), tree.prims.begin() + n.prim_first, tree.prims.begin() + n.prim_first + n.prim_count);
    } else {
      stack.push_back(n.right);
      stack.push_back(n.left);
    }
  }
}

// Renumbers depth first (so the result does not depend on the order in which
// parallel builders allocated nodes) and opens the largest inner children
// until a node has `arity` children.
Topology finalize(const BinaryTree& tree, int leaf_size, int arity) {
  std::vector<TopoNode> nodes;
  std::vector<std::uint32_t> prim_order;
  prim_order.reserve(tree.prims.size());
  nodes.reserve(tree.nodes.size());
  auto final_leaf = [&](std::uint32_t id) {
    const BinaryNode& n = tree.nodes[id];
    return n.leaf() || (tree.merge_small_subtrees && n.prim_count <= std::uint32_t(leaf_size));
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work;  // (binary node, topology node)
  std::vector<std::uint32_t> scratch;
  nodes.push_back({});
  work.push_back({tree.root, 0});
  std::vector<std::uint32_t> children;
  while (!work.empty()) {
    const auto [b, t] = work.back();
    work.pop_back();
    nodes[t].prim_first = std::uint32_t(prim_order.size());
    nodes[t].prim_count = tree.nodes[b].prim_count;
    if (final_leaf(b)) {
      gather_prims(tree, b, prim_order, scratch);
      continue;
    }
    children = {tree.nodes[b].left, tree.nodes[b].right};
    while (int(children.size()) < arity) {
      int widest = -1;
      float widest_area = -1;
      for (int i = 0; i < int(children.size()); ++i) {
        if (final_leaf(children[i])) continue;
        const float area = tree.nodes[children[i]].box.surface_area();
        if (area > widest_area) widest_area = area, widest = i;
      }
      if (widest < 0) break;
      const BinaryNode& open = tree.nodes[children[widest]];
      children[widest] = open.left;
      children.insert(children.begin() + widest + 1, open.right);
    }
    const auto first = std::uint32_t(nodes.size());
    nodes[t].first_child = first;
    nodes[t].num_children = std::uint32_t(children.size());
    nodes.resize(nodes.size() + children.size());
    for (std::size_t i = children.size(); i-- > 0;) work.push_back({children[i], first + std::uint32_t(i)});
  }
  return {std::move(nodes), std::move(prim_order)};
}

}  // namespace

int Topology::depth() const {
  if (nodes.empty()) return 0;
  // Children always come after their parent, so one forward pass suffices.
  std::vector<int> level(nodes.size(), 0);
  int deepest = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    deepest = std::max(deepest, level[i]);
    for (std::uint32_t c = 0; c < nodes[i].num_children; ++c) level[nodes[i].first_child + c] = level[i] + 1;
  }
  return deepest;
}

Topology build_topology(std::span<const AABB3f> boxes, const BuildOptions& options) {
  check_options(options);
  if (boxes.empty()) return {};
  if (boxes.size() >= (std::size_t(1) << 31)) throw Error("bvh: too many primitives (" + std::to_string(boxes.size()) + ")");
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const AABB3f& b = boxes[i];
    if (!b.lo.allFinite() || !b.hi.allFinite() || b.empty())
      throw Error("bvh: primitive " + std::to_string(i) + " has an empty or non-finite bounding box");
  }
  BinaryTree tree;
  switch (options.builder) {
    case Builder::sah:
    case Builder::median:
    case Builder::pca:
    case Builder::boxtree: tree = detail::build_top_down(boxes, options); break;
    case Builder::bottom_up: tree = detail::build_bottom_up(boxes, options); break;
    case Builder::tiling: tree = detail::build_tiling(boxes, options); break;
    case Builder::insertion: tree = detail::build_insertion(boxes, options); break;
  }
  return finalize(tree, options.leaf_size, options.arity);
}

}  // namespace geods::bvh
