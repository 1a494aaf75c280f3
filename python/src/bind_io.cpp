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
#include "mesh_arrays.hpp"
#include "geods/core/error.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/volume_io.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using std::filesystem::path;

template <typename T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

// A numpy array that owns a copy of `n` values shaped `shape`.
template <typename T>
py::array_t<T> to_numpy(const T* data, std::vector<py::ssize_t> shape) {
  py::array_t<T> a(shape);
  if (a.size() > 0) std::memcpy(a.mutable_data(), data, std::size_t(a.size()) * sizeof(T));
  return a;
}

py::tuple read_mesh_py(const path& p) {
  TriMesh mesh;
  {
    py::gil_scoped_release release;
    mesh = io::read_mesh(p);
  }
  const auto nv = py::ssize_t(mesh.num_vertices()), nf = py::ssize_t(mesh.num_triangles());
  py::array_t<float> v = to_numpy(mesh.vertices.empty() ? nullptr : mesh.vertices[0].data(), {nv, 3});
  // int32 indices unless the mesh is too large for them.
  if (mesh.num_vertices() <= std::size_t(std::numeric_limits<std::int32_t>::max())) {
    py::array_t<std::int32_t> f({nf, py::ssize_t(3)});
    std::memcpy(f.mutable_data(), mesh.triangles.data(), std::size_t(nf) * 3 * sizeof(std::int32_t));
    return py::make_tuple(v, f);
  }
  py::array_t<std::int64_t> f({nf, py::ssize_t(3)});
  auto* out = f.mutable_data();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) out[3 * t + std::size_t(c)] = mesh.triangles[t][std::size_t(c)];
  return py::make_tuple(v, f);
}

void write_mesh_py(const path& p, const CArray<float>& v, const CArray<std::int64_t>& f, bool binary) {
  const TriMesh mesh = mesh_from_arrays(v, f, "write_mesh");
  py::gil_scoped_release release;
  io::write_mesh(p, mesh, binary ? io::MeshEncoding::binary : io::MeshEncoding::ascii);
}

py::object read_volume_py(const path& p, bool with_meta) {
  io::AnyGrid3 grid;
  {
    py::gil_scoped_release release;
    grid = io::read_volume(p);
  }
  return std::visit(
      [&](const auto& g) -> py::object {
        const py::array a = to_numpy(g.data.data(), {py::ssize_t(g.dims[2]), py::ssize_t(g.dims[1]), py::ssize_t(g.dims[0])});
        if (!with_meta) return a;
        return py::make_tuple(a, py::make_tuple(g.origin.x(), g.origin.y(), g.origin.z()),
                              py::make_tuple(g.spacing.x(), g.spacing.y(), g.spacing.z()));
      },
      grid);
}

template <typename T>
io::AnyGrid3 grid_from(const py::array& array) {
  const auto a = CArray<T>::ensure(array);
  Grid3<T> g;
  g.dims = {std::size_t(a.shape(2)), std::size_t(a.shape(1)), std::size_t(a.shape(0))};
  g.data.assign(a.data(), a.data() + a.size());
  return g;
}

void write_volume_py(const path& p, const py::array& array, const std::array<double, 3>& origin,
                     const std::array<double, 3>& spacing) {
  if (array.ndim() != 3) throw Error("write_volume: the array must be 3-D (nz, ny, nx)");
  io::AnyGrid3 grid;
  const py::dtype dt = array.dtype();
  if (dt.is(py::dtype::of<std::uint8_t>()) || dt.kind() == 'b') grid = grid_from<std::uint8_t>(array);
  else if (dt.is(py::dtype::of<std::uint16_t>())) grid = grid_from<std::uint16_t>(array);
  else if (dt.is(py::dtype::of<std::int16_t>()) || dt.is(py::dtype::of<std::int8_t>())) grid = grid_from<std::int16_t>(array);
  else if (dt.is(py::dtype::of<float>())) grid = grid_from<float>(array);
  else if (dt.is(py::dtype::of<double>()) || dt.kind() == 'i' || dt.kind() == 'u') grid = grid_from<double>(array);
  else throw Error("write_volume: unsupported dtype " + py::cast<std::string>(py::repr(dt)));
  std::visit(
      [&](auto& g) {
        g.origin = Vec3d(origin[0], origin[1], origin[2]).cast<float>();
        g.spacing = Vec3d(spacing[0], spacing[1], spacing[2]).cast<float>();
      },
      grid);
  py::gil_scoped_release release;
  io::write_volume(p, grid);
}

py::array_t<double> read_points_py(const path& p) {
  io::PointMatrix m;
  {
    py::gil_scoped_release release;
    m = io::read_points(p);
  }
  return to_numpy(m.data(), {py::ssize_t(m.rows()), py::ssize_t(m.cols())});
}

void write_points_py(const path& p, const CArray<double>& a) {
  if (a.ndim() != 2 || (a.shape(1) != 2 && a.shape(1) != 3)) throw Error("write_points: expected an (n, 2) or (n, 3) array");
  io::PointMatrix m(a.shape(0), a.shape(1));
  if (a.size()) std::memcpy(m.data(), a.data(), std::size_t(a.size()) * sizeof(double));
  py::gil_scoped_release release;
  io::write_points(p, m);
}

py::array_t<double> read_segments_py(const path& p) {
  io::SegmentMatrix m;
  {
    py::gil_scoped_release release;
    m = io::read_segments(p);
  }
  return to_numpy(m.data(), {py::ssize_t(m.rows()), py::ssize_t(4)});
}

py::array_t<std::uint8_t> read_image_py(const path& p) {
  Image<std::uint8_t> im;
  {
    py::gil_scoped_release release;
    im = io::read_image(p);
  }
  const auto h = py::ssize_t(im.height), w = py::ssize_t(im.width), c = py::ssize_t(im.channels);
  return im.channels == 1 ? to_numpy(im.data.data(), {h, w}) : to_numpy(im.data.data(), {h, w, c});
}

void write_png_py(const path& p, const CArray<std::uint8_t>& a) {
  if (a.ndim() != 2 && a.ndim() != 3) throw Error("write_png: expected an (h, w) or (h, w, c) uint8 array");
  Image<std::uint8_t> im;
  im.height = std::size_t(a.shape(0));
  im.width = std::size_t(a.shape(1));
  im.channels = a.ndim() == 3 ? std::size_t(a.shape(2)) : 1;
  im.data.assign(a.data(), a.data() + a.size());
  py::gil_scoped_release release;
  io::write_png(p, im);
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

Text files: 2 columns are 2D points, 3 or more are 3D (extra columns such as
normals are ignored); a CSV header line is skipped. Raises geods.Error for
malformed files, NaN/inf coordinates or no points.)doc");
  m.def("write_points", &write_points_py, py::arg("path"), py::arg("points"),
        R"doc(Writes an (n, 2) or (n, 3) array as .npy, .xyz, .csv or .ply by extension.)doc");
  m.def("read_segments", &read_segments_py, py::arg("path"),
        R"doc(Reads 2D segments from .npy (m, 4), .edg or .cin as a float64 (m, 4) array of x0, y0, x1, y1.)doc");
  m.def("read_image", &read_image_py, py::arg("path"),
        R"doc(Reads a PNG, JPEG or BMP as uint8: (h, w) for grey, (h, w, c) for 2 to 4 channels.)doc");
  m.def("write_png", &write_png_py, py::arg("path"), py::arg("image"),
        R"doc(Writes a uint8 (h, w) or (h, w, c) array (c = 1 to 4) as an 8-bit PNG.)doc");
}

}  // namespace geods::python
