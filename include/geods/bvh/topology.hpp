#pragma once
// The shape of a hierarchy independent of its bounding volumes: nodes with
// contiguous children and contiguous primitive ranges, built by one of the
// builders of build_options.hpp from the primitives' bounding boxes.
#include <cstdint>
#include <span>
#include <vector>

#include "geods/bvh/build_options.hpp"
#include "geods/core/aabb.hpp"
#include "geods/core/flat_array.hpp"

namespace geods::bvh {

/// Node of a Topology. Inner nodes have num_children > 0 children stored at
/// [first_child, first_child + num_children); leaves have none. Every node
/// covers the primitives at positions [prim_first, prim_first + prim_count)
/// of Topology::prim_order (its leaves are contiguous there).
struct TopoNode {
  std::uint32_t first_child = 0;
  std::uint32_t num_children = 0;
  std::uint32_t prim_first = 0;
  std::uint32_t prim_count = 0;

  bool leaf() const { return num_children == 0; }
};

struct Topology {
  FlatArray<TopoNode> nodes;             // root at 0 (empty for no primitives)
  FlatArray<std::uint32_t> prim_order;  // primitive ids in leaf order

  /// Longest root-to-leaf path in edges (0 for a single leaf).
  int depth() const;
};

/// Builds the hierarchy over primitives given by their boxes (centroid = box
/// center) with options.builder, options.leaf_size and options.arity.
/// Deterministic: the same input gives the same tree for any thread count.
/// Throws geods::Error for empty or non-finite boxes.
Topology build_topology(std::span<const AABB3f> boxes, const BuildOptions& options);

}  // namespace geods::bvh
