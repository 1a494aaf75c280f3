#pragma once
// The fields of the texture module's stats, named once (see spatial/stats_fields.hpp).
#include "geods/texture/neighborhood_index.hpp"
#include "geods/texture/synthesis.hpp"

namespace geods::texture {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const SynthesisStats& s, F&& f) {
  f("width", s.width), f("height", s.height), f("channels", s.channels), f("levels", s.levels),
      f("pixels", s.pixels), f("candidates", s.candidates), f("dimension", s.dimension),
      f("reduced_dimension", s.reduced_dimension), f("full_distances", s.full_distances),
      f("mean_neighborhood_distance", s.mean_neighborhood_distance), f("compute_s", s.compute_s);
}

template <typename F>
void for_each_field(const NeighborhoodIndexStats& s, F&& f) {
  f("candidates", s.candidates), f("dimension", s.dimension), f("reduced_dimension", s.reduced_dimension),
      f("explained_variance", s.explained_variance), f("bytes", s.bytes);
}

}  // namespace geods::texture
