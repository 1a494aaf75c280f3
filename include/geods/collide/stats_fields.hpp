#pragma once
// The fields of CollideStats, named once (see spatial/stats_fields.hpp).
#include "geods/collide/collide.hpp"

namespace geods::collide {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const CollideStats& s, F&& f) {
  f("volume_tests", s.volume_tests), f("leaf_pairs", s.leaf_pairs), f("triangle_tests", s.triangle_tests);
}

}  // namespace geods::collide
