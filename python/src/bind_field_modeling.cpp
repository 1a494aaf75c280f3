// Python bindings of geods::field's projection of distance functions, modeling
// (CSG, blends, offsets, surfaces) and morphing.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/field/modeling.hpp"
#include "geods/field/morph.hpp"
#include "geods/field/projection.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

// Rows of `cols` float64 from an array (or None: no rows); (cols,) is one row.
std::vector<double> table_rows(const py::object& x, std::size_t cols, const std::string& what, std::size_t& rows) {
  rows = 0;
  if (x.is_none()) return {};
  const Rows<double> a = Rows<double>::ensure(x);
  if (!a) throw Error(what + ": expected an array of numbers");
  if (a.size() == 0) return {};
  if (!(a.ndim() == 2 && std::size_t(a.shape(1)) == cols) && !(a.ndim() == 1 && std::size_t(a.shape(0)) == cols))
    throw Error(what + ": expected rows of " + std::to_string(cols) + " numbers");
  rows = std::size_t(a.size()) / cols;
  return {a.data(), a.data() + a.size()};
}

// A float32 array of 1 to 3 dimensions as a field on the unit grid (x the last axis).
Grid3<float> field_from(const py::object& x, std::vector<py::ssize_t>& shape, const std::string& what) {
  const Rows<float> a = Rows<float>::ensure(x);
  if (!a || a.ndim() < 1 || a.ndim() > 3) throw Error(what + ": expected a 1-, 2- or 3-D array of numbers");
  shape.assign(a.shape(), a.shape() + a.ndim());
  Grid3<float> g;
  for (py::ssize_t d = 0; d < 3; ++d) g.dims[std::size_t(d)] = d < a.ndim() ? std::size_t(a.shape(a.ndim() - 1 - d)) : 1;
  g.data.assign(a.data(), a.data() + a.size());
  return g;
}

py::tuple project_distance_py(const py::object& sites, const std::vector<std::int64_t>& size, const py::object& segments,
                              const py::object& polygons, const py::object& origin, double spacing,
                              const py::object& max_distance) {
  if (size.size() != 2 && size.size() != 3) throw Error("project_distance: size is (W, H) or (W, H, D)");
  const std::size_t dim = size.size();
  Grid3Geometry grid;
  for (std::size_t a = 0; a < 3; ++a) {
    const std::int64_t n = a < dim ? size[a] : 1;
    if (n < 1) throw Error("project_distance: size must be >= 1 along every axis");
    grid.dims[a] = std::size_t(n);
  }
  if (!origin.is_none()) {
    const auto o = py::cast<std::vector<double>>(origin);
    if (o.size() != dim) throw Error("project_distance: origin needs one value per axis of size");
    for (std::size_t a = 0; a < dim; ++a) grid.origin[Eigen::Index(a)] = float(o[a]);
  }
  grid.spacing = Vec3f::Constant(float(spacing));
  field::ProjectionSites s;
  std::size_t n = 0;
  const std::vector<double> p = table_rows(sites, dim, "project_distance sites", n);
  for (std::size_t i = 0; i < n; ++i) s.points.emplace_back(p[dim * i], p[dim * i + 1], dim == 3 ? p[dim * i + 2] : 0.0);
  const std::vector<double> q = table_rows(segments, 2 * dim, "project_distance segments", n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* r = q.data() + 2 * dim * i;
    s.segments.push_back(dim == 2 ? std::array<Vec3d, 2>{Vec3d(r[0], r[1], 0), Vec3d(r[2], r[3], 0)}
                                  : std::array<Vec3d, 2>{Vec3d(r[0], r[1], r[2]), Vec3d(r[3], r[4], r[5])});
  }
  if (!polygons.is_none())
    for (const py::handle& poly : polygons) {
      const std::vector<double> v = table_rows(py::reinterpret_borrow<py::object>(poly), 2, "project_distance polygon", n);
      std::vector<Vec2d> ring(n);
      for (std::size_t i = 0; i < n; ++i) ring[i] = {v[2 * i], v[2 * i + 1]};
      s.polygons.push_back(std::move(ring));
    }
  field::ProjectionOptions options;
  if (!max_distance.is_none()) options.max_distance = py::cast<double>(max_distance);
  const field::Projection r = without_gil([&] { return field::project_distance(s, grid, options); });
  std::vector<py::ssize_t> shape{py::ssize_t(grid.dims[1]), py::ssize_t(grid.dims[0])};
  if (dim == 3) shape.insert(shape.begin(), py::ssize_t(grid.dims[2]));
  return py::make_tuple(copy_array(r.distance.data.data(), shape), index_array(r.ids, shape));
}

py::array_t<float> csg_field_py(const py::object& a, const py::object& b, const std::string& op, double blend) {
  std::vector<py::ssize_t> sa, sb;
  const Grid3<float> fa = field_from(a, sa, "csg_field"), fb = field_from(b, sb, "csg_field");
  if (sa != sb) throw Error("csg_field: the fields have different shapes");
  const field::CsgOp o = field::parse_csg_op(op);
  const Grid3<float> r = without_gil([&] { return field::csg(fa, fb, o, blend); });
  return copy_array(r.data.data(), sa);
}

py::array_t<float> blend_py(const py::object& a, const py::object& b, double radius, const std::string& op) {
  if (!(radius > 0) || !std::isfinite(radius)) throw Error("blend: the radius must be finite and > 0");
  return csg_field_py(a, b, op, radius);
}

py::array_t<float> offset_py(const py::object& d, double distance) {
  std::vector<py::ssize_t> shape;
  const Grid3<float> f = field_from(d, shape, "offset");
  const Grid3<float> r = field::offset(f, distance);
  return copy_array(r.data.data(), shape);
}

py::tuple field_surface_py(const py::object& d, double level, const std::array<double, 3>& origin,
                           const std::array<double, 3>& spacing) {
  std::vector<py::ssize_t> shape;
  Grid3<float> f = field_from(d, shape, "field_surface");
  if (shape.size() != 3) throw Error("field_surface: expected a 3-D field (nz, ny, nx)");
  for (int a = 0; a < 3; ++a) f.origin[a] = float(origin[std::size_t(a)]), f.spacing[a] = float(spacing[std::size_t(a)]);
  const TriMesh m = without_gil([&] { return field::field_surface(f, level); });
  return mesh_arrays(m, false);
}

py::tuple fit_rigid_py(const py::handle& from, const py::handle& to) {
  const std::vector<Vec3d> p = points_of<double, 3>(from, "fit_rigid from"), q = points_of<double, 3>(to, "fit_rigid to");
  const field::RigidTransform t = field::fit_rigid(p, q);
  py::array_t<double> r({3, 3});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.mutable_at(i, j) = t.rotation(i, j);
  const Vec3d c = t.centre + t.translation - t.rotation * t.centre;  // q = R p + c
  return py::make_tuple(r, copy_array(c.data(), {3}));
}

py::list morph_py(const Rows<float>& va, const Rows<std::int64_t>& fa, const Rows<float>& vb, const Rows<std::int64_t>& fb,
                  std::int64_t steps, const py::object& correspondences, std::int64_t res, const std::string& kernel,
                  const std::string& sign) {
  if (steps < 2) throw Error("morph: steps must be >= 2");
  if (res < 4) throw Error("morph: res must be >= 4");
  const TriMesh a = mesh_from_arrays(va, fa, "morph A"), b = mesh_from_arrays(vb, fb, "morph B");
  field::MorphOptions options;
  options.res = std::size_t(res);
  options.kernel = field::parse_rbf_kernel(kernel);
  options.sign = field::parse_sign_method(sign);
  std::size_t n = 0;
  const std::vector<double> c = table_rows(correspondences, 6, "morph correspondences", n);
  for (std::size_t i = 0; i < n; ++i) {
    options.from.emplace_back(c[6 * i], c[6 * i + 1], c[6 * i + 2]);
    options.to.emplace_back(c[6 * i + 3], c[6 * i + 4], c[6 * i + 5]);
  }
  std::vector<TriMesh> meshes;
  without_gil([&] {
    const field::Morph m = field::Morph::build(a, b, options);
    for (std::int64_t k = 0; k < steps; ++k) meshes.push_back(m.surface(double(k) / double(steps - 1)));
    return 0;
  });
  py::list out;
  for (const TriMesh& m : meshes) out.append(mesh_arrays(m, false));
  return out;
}

}  // namespace

void bind_field_modeling(py::module_& m) {
  m.def("project_distance", &project_distance_py, py::arg("sites"), py::arg("size"), py::arg("segments") = py::none(),
        py::arg("polygons") = py::none(), py::arg("origin") = py::none(), py::arg("spacing") = 1.0,
        py::arg("max_distance") = py::none(),
        "Distance field and discrete Voronoi diagram by projecting the sites' distance functions into a\n"
        "z-buffer (seed 6.1.2): cones for points, tents for segments, slabs for filled polygons; on the\n"
        "slices of a volume, hyperboloids. size (W, H): sites (n, 2), segments (m, 4) x0,y0,x1,y1,\n"
        "polygons a list of (k, 2) rings (filled, even-odd), results of shape (H, W); size (W, H, D):\n"
        "sites (n, 3), segments (m, 6), polygons in the plane z = 0, results (D, H, W). Sample (i, j[, k])\n"
        "sits at origin + (i, j[, k]) * spacing. -> (distance float64, ids int64): ids number the points,\n"
        "then the segments, then the polygons; -1 (and inf) beyond max_distance. Exact at the samples.");
  m.def("cone_tessellation_error", &field::cone_tessellation_error, py::arg("max_distance"), py::arg("sides"),
        "Largest overestimate of a point's distance (up to max_distance) by a cone tessellated as a fan of\n"
        "`sides` triangles (the graphics-hardware method): max_distance (1 / cos(pi / sides) - 1).\n"
        "project_distance has none: it evaluates the distance functions exactly at the samples.");
  m.def("csg_field", &csg_field_py, py::arg("a"), py::arg("b"), py::arg("op") = "union", py::arg("blend") = 0.0,
        "Boolean operation on two signed distance fields of the same grid (negative inside), seed 6.2.2:\n"
        "'union' min(a, b), 'intersection' max(a, b), 'difference' max(a, -b); blend > 0 rounds the\n"
        "crease with the polynomial smooth min / max of that radius. float32 of the fields' shape.");
  m.def("blend", &blend_py, py::arg("a"), py::arg("b"), py::arg("radius"), py::arg("op") = "union",
        "Smooth union (or intersection, difference) of two signed distance fields a, b of the same shape (nz, ny, nx)\n"
        "with a blend radius > 0: float32 of their shape.");
  m.def("offset", &offset_py, py::arg("d"), py::arg("distance"),
        "The offset field d - distance of a field d (nz, ny, nx), float32 of its shape: its zero set is the surface\n"
        "moved outward by distance (inward if < 0).");
  m.def("field_surface", &field_surface_py, py::arg("d"), py::arg("level") = 0.0,
        py::arg("origin") = std::array<double, 3>{0, 0, 0}, py::arg("spacing") = std::array<double, 3>{1, 1, 1},
        "The surface {d = level} of a signed distance field (nz, ny, nx), negative inside, by marching\n"
        "cubes with outward orientation -> (V, F); origin and spacing as sdf_grid returns them (x first).");
  m.def("fit_rigid", &fit_rigid_py, py::arg("source"), py::arg("target"),
        "Least-squares rigid motion (Kabsch, no reflection) mapping source (n, 3) onto target (n, 3):\n"
        "(R (3, 3), t (3,)) minimizing sum |R p + t - q|^2.");
  m.def("morph", &morph_py, py::arg("VA"), py::arg("FA"), py::arg("VB"), py::arg("FB"), py::arg("steps"),
        py::arg("correspondences") = py::none(), py::arg("res") = 64, py::arg("kernel") = "thin_plate",
        py::arg("sign") = "winding",
        "Morph from mesh A to mesh B through their signed distance fields (seed 6.2.1): steps surfaces\n"
        "(V, F) at t = 0, 1/(steps - 1), ..., 1 on a grid of res samples along its longest side. Without\n"
        "correspondences, (1 - t) D_A + t D_B (equation 16); with correspondences (k, 6) rows\n"
        "x0,y0,z0,x1,y1,z1, A and B are warped towards each other (equation 17: a least-squares rigid\n"
        "part and a radial basis function elastic part, kernel 'thin_plate' or 'gaussian'). The first\n"
        "and last surfaces are the marching-cubes surfaces of D_A and D_B.");
}

}  // namespace geods::python
