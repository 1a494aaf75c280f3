#pragma once
// The fields of the terrain module's stats, named once (see spatial/stats_fields.hpp).
#include "geods/terrain/terrain.hpp"

namespace geods::terrain {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const TerrainStats& s, F&& f) {
  f("width", s.width), f("height", s.height), f("grid", s.grid), f("levels", s.levels), f("slots", s.slots),
      f("unused_slots", s.unused_slots), f("unused_slots_pct", s.unused_slots_pct),
      f("filled_samples", s.filled_samples), f("bytes", s.bytes), f("mapped", s.mapped),
      f("build_s", s.build_s);
}

}  // namespace geods::terrain
