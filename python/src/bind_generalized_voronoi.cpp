// Python bindings of the generalized Voronoi diagrams (seed §5.3.3):
// geods.power_diagram, geods.farthest_voronoi, geods.kth_order_voronoi, of §5.3.2
// geods.constrained_voronoi, and of §5.4.3 geods.smallest_color_spanning_circle.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/color_spanning.hpp"
#include "geods/voronoi/constrained_voronoi.hpp"
#include "geods/voronoi/farthest_voronoi.hpp"
#include "geods/voronoi/generalized_stats_fields.hpp"
#include "geods/voronoi/kth_order_voronoi.hpp"
#include "geods/voronoi/power_diagram.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

std::vector<Vec2d> to_points(const py::handle& object, const char* what) { return points_of<double, 2>(object, what); }

AABB2d box_or_frame(const py::object& box, const std::vector<Vec2d>& points, const char* what) {
  if (points.empty()) throw Error(std::string(what) + ": no points");
  if (box.is_none()) return voronoi::frame_around(points);
  const std::vector<double> v = box.cast<std::vector<double>>();
  if (v.size() != 4 || !(v[0] < v[2]) || !(v[1] < v[3]))
    throw Error(std::string(what) + ": box must be (x0, y0, x1, y1) with x0 < x1 and y0 < y1");
  return AABB2d({v[0], v[1]}, {v[2], v[3]});
}

py::list polygons(const std::vector<std::vector<Vec2d>>& cells) {
  py::list out;
  for (const auto& cell : cells) out.append(points_array(cell));
  return out;
}

py::tuple box_tuple(const AABB2d& b) { return py::make_tuple(b.lo[0], b.lo[1], b.hi[0], b.hi[1]); }

template <typename Edge>
py::tuple edge_arrays(const std::vector<Edge>& edges) {
  std::vector<std::uint32_t> sites;
  std::vector<double> segments;
  for (const auto& e : edges) {
    sites.insert(sites.end(), {e.a, e.b});
    segments.insert(segments.end(), {e.p0[0], e.p0[1], e.p1[0], e.p1[1]});
  }
  return py::make_tuple(index_array(sites, {py::ssize_t(sites.size() / 2), 2}),
                        copy_array(segments.data(), {py::ssize_t(segments.size() / 4), 4}));
}

class PyPowerDiagram {
 public:
  PyPowerDiagram(const py::handle& points, const py::handle& weights, const py::object& box) {
    const std::vector<Vec2d> p = to_points(points, "power_diagram");
    const std::vector<double> w = py::cast<std::vector<double>>(py::array_t<double, py::array::forcecast>::ensure(weights).attr("ravel")());
    const AABB2d b = box_or_frame(box, p, "power_diagram");
    py::gil_scoped_release release;
    d_ = std::make_unique<voronoi::PowerDiagram>(p, w, b);
  }
  py::list cells() const { return polygons(d_->cells()); }
  py::tuple edges() const { return edge_arrays(d_->edges()); }
  py::tuple box() const { return box_tuple(d_->box()); }
  py::array triangles() const {
    const auto& t = d_->triangulation().triangles();
    return index_array(t, {py::ssize_t(t.size() / 3), 3});
  }
  py::array redundant() const { return index_array(d_->triangulation().redundant()); }
  py::array representative() const {
    std::vector<std::uint32_t> r(d_->points().size());
    for (std::uint32_t i = 0; i < r.size(); ++i) r[i] = d_->triangulation().representative(i);
    return index_array(r);
  }
  py::dict stats() const {
    py::dict s = stats_dict(d_->triangulation().stats());
    s["edges"] = d_->edges().size();
    return s;
  }
  void validate() const { d_->validate(); }

 private:
  std::unique_ptr<voronoi::PowerDiagram> d_;
};

class PyFarthestVoronoi {
 public:
  PyFarthestVoronoi(const py::handle& points, const py::object& box) {
    const std::vector<Vec2d> p = to_points(points, "farthest_voronoi");
    const AABB2d b = box_or_frame(box, p, "farthest_voronoi");
    py::gil_scoped_release release;
    d_ = std::make_unique<voronoi::FarthestVoronoi>(p, b);
  }
  py::list cells() const { return polygons(d_->cells()); }
  py::tuple edges() const { return edge_arrays(d_->edges()); }
  py::tuple box() const { return box_tuple(d_->box()); }
  py::array corners() const { return index_array(d_->corners()); }
  py::dict stats() const { return stats_dict(d_->stats()); }
  void validate() const { d_->validate(); }

 private:
  std::unique_ptr<voronoi::FarthestVoronoi> d_;
};

class PyKthOrderVoronoi {
 public:
  PyKthOrderVoronoi(const py::handle& points, long k, const py::object& box) {
    const std::vector<Vec2d> p = to_points(points, "kth_order_voronoi");
    if (k < 1) throw Error("kth_order_voronoi: k = " + std::to_string(k) + " must be at least 1");
    const AABB2d b = box_or_frame(box, p, "kth_order_voronoi");
    py::gil_scoped_release release;
    d_ = std::make_unique<voronoi::KthOrderVoronoi>(p, std::size_t(k), b);
  }
  py::list cells() const {
    py::list out;
    for (const auto& r : d_->regions()) out.append(points_array(r.polygon));
    return out;
  }
  py::array sites() const {
    std::vector<std::uint32_t> s;
    for (const auto& r : d_->regions()) s.insert(s.end(), r.sites.begin(), r.sites.end());
    return index_array(s, {py::ssize_t(d_->regions().size()), py::ssize_t(d_->k())});
  }
  std::size_t k() const { return d_->k(); }
  py::tuple box() const { return box_tuple(d_->box()); }
  py::dict stats() const { return stats_dict(d_->stats()); }
  void validate() const { d_->validate(); }

 private:
  std::unique_ptr<voronoi::KthOrderVoronoi> d_;
};

class PyConstrainedVoronoi {
 public:
  PyConstrainedVoronoi(const py::handle& points, const py::handle& segments, const py::object& box) {
    const std::vector<Vec2d> p = to_points(points, "constrained_voronoi");
    const auto s = py::array_t<std::int64_t, py::array::forcecast>::ensure(segments);
    if (!s || (s.size() > 0 && (s.ndim() != 2 || s.shape(1) != 2)))
      throw Error("constrained_voronoi: segments must be an (m, 2) array of point indices");
    std::vector<voronoi::ConstrainedVoronoi::Segment> pairs(std::size_t(s.size() / 2));
    const auto flat = s.attr("ravel")().cast<py::array_t<std::int64_t>>();
    for (py::ssize_t i = 0; i < flat.size(); ++i) {
      const std::int64_t v = flat.at(i);
      if (v < 0 || v >= std::int64_t(p.size()))
        throw Error("constrained_voronoi: segment index " + std::to_string(v) + " is not a point index");
      pairs[std::size_t(i / 2)][std::size_t(i % 2)] = std::uint32_t(v);
    }
    const AABB2d b = box_or_frame(box, p, "constrained_voronoi");
    py::gil_scoped_release release;
    d_ = std::make_unique<voronoi::ConstrainedVoronoi>(p, pairs, b);
  }
  py::list cells() const {
    py::list out;
    for (const auto& piece : d_->pieces()) out.append(points_array(piece.polygon));
    return out;
  }
  py::array sites() const {
    std::vector<std::uint32_t> s;
    for (const auto& piece : d_->pieces()) s.push_back(piece.site);
    return index_array(s);
  }
  py::array constraints() const {
    std::vector<std::uint32_t> s;
    for (const auto& c : d_->constraints()) s.insert(s.end(), {c[0], c[1]});
    return index_array(s, {py::ssize_t(s.size() / 2), 2});
  }
  bool visible(const py::handle& x, std::uint32_t site) const {
    const std::vector<double> v = x.cast<std::vector<double>>();
    if (v.size() != 2 || site >= d_->points().size()) throw Error("ConstrainedVoronoi.visible: a point (x, y) and a site index");
    return d_->visible(Vec2d(v[0], v[1]), site);
  }
  py::tuple box() const { return box_tuple(d_->box()); }
  py::dict stats() const { return stats_dict(d_->stats()); }
  void validate() const { d_->validate(); }

 private:
  std::unique_ptr<voronoi::ConstrainedVoronoi> d_;
};

}  // namespace

void bind_generalized_voronoi(py::module_& m) {
  py::class_<PyPowerDiagram>(m, "PowerDiagram",
                             "Power diagram of weighted points and its regular triangulation, cells clipped to box.")
      .def(py::init<const py::handle&, const py::handle&, const py::object&>(), py::arg("points"), py::arg("weights"),
           py::arg("box") = py::none(), "points: float64 (n, 2); weights: float64 (n,); box: (xmin, ymin, xmax, ymax)")
      .def_property_readonly("cells", &PyPowerDiagram::cells,
                             "One counter-clockwise (k, 2) polygon per input point (empty for redundant points).")
      .def_property_readonly("edges", &PyPowerDiagram::edges, "(sites (m, 2) int64, segments (m, 4) float64).")
      .def_property_readonly("box", &PyPowerDiagram::box)
      .def_property_readonly("triangles", &PyPowerDiagram::triangles, "(t, 3) int64: the regular triangulation.")
      .def_property_readonly("redundant", &PyPowerDiagram::redundant, "int64: points whose cell is empty.")
      .def_property_readonly("representative", &PyPowerDiagram::representative,
                             "int64 per point: the first equal point of equal weight.")
      .def("stats", &PyPowerDiagram::stats,
           "dict: points, vertices, redundant, duplicates, triangles, hull, flips, removals, edges")
      .def("validate", &PyPowerDiagram::validate, "Checks every invariant; raises geods.Error if one fails.");
  m.def("power_diagram", [](const py::handle& p, const py::handle& w, const py::object& box) { return PyPowerDiagram(p, w, box); },
        py::arg("points"), py::arg("weights"), py::arg("box") = py::none(),
        "The power diagram of points (n, 2) with weights (n,) (power |x - p|^2 - w), clipped to box "
        "(default: the points' frame). Equal weights give the Voronoi diagram.");

  py::class_<PyFarthestVoronoi>(m, "FarthestVoronoi", "Farthest-point Voronoi diagram, cells clipped to box.")
      .def(py::init<const py::handle&, const py::object&>(), py::arg("points"), py::arg("box") = py::none(),
           "points: float64 (n, 2); box: (xmin, ymin, xmax, ymax)")
      .def_property_readonly("cells", &PyFarthestVoronoi::cells,
                             "One counter-clockwise (k, 2) polygon per input point (empty unless a hull corner).")
      .def_property_readonly("edges", &PyFarthestVoronoi::edges, "(sites (m, 2) int64, segments (m, 4) float64).")
      .def_property_readonly("box", &PyFarthestVoronoi::box)
      .def_property_readonly("corners", &PyFarthestVoronoi::corners, "int64: the hull corners, counter-clockwise.")
      .def("stats", &PyFarthestVoronoi::stats, "dict: sites, distinct, corners, edges, cell_vertices")
      .def("validate", &PyFarthestVoronoi::validate, "Checks every invariant; raises geods.Error if one fails.");
  m.def("farthest_voronoi", [](const py::handle& p, const py::object& box) { return PyFarthestVoronoi(p, box); },
        py::arg("points"), py::arg("box") = py::none(),
        "The farthest-point Voronoi diagram of points (n, 2), clipped to box (default: the points' frame).");

  py::class_<PyKthOrderVoronoi>(m, "KthOrderVoronoi", "K-th order Voronoi diagram, regions clipped to box.")
      .def(py::init<const py::handle&, long, const py::object&>(), py::arg("points"), py::arg("k"),
           py::arg("box") = py::none(), "points: float64 (n, 2); box: (xmin, ymin, xmax, ymax)")
      .def_property_readonly("cells", &PyKthOrderVoronoi::cells, "One counter-clockwise (m, 2) polygon per region.")
      .def_property_readonly("sites", &PyKthOrderVoronoi::sites, "(regions, k) int64: each region's k nearest sites, ascending.")
      .def_property_readonly("k", &PyKthOrderVoronoi::k)
      .def_property_readonly("box", &PyKthOrderVoronoi::box)
      .def("stats", &PyKthOrderVoronoi::stats, "dict: sites, distinct, k, regions, pieces, region_vertices")
      .def("validate", &PyKthOrderVoronoi::validate, "Checks every invariant; raises geods.Error if one fails.");
  m.def("kth_order_voronoi", [](const py::handle& p, long k, const py::object& box) { return PyKthOrderVoronoi(p, k, box); },
        py::arg("points"), py::arg("k"), py::arg("box") = py::none(),
        "The k-th order Voronoi diagram of points (n, 2): regions of equal k nearest sites, clipped to box.");

  py::class_<PyConstrainedVoronoi>(m, "ConstrainedVoronoi",
                                   "Constrained Voronoi diagram VD(S, L) (seed §5.3.2) as convex pieces tiling the box.")
      .def(py::init<const py::handle&, const py::handle&, const py::object&>(), py::arg("points"), py::arg("segments"),
           py::arg("box") = py::none(),
           "points: float64 (n, 2); segments: int64 (m, 2) point indices; box: (xmin, ymin, xmax, ymax), default around the points")
      .def_property_readonly("cells", &PyConstrainedVoronoi::cells, "One counter-clockwise convex (k, 2) polygon per piece.")
      .def_property_readonly("sites", &PyConstrainedVoronoi::sites, "int64 per piece: the site whose region it is in.")
      .def_property_readonly("constraints", &PyConstrainedVoronoi::constraints,
                             "(m, 2) int64: the segments, split at sites on them.")
      .def_property_readonly("box", &PyConstrainedVoronoi::box)
      .def("visible", &PyConstrainedVoronoi::visible, py::arg("point"), py::arg("site"),
           "Whether the segment from point = (x, y) to the site crosses no constraint.")
      .def("stats", &PyConstrainedVoronoi::stats, "dict: sites, distinct, segments, pieces, cells, max_candidates")
      .def("validate", &PyConstrainedVoronoi::validate, "Checks every invariant; raises geods.Error if one fails.");
  m.def("constrained_voronoi",
        [](const py::handle& p, const py::handle& s, const py::object& box) { return PyConstrainedVoronoi(p, s, box); },
        py::arg("points"), py::arg("segments"), py::arg("box") = py::none(),
        "The constrained Voronoi diagram of points (n, 2) and non-crossing segments (m, 2) of point indices that block "
        "sight: each piece of the box belongs to its nearest visible site.");

  m.def(
      "smallest_color_spanning_circle",
      [](const py::handle& points, const py::handle& colors) {
        const std::vector<Vec2d> p = to_points(points, "smallest_color_spanning_circle");
        const py::array_t<std::int64_t> c = py::array_t<std::int64_t, py::array::forcecast>::ensure(colors);
        if (!c) throw Error("smallest_color_spanning_circle: colors must be integers");
        std::vector<std::uint32_t> labels;
        const auto flat = c.attr("ravel")().cast<py::array_t<std::int64_t>>();
        for (py::ssize_t i = 0; i < flat.size(); ++i) {
          const std::int64_t v = flat.at(i);
          if (v < 0 || v > std::int64_t(0xffffffff))
            throw Error("smallest_color_spanning_circle: color " + std::to_string(v) + " is not a non-negative 32-bit integer");
          labels.push_back(std::uint32_t(v));
        }
        const voronoi::ColorSpanningCircle r = [&] {
          py::gil_scoped_release release;
          return voronoi::smallest_color_spanning_circle(p, labels);
        }();
        return py::make_tuple(points_array(std::vector<Vec2d>{r.circle.center}).reshape({2}), r.circle.radius,
                              index_array(r.support));
      },
      py::arg("points"), py::arg("colors"),
      "Smallest circle holding a point of every color (colors: (n,) non-negative integers): "
      "(center, radius, support), support the 1 to 3 points on its boundary that define it.");
}

}  // namespace geods::python
