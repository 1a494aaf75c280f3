// Bottom-up builders (§4.1.1: nearest-neighbour pairing and tiling) and the
// insertion builder (§4.1.2). They start from one leaf per primitive;
// finalize() later turns subtrees of at most leaf_size primitives into leaves.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "binary_tree.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace geods::bvh::detail {
namespace {

BinaryTree leaves_of(std::span<const AABB3f> boxes) {
  BinaryTree tree;
  tree.merge_small_subtrees = true;
  tree.prims.resize(boxes.size());
  std::iota(tree.prims.begin(), tree.prims.end(), 0u);
  tree.nodes.resize(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    tree.nodes[i].box = boxes[i];
    tree.nodes[i].prim_first = std::uint32_t(i);
    tree.nodes[i].prim_count = 1;
  }
  tree.nodes.reserve(2 * boxes.size());
  return tree;
}

std::uint32_t add_parent(BinaryTree& tree, std::uint32_t a, std::uint32_t b) {
  BinaryNode parent;
  parent.left = a;
  parent.right = b;
  parent.box = tree.nodes[a].box;
  parent.box.extend(tree.nodes[b].box);
  parent.prim_count = tree.nodes[a].prim_count + tree.nodes[b].prim_count;
  tree.nodes.push_back(parent);
  return std::uint32_t(tree.nodes.size() - 1);
}

}  // namespace

// Level by level: every node finds its nearest neighbour (box centers, k-d
// tree); in the order of increasing neighbour distance each unpaired node is
// paired with its nearest still unpaired neighbour among the 8 closest, and
// the pairs form the next level (unpaired nodes are carried up unchanged).
BinaryTree build_bottom_up(std::span<const AABB3f> boxes, const BuildOptions&) {
  BinaryTree tree = leaves_of(boxes);
  std::vector<std::uint32_t> level(boxes.size());
  std::iota(level.begin(), level.end(), 0u);
  constexpr std::size_t kCandidates = 8;
  while (level.size() > 1) {
    const std::size_t m = level.size();
    std::vector<float> coords(3 * m);
    for (std::size_t i = 0; i < m; ++i) {
      const Vec3f c = tree.nodes[level[i]].box.center();
      for (int a = 0; a < 3; ++a) coords[3 * i + a] = c[a];
    }
    const spatial::KdTree<float, 3> kd(std::move(coords), 3);
    const std::size_t k = std::min(kCandidates + 1, m);
    std::vector<std::uint32_t> cand(m * kCandidates, kNone);
    std::vector<float> nearest(m, std::numeric_limits<float>::infinity());
    parallel_for_each_index(0, m, [&](std::size_t i) {
      const Vec3f c(kd.point(i)[0], kd.point(i)[1], kd.point(i)[2]);
      std::size_t n = 0;
      for (const auto& nb : kd.query(c, k)) {
        if (nb.index == i || n == kCandidates) continue;
        if (n == 0) nearest[i] = nb.squared_distance;
        cand[i * kCandidates + n++] = nb.index;
      }
    }, 256);
    std::vector<std::uint32_t> order(m);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return nearest[a] < nearest[b] || (nearest[a] == nearest[b] && a < b);
    });
    std::vector<char> paired(m, 0);
    std::vector<std::uint32_t> next;
    next.reserve(m / 2 + 1);
    for (std::uint32_t i : order) {
      if (paired[i]) continue;
      for (std::size_t c = 0; c < kCandidates; ++c) {
        const std::uint32_t j = cand[i * kCandidates + c];
        if (j == kNone) break;
        if (paired[j]) continue;
        paired[i] = paired[j] = 1;
        next.push_back(add_parent(tree, level[i], level[j]));
        break;
      }
    }
    for (std::size_t i = 0; i < m; ++i)
      if (!paired[i]) next.push_back(level[i]);
    level = std::move(next);
  }
  tree.root = level[0];
  return tree;
}

// Tiling (sort-tile-recursive): sort the level along x into S slices, each
// slice along y into S columns, each column along z into tiles of 8 nodes,
// S = ceil(cbrt(n / 8)); the nodes of a tile are joined under one father (a
// small binary subtree, halving the tile in its z order). Repeat per level.
BinaryTree build_tiling(std::span<const AABB3f> boxes, const BuildOptions&) {
  BinaryTree tree = leaves_of(boxes);
  std::vector<std::uint32_t> level(boxes.size());
  std::iota(level.begin(), level.end(), 0u);
  constexpr std::size_t kTile = 8;
  auto sort_axis = [&](std::uint32_t* first, std::uint32_t* last, int axis) {
    std::sort(first, last, [&](std::uint32_t a, std::uint32_t b) {
      const float ca = tree.nodes[a].box.center()[axis], cb = tree.nodes[b].box.center()[axis];
      return ca < cb || (ca == cb && a < b);
    });
  };
  // Joins ids[first, last) under one subtree and returns its root.
  auto join = [&](auto&& self, const std::uint32_t* first, const std::uint32_t* last) -> std::uint32_t {
    if (last - first == 1) return *first;
    const std::uint32_t* mid = first + (last - first) / 2;
    const std::uint32_t a = self(self, first, mid);
    const std::uint32_t b = self(self, mid, last);
    return add_parent(tree, a, b);
  };
  while (level.size() > 1) {
    const std::size_t n = level.size();
    const auto slices = std::size_t(std::ceil(std::cbrt(double((n + kTile - 1) / kTile))));
    std::vector<std::uint32_t> next;
    sort_axis(level.data(), level.data() + n, 0);
    const std::size_t slice_size = (n + slices - 1) / slices;
    for (std::size_t s = 0; s < n; s += slice_size) {
      const std::size_t s_end = std::min(n, s + slice_size);
      sort_axis(level.data() + s, level.data() + s_end, 1);
      const std::size_t column_size = (s_end - s + slices - 1) / slices;
      for (std::size_t c = s; c < s_end; c += column_size) {
        const std::size_t c_end = std::min(s_end, c + column_size);
        sort_axis(level.data() + c, level.data() + c_end, 2);
        for (std::size_t t = c; t < c_end; t += kTile)
          next.push_back(join(join, level.data() + t, level.data() + std::min(c_end, t + kTile)));
      }
    }
    level = std::move(next);
  }
  tree.root = level[0];
  return tree;
}

// Insertion (Goldsmith and Salmon): primitives in a seeded random order
// (a bad early choice cannot be repaired later, and random orders avoid the
// worst cases of sorted input); each descends into the child whose surface
// area grows least and then pairs with the leaf it reaches.
BinaryTree build_insertion(std::span<const AABB3f> boxes, const BuildOptions&) {
  BinaryTree tree = leaves_of(boxes);
  const std::size_t n = boxes.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  Rng rng(0x6765'6f64'73ULL);
  for (std::size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
  std::vector<std::uint32_t> parent(2 * n, kNone);
  std::uint32_t root = order[0];
  for (std::size_t k = 1; k < n; ++k) {
    const std::uint32_t leaf = order[k];
    const AABB3f& b = boxes[leaf];
    std::uint32_t v = root;
    while (!tree.nodes[v].leaf()) {
      const BinaryNode& node = tree.nodes[v];
      auto growth = [&](std::uint32_t c) {
        AABB3f m = tree.nodes[c].box;
        return m.extend(b).surface_area() - tree.nodes[c].box.surface_area();
      };
      v = growth(node.left) <= growth(node.right) ? node.left : node.right;
    }
    const std::uint32_t up = parent[v];
    const std::uint32_t p = add_parent(tree, v, leaf);
    parent[v] = parent[leaf] = p;
    parent[p] = up;
    if (up == kNone) {
      root = p;
    } else {
      BinaryNode& u = tree.nodes[up];
      (u.left == v ? u.left : u.right) = p;
      for (std::uint32_t a = up; a != kNone; a = parent[a]) {
        tree.nodes[a].box.extend(b);
        ++tree.nodes[a].prim_count;
      }
    }
  }
  tree.root = root;
  return tree;
}

}  // namespace geods::bvh::detail
