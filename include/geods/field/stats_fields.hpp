#pragma once
// The fields of SdfGridStats, named once (see spatial/stats_fields.hpp).
#include "geods/field/morph.hpp"
#include "geods/field/projection.hpp"
#include "geods/field/adf.hpp"
#include "geods/field/sdf_grid.hpp"

namespace geods::field {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const SdfGridStats& s, F&& f) {
  f("samples", s.samples), f("in_band", s.in_band), f("tiles", s.tiles), f("tiles_outside", s.tiles_outside),
      f("candidates_per_sample", s.candidates_per_sample), f("winding_numbers", s.winding_numbers);
}

template <typename F>
void for_each_field(const ProjectionStats& s, F&& f) {
  f("sites", s.sites), f("pixels", s.pixels), f("fragments", s.fragments),
      f("fragments_per_pixel", s.fragments_per_pixel), f("culled_sites", s.culled_sites);
}

template <typename F>
void for_each_field(const MorphStats& s, F&& f) {
  f("samples", s.samples), f("correspondences", s.correspondences), f("rotation_angle", s.rotation_angle),
      f("fit_residual", s.fit_residual);
}

template <typename F>
void for_each_field(const AdfStats& s, F&& f) {
  f("cells", s.cells), f("leaves", s.leaves), f("depth", s.depth), f("unresolved", s.unresolved),
      f("exact_queries", s.exact_queries), f("signs", s.signs), f("corners", s.corners),
      f("value_bits", s.value_bits), f("key_bits", s.key_bits), f("quantum", s.quantum), f("bytes", s.bytes), f("dense_bytes", s.dense_bytes);
}

}  // namespace geods::field
