// build_topology: dispatch to a builder, then renumber the binary tree depth
// first and collapse it to the requested arity.
#include "geods/bvh/topology.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <utility>

#include "binary_tree.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::bvh {
namespace {

using detail::BinaryNode;
using detail::BinaryTree;
using detail::BinaryTreeView;

// Appends the primitives of the subtree at `id` in depth-first leaf order.
void gather_prims(const BinaryTreeView& tree, std::uint32_t id, std::vector<std::uint32_t>& out,
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

// Numbers the subtree of binary node `root` depth first into `nodes` (its
// topology node at `root_id`, which the caller has made) and `prim_order`,
// opening the largest inner children until a node has `arity` children. A node
// other than the root for which skip(b) holds gets its topology node but no
// descendants: skipped(b, t) is called instead, in depth-first order.
template <typename Skip, typename Skipped>
void number(const BinaryTreeView& tree, int leaf_size, int arity, std::uint32_t root, std::uint32_t root_id,
            std::vector<TopoNode>& nodes, std::vector<std::uint32_t>& prim_order, const Skip& skip,
            const Skipped& skipped) {
  auto final_leaf = [&](std::uint32_t id) {
    const BinaryNode& n = tree.nodes[id];
    return n.leaf() || (tree.merge_small_subtrees && n.prim_count <= std::uint32_t(leaf_size));
  };
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work;  // (binary node, topology node)
  std::vector<std::uint32_t> scratch;
  work.push_back({root, root_id});
  std::vector<std::uint32_t> children;
  while (!work.empty()) {
    const auto [b, t] = work.back();
    work.pop_back();
    nodes[t].prim_first = std::uint32_t(prim_order.size());
    nodes[t].prim_count = tree.nodes[b].prim_count;
    if (b != root && skip(b)) {
      skipped(b, t);
      continue;
    }
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
}

}  // namespace

// Renumbers depth first (so the result does not depend on the order in which
// parallel builders allocated nodes) and collapses to the arity. With more
// than one thread, the subtrees below a cut near the top are numbered in
// parallel on their own and copied into place: in depth-first order a node's
// descendants are one contiguous run, numbered as on their own.
Topology detail::finalize(const BinaryTreeView& tree, int leaf_size, int arity) {
  std::vector<TopoNode> nodes(1);
  std::vector<std::uint32_t> prim_order;
  prim_order.reserve(tree.prims.size());
  nodes.reserve(tree.nodes.size());
  const std::uint32_t total = tree.nodes[tree.root].prim_count;
  if (num_threads() == 1 || total < 65536) {
    number(tree, leaf_size, arity, tree.root, 0, nodes, prim_order, [](std::uint32_t) { return false; },
           [](std::uint32_t, std::uint32_t) {});
    return {std::move(nodes), std::move(prim_order)};
  }
  const std::uint32_t cut = total / 64;  // about 100 subtrees
  auto below_cut = [&](std::uint32_t b) { return tree.nodes[b].prim_count <= cut; };
  // The top alone, to list the subtrees below the cut in order.
  std::vector<std::uint32_t> roots;
  {
    std::vector<TopoNode> top(1);
    std::vector<std::uint32_t> top_prims;
    number(tree, leaf_size, arity, tree.root, 0, top, top_prims, below_cut,
           [&](std::uint32_t b, std::uint32_t) { roots.push_back(b); });
  }
  struct Part {
    std::vector<TopoNode> nodes;
    std::vector<std::uint32_t> prims;
    std::uint32_t id = 0, first = 0, prim_first = 0;  // its root, its descendants, its primitives
  };
  std::vector<Part> parts(roots.size());
  parallel_for_each_index(0, roots.size(), [&](std::size_t i) {
    parts[i].nodes.resize(1);
    number(tree, leaf_size, arity, roots[i], 0, parts[i].nodes, parts[i].prims, [](std::uint32_t) { return false; },
           [](std::uint32_t, std::uint32_t) {});
  }, 1);
  // The top again, now leaving room for each subtree's descendants and primitives.
  std::size_t next = 0;
  number(tree, leaf_size, arity, tree.root, 0, nodes, prim_order, below_cut, [&](std::uint32_t, std::uint32_t t) {
    Part& part = parts[next++];
    part.id = t;
    part.first = std::uint32_t(nodes.size());
    part.prim_first = std::uint32_t(prim_order.size());
    nodes.resize(nodes.size() + part.nodes.size() - 1);
    prim_order.resize(prim_order.size() + part.prims.size());
  });
  parallel_for_each_index(0, parts.size(), [&](std::size_t i) {
    const Part& part = parts[i];
    for (std::size_t k = 0; k < part.nodes.size(); ++k) {
      TopoNode n = part.nodes[k];
      n.prim_first += part.prim_first;
      if (!n.leaf()) n.first_child += part.first - 1;  // local 1 is the first descendant
      nodes[k == 0 ? part.id : part.first + k - 1] = n;
    }
    std::copy(part.prims.begin(), part.prims.end(), prim_order.begin() + part.prim_first);
  }, 1);
  return {std::move(nodes), std::move(prim_order)};
}

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
  auto bad = [&](std::size_t i) { return !boxes[i].lo.allFinite() || !boxes[i].hi.allFinite() || boxes[i].empty(); };
  std::atomic<bool> any_bad{false};
  parallel_for(0, boxes.size(), 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e && !any_bad.load(std::memory_order_relaxed); ++i)
      if (bad(i)) any_bad = true;
  });
  if (any_bad)  // name the first bad one
    for (std::size_t i = 0; i < boxes.size(); ++i)
      if (bad(i)) throw Error("bvh: primitive " + std::to_string(i) + " has an empty or non-finite bounding box");
  BinaryTree tree;
  switch (options.builder) {
    case Builder::sah:
    case Builder::median:
    case Builder::pca:
    case Builder::boxtree: return detail::build_top_down(boxes, options);
    case Builder::bottom_up: tree = detail::build_bottom_up(boxes, options); break;
    case Builder::tiling: tree = detail::build_tiling(boxes, options); break;
    case Builder::insertion: tree = detail::build_insertion(boxes, options); break;
  }
  return detail::finalize(tree, options.leaf_size, options.arity);
}

}  // namespace geods::bvh
