#pragma once
// Index lists handed to Python as int64 numpy arrays.
#include <pybind11/numpy.h>

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace geods::python {

/// The indices as an int64 array of `shape` (flat when empty). The library's
/// "no index" value (uint32 max: RayHit::no_hit, Delaunay2::no_edge) becomes
/// -1, as numpy users expect of a missing index.
inline pybind11::array_t<std::int64_t> index_array(std::span<const std::uint32_t> ids,
                                                   std::vector<pybind11::ssize_t> shape = {}) {
  if (shape.empty()) shape = {pybind11::ssize_t(ids.size())};
  pybind11::array_t<std::int64_t> out(shape);
  std::int64_t* o = out.mutable_data();
  for (std::size_t i = 0; i < ids.size(); ++i)
    o[i] = ids[i] == std::numeric_limits<std::uint32_t>::max() ? -1 : std::int64_t(ids[i]);
  return out;
}

}  // namespace geods::python
