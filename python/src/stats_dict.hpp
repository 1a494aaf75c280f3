#pragma once
// A structure's stats() as a Python dict, generated from the library's field
// lists (<module>/stats_fields.hpp) as the CLI's JSON is, so no field is spelled twice.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace geods::python {

/// {name: value} for each field of `stats` (lists for vectors and arrays).
template <typename Stats>
pybind11::dict stats_dict(const Stats& stats) {
  pybind11::dict d;
  for_each_field(stats, [&](const char* name, const auto& value) { d[name] = pybind11::cast(value); });
  return d;
}

}  // namespace geods::python
