#pragma once
// The fields of the spatial module's stats structs, named once: the CLI's JSON,
// the demo and Python's stats() dicts are all generated from these lists.
#include "geods/spatial/kd_tree.hpp"
#include "geods/spatial/quadtree.hpp"

namespace geods::spatial {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const KdTreeStats& s, F&& f) {
  f("points", s.points), f("nodes", s.nodes), f("leaves", s.leaves), f("depth", s.depth), f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const OrthtreeStats& s, F&& f) {
  f("points", s.points), f("nodes", s.nodes), f("leaves", s.leaves), f("empty_leaves", s.empty_leaves);
  f("depth", s.depth), f("bytes", s.bytes);
}

}  // namespace geods::spatial
