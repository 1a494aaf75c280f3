#pragma once
// The fields of the dynamic module's stats structs, named once (see
// spatial/stats_fields.hpp).
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/dynamic/dynamized.hpp"

namespace geods::dynamic {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const DynamizedStats& s, F&& f) {
  f("live", s.live), f("dead", s.dead), f("structures", s.structures), f("building", s.building);
  f("per_level", s.per_level), f("rebuilds", s.rebuilds), f("forced_builds", s.forced_builds);
  f("reconstructing", s.reconstructing), f("forced_rebuilds", s.forced_rebuilds), f("work", s.work);
  f("locator_bytes", s.locator_bytes);
}

/// The dynamization's fields, then the tree's own.
template <typename F>
void for_each_field(const DynamicKdTreeStats& s, F&& f) {
  for_each_field(s.structure, f);
  f("bytes", s.bytes);
}

}  // namespace geods::dynamic
