// Python bindings of field::Adf: adaptively sampled distance fields.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/parallel.hpp"
#include "geods/field/adf.hpp"
#include "geods/field/stats_fields.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

field::Adf adf_build(const Rows<float>& v, const Rows<std::int64_t>& f, double error, int max_depth,
                     const py::object& band, int checks, double padding, const std::string& sign) {
  const TriMesh mesh = mesh_from_arrays(v, f, "Adf");
  field::AdfOptions o;
  o.error = error;
  o.max_depth = max_depth;
  if (!band.is_none()) o.band = py::cast<double>(band);
  o.checks = checks;
  o.padding = padding;
  o.sign = field::parse_sign_method(sign);
  return without_gil([&] { return field::Adf::build(mesh, o); });
}

std::vector<Vec3f> query_points(const py::handle& points) {
  const PointRows<float> rows = point_rows<float>(points, 3, "Adf points", false);
  std::vector<Vec3f> ps(rows.count);
  for (std::size_t i = 0; i < rows.count; ++i) ps[i] = rows.point<3>(i);
  return ps;
}

py::array_t<double> distance_py(const field::Adf& adf, const py::handle& points) {
  const std::vector<Vec3f> ps = query_points(points);
  std::vector<double> d(ps.size());
  without_gil([&] { parallel_for_each_index(0, ps.size(), [&](std::size_t i) { d[i] = adf.distance(ps[i]); }); });
  return copy_array(d.data(), {py::ssize_t(d.size())});
}

template <Vec3f (field::Adf::*Method)(const Vec3f&) const>
py::array_t<float> vectors_py(const field::Adf& adf, const py::handle& points) {
  const std::vector<Vec3f> ps = query_points(points);
  std::vector<Vec3f> out(ps.size());
  without_gil([&] { parallel_for_each_index(0, ps.size(), [&](std::size_t i) { out[i] = (adf.*Method)(ps[i]); }); });
  return points_array(out);
}

}  // namespace

void bind_adf(py::module_& m) {
  py::class_<field::Adf>(m, "Adf",
                         "Adaptively sampled distance field of a triangle mesh (seed 6.1, Figure 60): an octree whose\n"
                         "leaves hold the exact signed distances at their corners, split until the trilinear\n"
                         "interpolation is within `error` of the exact field at each cell's test points (the checks^3\n"
                         "lattice less the corners; 3: the 19 edge, face and centre points).")
      .def(py::init(&adf_build), py::arg("V"), py::arg("F"), py::arg("error"),
           py::arg("max_depth") = field::AdfOptions{}.max_depth, py::arg("band") = py::none(),
           py::arg("checks") = field::AdfOptions{}.checks, py::arg("padding") = field::AdfOptions{}.padding,
           py::arg("sign") = "winding",
           "Builds the ADF of the mesh (V, F). band: half-width (world units) of the band about the surface:\n"
           "the field is clamped to [-band, band] and refined only near the surface (default: the whole field).\n"
           "padding: margin of the root cube, times the mesh's largest extent. sign: 'winding', 'pseudonormal'\n"
           "or 'none'.")
      .def("distance", &distance_py, py::arg("points"),
           "Signed distances (float64 (n,)) of points (n, 3): the leaf's trilinear interpolation.")
      .def("gradient", &vectors_py<&field::Adf::gradient>, py::arg("points"),
           "Gradients (float32 (n, 3)) of the interpolation at the points.")
      .def("closest_point", &vectors_py<&field::Adf::closest_point>, py::arg("points"),
           "p - d g / |g| (float32 (n, 3)): the closest surface point by the ADF.")
      .def(
          "isosurface",
          [](const field::Adf& adf, double offset, std::size_t res) {
            const TriMesh mesh = without_gil([&] { return adf.isosurface(offset, res); });
            return mesh_arrays(mesh, false);
          },
          py::arg("offset") = 0.0, py::arg("res") = 0,
          "The surface at distance `offset` (negative: inside) as (V, F), by marching cubes on the ADF sampled\n"
          "at res samples along the root cube's side (0: 2^min(depth, 8) + 1).")
      .def("stats", [](const field::Adf& adf) { return stats_dict(adf.stats()); },
           "dict: cells, leaves, depth, unresolved, exact_queries, signs, corners, value_bits, key_bits, quantum, bytes, dense_bytes")
      .def("validate", &field::Adf::validate, "Checks the tree; raises geods.Error if it is broken.")
      .def_property_readonly("origin", [](const field::Adf& adf) { return py::make_tuple(adf.origin().x(), adf.origin().y(), adf.origin().z()); },
                             "Low corner of the root cube.")
      .def_property_readonly("size", &field::Adf::size, "Side of the root cube.")
      .def("save", [](const field::Adf& adf, const std::filesystem::path& path) { adf.save(path); }, py::arg("path"),
           "Writes the ADF to a geods archive.")
      .def_static("load", [](const std::filesystem::path& path) { return field::Adf::load(path); }, py::arg("path"),
                  "Maps a file written by save() (read in place).");
}

}  // namespace geods::python
