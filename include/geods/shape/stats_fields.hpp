#pragma once
// The fields of the shape module's stats, named once (see spatial/stats_fields.hpp).
#include "geods/shape/retrieval.hpp"
#include "geods/shape/shape_database.hpp"

namespace geods::shape {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const ShapeDatabaseStats& s, F&& f) {
  f("shapes", s.shapes), f("dimension", s.dimension), f("labels", s.labels), f("structures", s.structures),
      f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const RetrievalScores& s, F&& f) {
  f("shapes", s.shapes), f("queries", s.queries), f("classes", s.classes), f("k", s.k), f("nn_rate", s.nn_rate),
      f("precision_at_k", s.precision_at_k), f("first_tier", s.first_tier), f("second_tier", s.second_tier),
      f("mean_average_precision", s.mean_average_precision), f("compute_s", s.compute_s);
}

}  // namespace geods::shape
