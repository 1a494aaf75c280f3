#pragma once
// The fields of BvhStats, named once (see spatial/stats_fields.hpp).
#include "geods/bvh/triangle_bvh.hpp"

namespace geods::bvh {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const BvhStats& s, F&& f) {
  f("triangles", s.triangles), f("nodes", s.nodes), f("leaves", s.leaves), f("depth", s.depth), f("bytes", s.bytes);
  f("sah_cost", s.sah_cost), f("tightness_volume", s.tightness_volume), f("tightness_hausdorff", s.tightness_hausdorff);
}

}  // namespace geods::bvh
