#pragma once
// The fields of AcceleratorStats, named once (see spatial/stats_fields.hpp).
#include <array>
#include <cstdint>

#include "geods/ray/accelerator.hpp"

namespace geods::ray {

/// Calls f(name, value) for each field, in declaration order; the resolution
/// only for the grid, the one accelerator that has cells per axis.
template <typename F>
void for_each_field(const AcceleratorStats& s, F&& f) {
  f("kind", s.kind), f("triangles", s.triangles), f("nodes", s.nodes), f("leaves", s.leaves);
  f("references", s.references), f("depth", s.depth), f("bytes", s.bytes), f("build_s", s.build_s);
  if (s.kind == "grid") f("resolution", std::array<std::uint32_t, 3>{s.resolution[0], s.resolution[1], s.resolution[2]});
}

}  // namespace geods::ray
