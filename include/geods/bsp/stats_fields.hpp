#pragma once
// The fields of BspStats, RayQueryStats and CsgStats, named once (see spatial/stats_fields.hpp).
#include "geods/bsp/csg.hpp"

namespace geods::bsp {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const BspStats& s, F&& f) {
  f("nodes", s.nodes), f("leaves", s.leaves), f("depth", s.depth), f("polygons", s.polygons),
      f("fragments", s.fragments), f("expected_cost", s.expected_cost), f("build_s", s.build_s);
}

template <typename F>
void for_each_field(const RayQueryStats& s, F&& f) {
  f("rays", s.rays), f("hits", s.hits), f("nodes_per_ray", s.nodes_per_ray), f("tests_per_ray", s.tests_per_ray),
      f("query_s", s.query_s);
}

template <typename F>
void for_each_field(const CsgStats& s, F&& f) {
  f("vertices", s.vertices), f("triangles", s.triangles), f("closed", s.closed), f("volume", s.volume),
      f("volume_a", s.volume_a), f("volume_b", s.volume_b), f("bsp_nodes", s.bsp_nodes), f("pieces", s.pieces),
      f("t_junctions", s.t_junctions), f("compute_s", s.compute_s);
}

}  // namespace geods::bsp
