// Python bindings of geods::field: the Euclidean distance transform, the signed distance of meshes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/parallel.hpp"
#include "geods/field/chamfer.hpp"
#include "geods/field/edt.hpp"
#include "geods/field/sdf_grid.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

// A 1-, 2- or 3-D array as a mask volume (nonzero = foreground; C order, the
// last axis x) and the array's shape.
Grid3<std::uint8_t> mask_from(const py::object& mask, std::vector<py::ssize_t>& shape, const std::string& what) {
  const py::module_ np = py::module_::import("numpy");
  const py::array a = np.attr("asarray")(mask);
  if (a.ndim() < 1 || a.ndim() > 3) throw Error(what + ": the mask must be a 1-, 2- or 3-D array");
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    throw Error(what + ": the mask must hold numbers or booleans, got " + py::cast<std::string>(py::repr(a.dtype())));
  if (kind == 'f' && py::cast<bool>(np.attr("isnan")(a).attr("any")())) throw Error(what + ": the mask holds NaN");
  const Rows<std::uint8_t> flags = Rows<std::uint8_t>::ensure(np.attr("not_equal")(a, 0));
  shape.assign(a.shape(), a.shape() + a.ndim());
  Grid3<std::uint8_t> g;
  for (py::ssize_t d = 0; d < a.ndim(); ++d) g.dims[std::size_t(d)] = std::size_t(a.shape(a.ndim() - 1 - d));
  for (py::ssize_t d = a.ndim(); d < 3; ++d) g.dims[std::size_t(d)] = 1;
  g.data.assign(flags.data(), flags.data() + flags.size());
  return g;
}

// One spacing or one per axis of the mask (x first), as 3 values; none: unset.
std::optional<std::array<double, 3>> spacing_from(const py::object& spacing, std::size_t axes, const std::string& what) {
  if (spacing.is_none()) return std::nullopt;
  std::array<double, 3> s{1, 1, 1};
  if (py::isinstance<py::float_>(spacing) || py::isinstance<py::int_>(spacing)) {
    s.fill(py::cast<double>(spacing));
  } else {
    const auto values = py::cast<std::vector<double>>(spacing);
    if (values.size() != axes)
      throw Error(what + ": spacing needs one value per axis (x first), " + std::to_string(axes) + " for this mask, got " +
                  std::to_string(values.size()));
    std::copy(values.begin(), values.end(), s.begin());
  }
  return s;
}

py::object edt_py(const py::object& mask, const py::object& spacing, bool return_indices, bool squared) {
  std::vector<py::ssize_t> shape;
  const Grid3<std::uint8_t> grid = mask_from(mask, shape, "edt");
  field::EdtRequest request;
  request.squared = squared;
  request.features = return_indices;
  request.spacing = spacing_from(spacing, shape.size(), "edt");
  const field::EdtResult r = without_gil([&] { return field::edt(grid.view(), request); });
  py::array_t<double> distance = copy_array(r.distance.data.data(), shape);
  if (!return_indices) return distance;
  return py::make_tuple(distance, index_array(r.features, shape));
}

// Per point: signed distance (float64), closest point (float32), face (int64), and with
// return_feature the feature (0 vertex, 1 edge, 2 face).
py::tuple signed_distance_py(const Rows<float>& v, const Rows<std::int64_t>& f, const py::handle& points,
                             const std::string& sign, bool return_feature) {
  const TriMesh mesh = mesh_from_arrays(v, f, "signed_distance");
  const PointRows<float> rows = point_rows<float>(points, 3, "signed_distance points", false);
  const field::SignMethod method = field::parse_sign_method(sign);
  const std::size_t n = rows.count;
  std::vector<Vec3f> ps(n);
  for (std::size_t i = 0; i < n; ++i) ps[i] = rows.point<3>(i);
  const std::vector<field::MeshPointDistance> r =
      without_gil([&] { return field::signed_distance(mesh, ps, method); });
  py::array_t<double> d{py::ssize_t(n)};
  py::array_t<float> closest({py::ssize_t(n), py::ssize_t(3)});
  std::vector<std::uint32_t> faces(n);
  py::array_t<std::int8_t> feature{py::ssize_t(n)};
  for (std::size_t i = 0; i < n; ++i) {
    d.mutable_data()[i] = r[i].distance;
    for (int a = 0; a < 3; ++a) closest.mutable_data()[3 * i + std::size_t(a)] = r[i].closest[a];
    faces[i] = r[i].face;
    feature.mutable_data()[i] = std::int8_t(r[i].feature);
  }
  if (return_feature) return py::make_tuple(d, closest, index_array(faces), feature);
  return py::make_tuple(d, closest, index_array(faces));
}

// Three numbers (x first) from one number or a sequence of three.
std::array<double, 3> triple(const py::handle& x, const std::string& what) {
  if (py::isinstance<py::float_>(x) || py::isinstance<py::int_>(x)) {
    const double s = py::cast<double>(x);
    return {s, s, s};
  }
  const auto values = py::cast<std::vector<double>>(x);
  if (values.size() != 3) throw Error("sdf_grid: " + what + " needs 1 or 3 values (x first), got " + std::to_string(values.size()));
  return {values[0], values[1], values[2]};
}

py::tuple sdf_grid_py(const Rows<float>& v, const Rows<std::int64_t>& f, const py::object& res,
                      const py::object& spacing, double padding, const py::object& band, const std::string& sign,
                      const py::object& origin, const py::object& dims, bool return_faces, const std::string& method) {
  const TriMesh mesh = mesh_from_arrays(v, f, "sdf_grid");
  Grid3Geometry grid;
  if (!origin.is_none() || !dims.is_none()) {
    // An explicit grid: origin, spacing and dims (x first).
    if (origin.is_none() || dims.is_none() || spacing.is_none())
      throw Error("sdf_grid: an explicit grid needs origin, spacing and dims");
    const std::array<double, 3> o = triple(origin, "origin"), s = triple(spacing, "spacing");
    const auto n = py::cast<std::vector<std::int64_t>>(dims);
    if (n.size() != 3) throw Error("sdf_grid: dims needs 3 values (x first)");
    for (int a = 0; a < 3; ++a) {
      if (n[a] < 0) throw Error("sdf_grid: dims must be >= 0");
      grid.dims[a] = std::size_t(n[a]);
      grid.origin[a] = float(o[a]);
      grid.spacing[a] = float(s[a]);
    }
  } else {
    if (res.is_none() == spacing.is_none()) throw Error("sdf_grid: give res or spacing (one of them)");
    const std::int64_t r = res.is_none() ? 0 : py::cast<std::int64_t>(res);
    if (r < 0) throw Error("sdf_grid: res must be > 0");
    grid = field::sdf_grid_geometry(mesh.bounds(), std::size_t(r), spacing.is_none() ? 0.0 : py::cast<double>(spacing),
                                    padding);
  }
  field::SdfGridOptions options;
  options.sign = field::parse_sign_method(sign);
  options.method = field::parse_sdf_method(method);
  if (!band.is_none()) options.band = py::cast<double>(band);
  options.faces = return_faces;
  const field::SdfGrid r = without_gil([&] { return field::sdf_grid(mesh, grid, options); });
  const std::vector<py::ssize_t> shape{py::ssize_t(grid.dims[2]), py::ssize_t(grid.dims[1]), py::ssize_t(grid.dims[0])};
  py::array_t<float> d = copy_array(r.distance.data.data(), shape);
  const py::tuple o = py::make_tuple(grid.origin.x(), grid.origin.y(), grid.origin.z());
  const py::tuple s = py::make_tuple(grid.spacing.x(), grid.spacing.y(), grid.spacing.z());
  if (return_faces) return py::make_tuple(d, o, s, index_array(r.faces, shape));
  return py::make_tuple(d, o, s);
}

py::array_t<double> chamfer_py(const py::object& mask, int size, const py::object& spacing) {
  std::vector<py::ssize_t> shape;
  const Grid3<std::uint8_t> grid = mask_from(mask, shape, "chamfer");
  field::ChamferRequest request;
  request.size = size;
  request.spacing = spacing_from(spacing, shape.size(), "chamfer");
  const Grid3<double> d = without_gil([&] { return field::chamfer(grid.view(), request); });
  return copy_array(d.data.data(), shape);
}

// One pass of the separable EDT over a copy of g (1-, 2- or 3-D float64); axis in geods order (0 = x = last).
py::array_t<double> edt_pass_py(const py::array_t<double, py::array::c_style | py::array::forcecast>& g, int axis,
                                double spacing) {
  if (g.ndim() < 1 || g.ndim() > 3) throw Error("edt_pass: g must be a 1-, 2- or 3-D array");
  if (axis < 0 || axis >= g.ndim())
    throw Error("edt_pass: axis must be in 0.." + std::to_string(g.ndim() - 1) + " (0 = x, the last array axis), got " +
                std::to_string(axis));
  std::array<std::size_t, 3> dims{1, 1, 1};
  std::vector<py::ssize_t> shape(g.shape(), g.shape() + g.ndim());
  for (py::ssize_t d = 0; d < g.ndim(); ++d) dims[std::size_t(d)] = std::size_t(g.shape(g.ndim() - 1 - d));
  py::array_t<double> out = copy_array(g.data(), shape);
  const std::span<double> values(out.mutable_data(), std::size_t(out.size()));
  without_gil([&] { field::edt_pass(values, dims, axis, spacing); });
  return out;
}

}  // namespace

void bind_field(py::module_& m) {
  m.def("edt", &edt_py, py::arg("mask"), py::arg("spacing") = py::none(), py::arg("return_indices") = false,
        py::arg("squared") = false,
        "Exact Euclidean distance transform of a 1-, 2- or 3-D mask (nonzero = foreground): per sample, the\n"
        "distance to the nearest zero sample (0 on zeros, inf if there is none), float64 of the mask's shape.\n"
        "spacing: one number, or one per axis in geods order (x first: (sx, sy, sz) for a (nz, ny, nx) mask,\n"
        "the reverse of scipy's `sampling`). return_indices: also the flat (C-order) index of the nearest\n"
        "zero sample (int64, -1 if none); np.unravel_index(i, mask.shape) gives its coordinates.\n"
        "squared: squared distances. Felzenszwalb-Huttenlocher, parallel; equal to brute force bit for bit\n"
        "with integer spacings.");

  m.def("edt_pass", &edt_pass_py, py::arg("g"), py::arg("axis"), py::arg("spacing") = 1.0,
        "One separable pass of edt on float64 squared distances g ((n,), (ny, nx) or (nz, ny, nx)): every line along `axis`\n"
        "(geods order: 0 = x = the last array axis) becomes g'(q) = min_p g(p) + (spacing (q - p))^2\n"
        "(inf: no sample). From 0 on the background and inf elsewhere, one pass per axis gives the squared\n"
        "EDT; a chunk needs only be whole along the pass's axis (geods.dask.edt). Returns a new float64 array of the same shape.");
  m.def("chamfer", &chamfer_py, py::arg("mask"), py::arg("size") = field::ChamferRequest{}.size,
        py::arg("spacing") = py::none(),
        "Chamfer distance transform of a 1-, 2- or 3-D mask, (n,), (ny, nx) or (nz, ny, nx) (nonzero =\n"
        "foreground; edt's convention): the\n"
        "distance to the nearest zero sample approximated by a forward and a backward scan with the\n"
        "3x3x3 (size=3) or 5x5x5 (size=5) matrix of Euclidean step lengths (seed Figure 61), float64 of\n"
        "the mask's shape. Never below the exact distance, at most chamfer_max_error(size) above it\n"
        "relatively (unit spacing): 12.8 % for size 3, 4.9 % for size 5. spacing as in edt.");
  m.def("chamfer_max_error", &field::chamfer_max_error, py::arg("size"),
        "Largest relative overestimate of geods.chamfer(size=size) with unit spacing (measured over offsets up to 47).");
  m.def("signed_distance", &signed_distance_py, py::arg("V"), py::arg("F"), py::arg("points"),
        py::arg("sign") = "winding", py::arg("return_feature") = false,
        "Exact signed distance of points (n, 3) to the triangle mesh (V, F), negative inside:\n"
        "(d float64 (n,), closest point float32 (n, 3), closest face int64 (n,)); with return_feature also\n"
        "the feature of the face holding the closest point (int8: 0 vertex, 1 edge, 2 face).\n"
        "sign: 'winding' (generalized winding number > 1/2: any mesh, open ones too), 'pseudonormal'\n"
        "(angle-weighted pseudonormals: closed meshes) or 'none'. Parallel over the points.");
  m.def("sdf_grid", &sdf_grid_py, py::arg("V"), py::arg("F"), py::arg("res") = py::none(),
        py::arg("spacing") = py::none(), py::arg("padding") = field::kDefaultPadding, py::arg("band") = py::none(),
        py::arg("sign") = "winding", py::arg("origin") = py::none(), py::arg("dims") = py::none(),
        py::arg("return_faces") = false, py::arg("method") = "exact",
        "Exact signed distance field of the mesh (V, F) on a grid, negative inside: (d float32 (nz, ny, nx),\n"
        "origin (x, y, z), spacing (sx, sy, sz)), and with return_faces the closest face of each sample\n"
        "(int64, -1 outside the band). The grid: res samples along the mesh's longest side, or samples\n"
        "`spacing` apart, with `padding` samples of margin on each side, centred on the mesh; or explicit\n"
        "origin, spacing and dims (x first). band: half-width in samples of a narrow band (samples beyond\n"
        "it get +-inf); default the whole grid. sign: 'winding', 'pseudonormal' or 'none'.\n"
        "method: 'exact', or 'propagation' (exact closest points on a shell of sqrt 3 samples about the\n"
        "surface passed on to neighbours by two scans, seed 6.1.1: never below the exact distance).");
}

}  // namespace geods::python
