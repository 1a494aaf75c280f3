#pragma once
// Meshes given to Python functions as numpy arrays V (n, 3) and F (m, 3).
#include <pybind11/numpy.h>

#include <cstdint>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/tri_mesh.hpp"

namespace geods::python {

/// A TriMesh from V (n, 3) float32 and F (m, 3) int64; `what` names the caller
/// in the geods::Error raised for a wrong shape or an index out of range.
inline TriMesh mesh_from_arrays(
    const pybind11::array_t<float, pybind11::array::c_style | pybind11::array::forcecast>& v,
    const pybind11::array_t<std::int64_t, pybind11::array::c_style | pybind11::array::forcecast>& f,
    const std::string& what) {
  if (v.ndim() != 2 || v.shape(1) != 3) throw Error(what + ": V must be an (n, 3) array");
  if (f.ndim() != 2 || f.shape(1) != 3) throw Error(what + ": F must be an (m, 3) array");
  TriMesh mesh;
  mesh.vertices.resize(std::size_t(v.shape(0)));
  const float* pv = v.data();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) mesh.vertices[i] = Vec3f(pv[3 * i], pv[3 * i + 1], pv[3 * i + 2]);
  mesh.triangles.resize(std::size_t(f.shape(0)));
  const std::int64_t* idx = f.data();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::int64_t i = idx[3 * t + std::size_t(c)];
      if (i < 0 || i >= v.shape(0))
        throw Error(what + ": F[" + std::to_string(t) + "] has vertex index " + std::to_string(i) + " out of range (" +
                    std::to_string(v.shape(0)) + " vertices)");
      mesh.triangles[t][std::size_t(c)] = std::uint32_t(i);
    }
  return mesh;
}

}  // namespace geods::python
