#pragma once
// The fields of MinMaxOctreeStats, named once (see spatial/stats_fields.hpp).
#include "geods/iso/min_max_octree.hpp"

namespace geods::iso {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const MinMaxOctreeStats& s, F&& f) {
  f("nodes", s.nodes), f("levels", s.levels), f("leaf_cells", s.leaf_cells), f("cells", s.cells), f("bytes", s.bytes);
}

}  // namespace geods::iso
