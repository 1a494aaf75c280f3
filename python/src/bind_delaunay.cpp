// Python bindings of the Delaunay triangulation: geods.Delaunay2.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "arrays.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/delaunay3.hpp"
#include "geods/voronoi/spheres.hpp"
#include "geods/voronoi/voronoi3.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using voronoi::Delaunay2;
std::vector<Vec2d> as_points(const py::handle& h, const char* what) { return points_of<double, 2>(h, what); }

Vec2d as_point(const py::handle& h, const char* what) { return point_of<double, 2>(h, what); }

std::int64_t as_index(std::uint32_t i) { return index_value(i); }

// Voronoi3(points, box): clipped to the box (6 numbers), or to the hull for None.
voronoi::Voronoi3 make_voronoi3(const py::handle& points_in, const py::handle& box_in) {
  const std::vector<Vec3d> points = points_of<double, 3>(points_in, "Voronoi3");
  if (box_in.is_none()) return without_gil([&] { return voronoi::Voronoi3(voronoi::Delaunay3(points)); });
  const py::array_t<double, py::array::c_style | py::array::forcecast> box =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(box_in);
  if (!box || box.size() != 6) throw Error("Voronoi3: box must be 6 numbers x0, y0, z0, x1, y1, z1, or None");
  const double* b = box.data();
  const AABB3d aabb(Vec3d(b[0], b[1], b[2]), Vec3d(b[3], b[4], b[5]));
  return without_gil([&] { return voronoi::Voronoi3(points, aabb); });
}

std::uint32_t vertex_index(std::int64_t i, const Delaunay2& dt, const char* what) {
  if (i < 0 || std::size_t(i) >= dt.points().size())
    throw Error(std::string(what) + ": point " + std::to_string(i) + " does not exist");
  return std::uint32_t(i);
}

Delaunay2 make(const py::handle& points_in, const py::object& segments_in, std::uint64_t seed) {
  const std::vector<Vec2d> points = as_points(points_in, "Delaunay2");
  Delaunay2::Options options;
  options.seed = seed;
  if (segments_in.is_none()) {
    py::gil_scoped_release release;
    return Delaunay2(points, options);
  }
  const py::array seg = py::array::ensure(segments_in);
  if (!seg || seg.ndim() != 2 || (seg.shape(1) != 2 && seg.shape(1) != 4))
    throw Error("Delaunay2: segments must be (m, 2) point indices or (m, 4) end coordinates x0, y0, x1, y1");
  if (seg.shape(1) == 4) {
    const PointRows<double> ends = point_rows<double>(seg, 4, "Delaunay2 segments", false);
    std::vector<std::array<Vec2d, 2>> segments(ends.count);
    for (std::size_t k = 0; k < segments.size(); ++k) {
      const Vec4d e = ends.point<4>(k);
      segments[k] = {e.head<2>(), e.tail<2>()};
    }
    py::gil_scoped_release release;
    return Delaunay2::from_segment_ends(points, segments, options);
  }
  if (seg.dtype().kind() != 'i' && seg.dtype().kind() != 'u')
    throw Error("Delaunay2: (m, 2) segments must be integer point indices");
  const auto idx = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(seg);
  std::vector<Delaunay2::Segment> segments(std::size_t(idx.shape(0)));
  for (std::size_t k = 0; k < segments.size(); ++k)
    for (int s = 0; s < 2; ++s) {
      const std::int64_t v = idx.at(k, s);
      if (v < 0 || std::size_t(v) >= points.size())
        throw Error("Delaunay2: segment " + std::to_string(k) + " refers to point " + std::to_string(v) +
                    ", but there are " + std::to_string(points.size()) + " points");
      segments[k][s] = std::uint32_t(v);
    }
  py::gil_scoped_release release;
  return Delaunay2(points, segments, options);
}

using voronoi::Delaunay3;

std::uint32_t point_index3(std::int64_t i, const Delaunay3& dt, const char* what) {
  if (i < 0 || std::size_t(i) >= dt.points().size())
    throw Error(std::string(what) + ": point " + std::to_string(i) + " does not exist");
  return std::uint32_t(i);
}

void bind_delaunay3(py::module_& m) {
  py::class_<Delaunay3>(m, "Delaunay3", R"doc(
Delaunay tetrahedralization of 3D points (Bowyer-Watson insertion in BRIO order,
exact predicates with symbolic perturbation: any input, cospherical or coplanar
sets included, gives a valid and unique result).

Delaunay3(points, seed=..., insertion="cavity") -- points (n, 3). Duplicates merge
into their first occurrence; fewer than four distinct points or all coplanar give
no tetrahedra (dimension < 3). NaN/inf raise geods.Error (ValueError).
insertion="flips" inserts each point (here and in insert()) by 1-4, 2-3, 3-2
(and 4-4) flips instead of the Bowyer-Watson cavity: the same tetrahedra.
)doc")
      .def(py::init([](const py::handle& points_in, std::uint64_t seed, const std::string& insertion) {
             if (insertion != "cavity" && insertion != "flips")
               throw Error("Delaunay3: insertion must be \"cavity\" or \"flips\", got \"" + insertion + "\"");
             const std::vector<Vec3d> points = points_of<double, 3>(points_in, "Delaunay3");
             py::gil_scoped_release release;
             return Delaunay3(points, {.insertion = insertion == "flips" ? voronoi::Delaunay3Insertion::flips
                                                                         : voronoi::Delaunay3Insertion::cavity,
                                       .seed = seed});
           }),
           py::arg("points"), py::arg("seed") = Delaunay3::Options{}.seed, py::arg("insertion") = "cavity")
      .def_property_readonly(
          "points", [](const Delaunay3& dt) { return points_array(dt.points()); }, "(n, 3) float64: the points")
      .def_property_readonly(
          "tetrahedra",
          [](const Delaunay3& dt) {
            return index_array(dt.tetrahedra(), {py::ssize_t(dt.tetrahedron_count()), 4});
          },
          "(m, 4) int64: positively oriented vertex indices (first occurrences of duplicates)")
      .def_property_readonly(
          "neighbors",
          [](const Delaunay3& dt) { return index_array(dt.neighbors(), {py::ssize_t(dt.tetrahedron_count()), 4}); },
          "(m, 4) int64: the tetrahedron across the face opposite each vertex, -1 on the hull")
      .def_property_readonly("dimension", &Delaunay3::dimension,
                             "affine dimension: -1 no points, 0 all equal, 1 collinear, 2 coplanar, 3 a solid")
      .def(
          "hull",
          [](const Delaunay3& dt) {
            std::vector<std::uint32_t> flat;
            for (const auto& t : dt.hull()) flat.insert(flat.end(), t.begin(), t.end());
            return index_array(flat, {py::ssize_t(flat.size() / 3), 3});
          },
          "(h, 3) int64: the convex hull's triangles, counter-clockwise seen from outside")
      .def(
          "representative",
          [](const Delaunay3& dt, std::int64_t i) {
            return index_value(dt.representative(point_index3(i, dt, "Delaunay3.representative")));
          },
          py::arg("i"), "the first occurrence of point i, -1 if it was removed")
      .def(
          "locate",
          [](const Delaunay3& dt, const py::handle& q) {
            return index_value(dt.locate(point_of<double, 3>(q, "Delaunay3.locate")));
          },
          py::arg("q"), "index of a tetrahedron containing q = (x, y, z) (closed), -1 outside the hull")
      .def(
          "nearest_vertex",
          [](const Delaunay3& dt, const py::handle& q) {
            return index_value(dt.nearest_vertex(point_of<double, 3>(q, "Delaunay3.nearest_vertex")));
          },
          py::arg("q"), "index of the nearest point to q = (x, y, z) (a first occurrence), -1 if empty")
      .def(
          "vertex_neighbors",
          [](const Delaunay3& dt, std::int64_t v) {
            return index_array(dt.vertex_neighbors(point_index3(v, dt, "Delaunay3.vertex_neighbors")));
          },
          py::arg("v"), "the Delaunay neighbours of point v, ascending: int64 (k,)")
      .def(
          "insert",
          [](Delaunay3& dt, const py::handle& p) {
            return std::int64_t(dt.insert(point_of<double, 3>(p, "Delaunay3.insert")));
          },
          py::arg("p"), "inserts a point p = (x, y, z), returns its index")
      .def(
          "remove", [](Delaunay3& dt, std::int64_t i) { dt.remove(point_index3(i, dt, "Delaunay3.remove")); },
          py::arg("i"), "removes point i (rebuilds: O(n log n))")
      .def(
          "save", [](const Delaunay3& dt, const std::filesystem::path& path) { dt.save(path); }, py::arg("path"),
          "writes the tetrahedralization to a geods archive")
      .def_static(
          "load", [](const std::filesystem::path& path) { return Delaunay3::load(path); }, py::arg("path"),
          "reads a tetrahedralization written by save() (checked exactly); insert and remove go on as before")
      .def("validate", &Delaunay3::validate, "checks every invariant (exact); raises geods.Error on a violation")
      .def("stats", [](const Delaunay3& dt) { return stats_dict(dt.stats()); }, "dict of the DelaunayStats fields");

  py::class_<voronoi::Voronoi3>(m, "Voronoi3", R"doc(
The Voronoi cells of 3D points clipped to a box (x0, y0, z0, x1, y1, z1), or with
box=None to the points' convex hull, as closed convex polyhedra.
)doc")
      .def(py::init(&make_voronoi3),
           py::arg("points"), py::arg("box") = py::none(), "points: float64 (n, 3); box: 6 numbers or None (the hull)")
      .def_property_readonly(
          "cells",
          [](const voronoi::Voronoi3& vd) {
            py::list out;
            for (const auto& cell : vd.cells()) {
              py::dict d;
              d["site"] = std::int64_t(cell.site);
              d["volume"] = cell.volume;
              d["centroid"] = copy_array(cell.centroid.data(), {3});
              d["vertices"] = points_array(cell.vertices);
              py::list faces;
              for (std::size_t f = 0; f < cell.face_count(); ++f)
                faces.append(index_array(std::span<const std::uint32_t>(
                    cell.face_vertices.data() + cell.face_offsets[f], cell.face_offsets[f + 1] - cell.face_offsets[f])));
              d["faces"] = faces;
              std::vector<std::int64_t> labels;
              for (const std::uint32_t l : cell.face_neighbors)  // box side k: -2 - k; hull triangle k: -1000 - k
                labels.push_back(voronoi::Voronoi3::is_hull_face(l) ? -1000 - std::int64_t(l & 0x7fffffffu)
                                                                    : std::int32_t(l));
              d["neighbors"] = copy_array(labels.data(), {py::ssize_t(labels.size())});
              out.append(d);
            }
            return out;
          },
          R"doc(One dict per distinct point: "site" (its index), "volume", "centroid",
"vertices" (k, 3), "faces" (index loops into vertices, counter-clockwise seen from
outside) and "neighbors" (per face the site across, -2 - k for box side k: -x, +x,
-y, +y, -z, +z, or -1000 - k for hull triangle k).)doc")
      .def_property_readonly(
          "box",
          [](const voronoi::Voronoi3& vd) {
            const double b[6] = {vd.box().lo[0], vd.box().lo[1], vd.box().lo[2],
                                 vd.box().hi[0], vd.box().hi[1], vd.box().hi[2]};
            return copy_array(b, {6});
          },
          "(6,) float64: the box, or the hull's bounding box")
      .def("volume_total", &voronoi::Voronoi3::volume_total, "the sum of the cells' volumes: the box's or the hull's")
      .def(
          "mesh", [](const voronoi::Voronoi3& vd, double explode) { return mesh_arrays(vd.mesh(explode), false); },
          py::arg("explode") = 0.0,
          "(V float32 (n, 3), F (m, 3)): every cell a closed surface, moved from the box's centre by explode")
      .def("stats", [](const voronoi::Voronoi3& vd) { return stats_dict(vd.stats()); },
           "dict: sites, faces, vertices, empty, bytes")
      .def("validate", &voronoi::Voronoi3::validate, py::call_guard<py::gil_scoped_release>(),
           "Checks every invariant (closed convex cells on their bisectors, none overlapping, volumes adding up); "
           "raises geods.Error if one fails.")
      .def(
          "save", [](const voronoi::Voronoi3& vd, const std::filesystem::path& path) { vd.save(path); }, py::arg("path"),
          "writes the cells, points, box and hull to a geods archive")
      .def_static(
          "load", [](const std::filesystem::path& path) { return voronoi::Voronoi3::load(path); }, py::arg("path"),
          "reads cells written by save() (indices and closedness checked)");
  m.def(
      "voronoi3", &make_voronoi3, py::arg("points"), py::arg("box") = py::none(),
      "The Voronoi cells of 3D points (n, 3) clipped to box (x0, y0, z0, x1, y1, z1), or to their convex hull when "
      "box is None: a Voronoi3.");
  m.def(
      "largest_empty_sphere",
      [](const py::handle& points_in) {
        const std::vector<Vec3d> points = points_of<double, 3>(points_in, "largest_empty_sphere");
        const voronoi::Sphere s = without_gil([&] { return voronoi::largest_empty_sphere(points); });
        return py::make_tuple(copy_array(s.center.data(), {3}), s.radius);
      },
      py::arg("points"), R"doc(
The largest sphere centred in the convex hull of (n, 3) points with no point inside:
(center (3,), radius). Coplanar points give the largest empty circle in their plane.
)doc");
}

}  // namespace

void bind_delaunay(py::module_& m) {
  bind_delaunay3(m);
  py::class_<Delaunay2>(m, "Delaunay2", R"doc(
Delaunay triangulation of 2D points (incremental, Lawson flips, exact predicates),
optionally constrained by segments.

Delaunay2(points, segments=None, seed=...) -- points (n, 2); segments either (m, 2)
integer point indices or (m, 4) end coordinates x0, y0, x1, y1 (then the end points
are appended to the points). Duplicates merge into their first occurrence; all
collinear points give no triangles (degenerate). Crossing segments are split at a
new appended point (intersection_points). NaN/inf raise geods.Error (ValueError).
)doc")
      .def(py::init(&make), py::arg("points"), py::arg("segments") = py::none(),
           py::arg("seed") = Delaunay2::Options{}.seed)
      .def_property_readonly(
          "points",
          [](const Delaunay2& dt) { return points_array(dt.points()); },
          "(n, 2) float64: the input points, then intersection and inserted points")
      .def_property_readonly(
          "triangles",
          [](const Delaunay2& dt) { return index_array(dt.triangles().span(), {py::ssize_t(dt.triangle_count()), 3}); },
          "(m, 3) int64: counter-clockwise vertex indices (first occurrences of duplicates)")
      .def_property_readonly(
          "halfedges", [](const Delaunay2& dt) { return index_array(dt.halfedges().span()); },
          "(3m,) int64: the opposite half-edge of half-edge e (from triangles.flat[e] to the next vertex "
          "of its triangle), -1 on the hull")
      .def_property_readonly(
          "hull", [](const Delaunay2& dt) { return index_array(dt.hull().span()); },
          "hull vertices counter-clockwise (for a degenerate set: the distinct points sorted by x, y)")
      .def_property_readonly("degenerate", &Delaunay2::degenerate, "True when there are no triangles")
      .def_property_readonly(
          "constrained",
          [](const Delaunay2& dt) {  // empty without segments: all false
            return dt.constrained().empty() ? bool_array(std::vector<std::uint8_t>(dt.halfedges().size()))
                                            : bool_array(dt.constrained());
          },
          "(3m,) bool: half-edges on a segment")
      .def_property_readonly(
          "constrained_edges",
          [](const Delaunay2& dt) {
            const auto edges = dt.constrained_edges();
            std::vector<std::uint32_t> flat;
            for (const auto& e : edges) flat.insert(flat.end(), e.begin(), e.end());
            return index_array(flat, {py::ssize_t(edges.size()), 2});
          },
          "(k, 2) int64: the constrained edges, each once")
      .def_property_readonly(
          "intersection_points",
          [](const Delaunay2& dt) { return index_array(dt.intersection_points()); },
          "indices of the points added where segments cross")
      .def_property_readonly(
          "inside",
          [](const Delaunay2& dt) { return bool_array(dt.inside()); },
          "(m,) bool: triangles inside the segments (even-odd from outside the hull): a polygon minus its holes")
      .def(
          "representative", [](const Delaunay2& dt, std::int64_t i) {
            return as_index(dt.representative(vertex_index(i, dt, "Delaunay2.representative")));
          },
          py::arg("i"), "the first occurrence of point i, -1 if it was removed")
      .def(
          "locate",
          [](const Delaunay2& dt, const py::handle& q) { return as_index(dt.locate(as_point(q, "Delaunay2.locate"))); },
          py::arg("q"), "index of a triangle containing q = (x, y) (closed), -1 outside the hull")
      .def(
          "nearest",
          [](const Delaunay2& dt, const py::handle& q) { return as_index(dt.nearest(as_point(q, "Delaunay2.nearest"))); },
          py::arg("q"), "index of the nearest point to q = (x, y) (a first occurrence), -1 if empty")
      .def(
          "neighbors",
          [](const Delaunay2& dt, std::int64_t v) {
            const auto nb = dt.neighbors(vertex_index(v, dt, "Delaunay2.neighbors"));
            return index_array(nb);
          },
          py::arg("v"), "Delaunay neighbours of vertex v, counter-clockwise: int64 (k,)")
      .def(
          "insert", [](Delaunay2& dt, const py::handle& p) { return std::int64_t(dt.insert(as_point(p, "Delaunay2.insert"))); },
          py::arg("p"), "inserts a point p = (x, y), returns its index")
      .def(
          "remove", [](Delaunay2& dt, std::int64_t v) { dt.remove(vertex_index(v, dt, "Delaunay2.remove")); },
          py::arg("i"), "removes point i (not with segments)")
      .def(
          "save", [](const Delaunay2& dt, const std::filesystem::path& path) { dt.save(path); }, py::arg("path"),
          "writes the triangulation to a geods archive")
      .def_static(
          "load", [](const std::filesystem::path& path) { return Delaunay2::load(path); }, py::arg("path"),
                  "reads a triangulation written by save(); insert and remove go on as before")
      .def("validate", &Delaunay2::validate, "checks every invariant; raises geods.Error on a violation")
      .def("stats", [](const Delaunay2& dt) { return stats_dict(dt.stats()); }, "dict of the Delaunay2Stats fields");
}

}  // namespace geods::python
