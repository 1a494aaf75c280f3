// Python bindings of geods::io: meshes, volumes, points, segments and images
// as numpy arrays. (.npy files are numpy's own job and are not bound.)
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <limits>
#include <string>

#include "bindings.hpp"
#include "arrays.hpp"
#include "without_gil.hpp"
#include "geods/core/error.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/table_io.hpp"
#include "geods/io/volume_io.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using std::filesystem::path;

py::tuple read_mesh_py(const path& p) {
  const TriMesh mesh = without_gil([&] { return io::read_mesh(p); });
  return mesh_arrays(mesh, false);
}

// V is checked in its own dtype before the cast to float (1e300 would become inf,
// which write_mesh refuses anyway, under a less clear name); F must hold integers
// (a float F would be truncated to other indices).
void write_mesh_py(const path& p, const py::array& v, const py::array& f, bool binary) {
  const auto v64 = Rows<double>::ensure(v);
  if (!v64) throw Error("write_mesh: V must be an (n, 3) array of numbers");
  for (py::ssize_t i = 0; i < v64.size(); ++i)
    if (!(std::abs(v64.data()[i]) <= double(std::numeric_limits<float>::max())))
      throw Error(p.string() + ": cannot write mesh: vertex " + std::to_string(i / 3) + " has a non-finite coordinate " +
                  "or one outside the float range (" + format_number(v64.data()[i]) + ")");
  if (f.dtype().kind() != 'i' && f.dtype().kind() != 'u' && f.size() > 0)
    throw Error("write_mesh: F must be an integer array of vertex indices, not " + std::string(py::str(py::object(f.dtype()))));
  const TriMesh mesh = mesh_from_arrays(Rows<float>::ensure(v), Rows<std::int64_t>::ensure(f), "write_mesh");
  py::gil_scoped_release release;
  io::write_mesh(p, mesh, binary ? io::MeshEncoding::binary : io::MeshEncoding::ascii);
}

py::object read_volume_py(const path& p, bool with_meta) {
  const io::AnyGrid3 grid = without_gil([&] { return io::read_volume(p); });
  return std::visit(
      [&](const auto& g) -> py::object {
        const py::array a = copy_array(g.data.data(), {py::ssize_t(g.dims[2]), py::ssize_t(g.dims[1]), py::ssize_t(g.dims[0])});
        if (!with_meta) return a;
        return py::make_tuple(a, py::make_tuple(g.origin.x(), g.origin.y(), g.origin.z()),
                              py::make_tuple(g.spacing.x(), g.spacing.y(), g.spacing.z()));
      },
      grid);
}

void write_volume_py(const path& p, const py::array& array, const std::array<double, 3>& origin,
                     const std::array<double, 3>& spacing) {
  io::AnyGrid3 grid = volume_from_array(array, spacing, origin, "write_volume");
  py::gil_scoped_release release;
  io::write_volume(p, grid);
}

py::array_t<double> read_points_py(const path& p) {
  const io::PointMatrix m = without_gil([&] { return io::read_points(p); });
  return copy_array(m.data(), {py::ssize_t(m.rows()), py::ssize_t(m.cols())});
}

py::array_t<double> read_table_py(const path& p) {
  const io::Table t = without_gil([&] { return io::read_table(p); });
  return copy_array(t.values.data(), {py::ssize_t(t.rows), py::ssize_t(t.cols)});
}

void write_points_py(const path& p, const Rows<double>& a) {
  if (a.ndim() != 2 || (a.shape(1) != 2 && a.shape(1) != 3)) throw Error("write_points: expected an (n, 2) or (n, 3) array");
  io::PointMatrix m(a.shape(0), a.shape(1));
  if (a.size()) std::memcpy(m.data(), a.data(), std::size_t(a.size()) * sizeof(double));
  py::gil_scoped_release release;
  io::write_points(p, m);
}

py::array_t<double> read_segments_py(const path& p) {
  const io::SegmentMatrix m = without_gil([&] { return io::read_segments(p); });
  return copy_array(m.data(), {py::ssize_t(m.rows()), py::ssize_t(4)});
}

py::array_t<std::uint8_t> read_image_py(const path& p) {
  const Image<std::uint8_t> im = without_gil([&] { return io::read_image(p); });
  return image_array(im);
}

// By dtype: uint8 and bool as 8-bit, uint16 as 16-bit, floats in [0, 1] as
// round(255 v), other integers if every value is in 0..255; anything else is refused.
void write_png_py(const path& p, const py::array& a) {
  const py::dtype dt = a.dtype();
  if (dt.equal(py::dtype::of<std::uint8_t>()) || dt.kind() == 'b') {
    const Image<std::uint8_t> im = image_from_array(Rows<std::uint8_t>::ensure(a), "write_png");
    py::gil_scoped_release release;
    return io::write_png(p, im);
  }
  if (dt.equal(py::dtype::of<std::uint16_t>())) {
    const Image<std::uint16_t> im = image_from_array(Rows<std::uint16_t>::ensure(a), "write_png");
    py::gil_scoped_release release;
    return io::write_png(p, im);
  }
  if (dt.kind() == 'f') {
    const Image<double> im = image_from_array(Rows<double>::ensure(a), "write_png");
    py::gil_scoped_release release;
    return io::write_png(p, im);
  }
  if (dt.kind() == 'i' || dt.kind() == 'u') {
    // Compared as they are (uint64 above 2^63 included), then narrowed.
    const auto wide = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    const auto signed_values = Rows<std::int64_t>::ensure(a);
    for (py::ssize_t i = 0; i < a.size(); ++i) {
      const bool negative = dt.kind() == 'i' && signed_values.data()[i] < 0;
      if (negative || wide.data()[i] > 255)
        throw Error(p.string() + ": cannot write PNG: value " +
                    (negative ? std::to_string(signed_values.data()[i]) : std::to_string(wide.data()[i])) +
                    " of the " + std::string(py::str(py::object(dt))) +
                    " image is outside 0..255 (8-bit PNG); give uint16 for a 16-bit PNG or floats in [0, 1]");
    }
    const Image<std::uint8_t> im = image_from_array(Rows<std::uint8_t>::ensure(a), "write_png");
    py::gil_scoped_release release;
    return io::write_png(p, im);
  }
  throw Error(p.string() + ": cannot write PNG from an array of " + std::string(py::str(py::object(dt))) +
              " (uint8, bool, uint16, other integers in 0..255, or floats in [0, 1])");
}

}  // namespace

void bind_io(py::module_& m) {
  // bind_core normally registers geods.Error (a ValueError); registering a
  // second translator would shadow it, so only do it if it is missing.
  if (!py::hasattr(m, "Error")) py::register_exception<Error>(m, "Error", PyExc_ValueError);

  m.def("read_mesh", &read_mesh_py, py::arg("path"),
        R"doc(Reads a triangle mesh: PLY, OBJ, STL, OFF, glTF/GLB (also .ply.gz, .off.gz).

Returns (V, F): V float32 (n, 3) vertex positions, F int32 (m, 3) vertex
indices (int64 for meshes of more than 2^31 vertices). Polygons are
triangulated; coincident vertices of STL are merged. Raises geods.Error (a
ValueError) naming the file for missing, malformed or truncated files,
non-finite coordinates, out-of-range indices or no triangles.)doc");
  m.def("write_mesh", &write_mesh_py, py::arg("path"), py::arg("V"), py::arg("F"), py::arg("binary") = true,
        R"doc(Writes a triangle mesh as PLY, OBJ or STL by the file's extension.

V is (n, 3) floats, F is (m, 3) integer vertex indices. binary=False writes
ascii PLY/STL (OBJ is always text).)doc");
  m.def("read_volume", &read_volume_py, py::arg("path"), py::arg("with_meta") = false,
        R"doc(Reads a volume: .npy (3-D), .nrrd/.nhdr (raw or gzip), .nii/.nii.gz (NIfTI-1).

Returns an array of shape (nz, ny, nx) in the file's dtype (uint8, uint16,
int16, float32, float64; int8 widens to int16, 32-bit integers to float64,
NIfTI data with scl_slope/scl_inter is scaled to float32). With
with_meta=True, returns (array, origin, spacing) with origin and spacing as
(x, y, z) tuples.)doc");
  m.def("write_volume", &write_volume_py, py::arg("path"), py::arg("array"),
        py::arg("origin") = std::array<double, 3>{0, 0, 0}, py::arg("spacing") = std::array<double, 3>{1, 1, 1},
        R"doc(Writes a (nz, ny, nx) array as .npy, .nrrd or .nii/.nii.gz by extension.

origin and spacing are (x, y, z) (NRRD and NIfTI keep them). uint8, uint16,
int16, float32 and float64 are written as they are; int8 as int16, other
integers as float64.)doc");
  m.def("read_points", &read_points_py, py::arg("path"),
        R"doc(Reads points from .npy, .xyz, .csv or .ply as a float64 (n, 2) or (n, 3) array.

Reads through read_table. Text files: 2 columns are 2D points, 3 or more are 3D
(extra columns such as normals are ignored); a CSV header line is skipped. Raises geods.Error for
malformed files, NaN/inf coordinates or no points.)doc");
  m.def("read_table", &read_table_py, py::arg("path"),
        R"doc(Reads a table of numbers as a float64 (n, d) array, any d: .npy (any numeric dtype), .csv
(a header line is skipped), .txt (blanks or commas), .xyz or .ply (vertex x, y[, z]).

read_points and read_segments read through it. Every row has as many numbers as the first; raises
geods.Error naming the file and line for malformed files, NaN/inf values or no rows.)doc");
  m.def("write_points", &write_points_py, py::arg("path"), py::arg("points"),
        R"doc(Writes an (n, 2) or (n, 3) array as .npy, .xyz, .csv or .ply by extension.)doc");
  m.def("read_segments", &read_segments_py, py::arg("path"),
        R"doc(Reads 2D segments from a table of 4 columns (.npy, .csv, .txt), .edg or .cin as a float64 (m, 4) array of x0, y0, x1, y1.)doc");
  m.def("read_image", &read_image_py, py::arg("path"),
        R"doc(Reads a PNG, JPEG or BMP as uint8: (h, w) for grey, (h, w, c) for 2 to 4 channels.)doc");
  m.def("write_png", &write_png_py, py::arg("path"), py::arg("image"),
        R"doc(Writes an (h, w) or (h, w, c) array (c = 1 to 4) as a PNG, by its dtype:

uint8 and bool: 8-bit; uint16: 16-bit; floats: values in [0, 1] written as
round(255 v) in 8 bits; other integers: 8-bit if every value is in 0..255.
Anything else (NaN, floats outside [0, 1], integers outside 0..255, other
dtypes) raises geods.Error: nothing is clamped or wrapped.)doc");
}

}  // namespace geods::python
