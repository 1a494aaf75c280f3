// geods.SegmentVoronoi (Voronoi diagram of segments and points, medial axis),
// geods.MotionPlanner and geods.plan_path (disc robot among polygons).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/motion_planning.hpp"
#include "geods/voronoi/segment_voronoi.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

using voronoi::MotionPlanner;
using voronoi::PathPlan;
using voronoi::PlanOptions;
using voronoi::SegmentVoronoi;

std::vector<double> rows_of(const py::object& x, std::size_t cols, const char* what) {
  if (x.is_none()) return {};
  const Rows<double> a = Rows<double>::ensure(x);
  if (!a) throw Error(std::string(what) + ": expected an array of numbers");
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || static_cast<std::size_t>(a.shape(1)) != cols)
    throw Error(std::string(what) + ": expected an (n, " + std::to_string(cols) + ") array");
  return std::vector<double>(a.data(), a.data() + a.size());
}

std::vector<std::vector<Vec2d>> polygons_of(const py::object& obstacles) {
  std::vector<std::vector<Vec2d>> out;
  for (const py::handle& ring : obstacles) out.push_back(points_of<double, 2>(ring, "obstacle", nullptr));
  return out;
}

AABB2d box_of(const SegmentVoronoi& v, const py::object& box) {
  if (box.is_none()) {
    AABB2d b = v.bounds();
    const Vec2d m = Vec2d::Constant(0.05 * std::max((b.hi - b.lo).maxCoeff(), 1e-9));
    return AABB2d(b.lo - m, b.hi + m);
  }
  const std::vector<double> c = box.cast<std::vector<double>>();
  if (c.size() != 4 || !(c[0] < c[2]) || !(c[1] < c[3])) throw Error("box must be (x0, y0, x1, y1) with x0 < x1, y0 < y1");
  return AABB2d(Vec2d(c[0], c[1]), Vec2d(c[2], c[3]));
}

py::dict plan_dict(const PathPlan& p) {
  py::dict d;
  d["found"] = p.found;
  d["reason"] = p.reason;
  d["path"] = p.found ? py::object(points_array(p.path)) : py::none();
  d["length"] = p.length;
  d["min_clearance"] = p.min_clearance;
  d["max_radius"] = p.max_radius;
  return d;
}

}  // namespace

void bind_segment_voronoi(py::module_& m) {
  py::class_<SegmentVoronoi, std::shared_ptr<SegmentVoronoi>>(m, "SegmentVoronoi",
                                                              "Voronoi diagram of segments (n, 4) and points (k, 2); "
                                                              "edges are lines and parabolic arcs")
      .def(py::init([](const py::object& segments, const py::object& points) {
             const std::vector<double> s = rows_of(segments, 4, "segments"), p = rows_of(points, 2, "points");
             return without_gil([&] { return std::make_shared<SegmentVoronoi>(p, s); });
           }),
           py::arg("segments"), py::arg("points") = py::none())
      .def("points", [](const SegmentVoronoi& v) {
        std::vector<Vec2d> p(v.num_points());
        for (std::uint32_t i = 0; i < p.size(); ++i) p[i] = v.point(i);
        return points_array(p);
      }, "Point sites (input points and segment endpoints, each once), float64 (k, 2)")
      .def("segments", [](const SegmentVoronoi& v) {
        std::vector<std::int64_t> s;
        for (std::uint32_t i = 0; i < v.num_segments(); ++i) s.insert(s.end(), {v.segment(i)[0], v.segment(i)[1]});
        return copy_array(s.data(), {static_cast<py::ssize_t>(v.num_segments()), 2});
      }, "Segment sites as point ids, int64 (m, 2); site id of segment j is num_points + j")
      .def_property_readonly("num_points", &SegmentVoronoi::num_points)
      .def_property_readonly("num_segments", &SegmentVoronoi::num_segments)
      .def("split_count", &SegmentVoronoi::split_count, "How many times input segments were split at points on them")
      .def("vertices", [](const SegmentVoronoi& v) {
        std::vector<double> x;
        for (const auto& p : v.vertices()) x.insert(x.end(), {p.position[0], p.position[1], p.clearance});
        return copy_array(x.data(), {static_cast<py::ssize_t>(v.vertices().size()), 3});
      }, "Voronoi vertices as rows (x, y, clearance): float64 (v, 3)")
      .def("edges", [](const SegmentVoronoi& v) {
        const auto& es = v.edges();
        std::vector<std::int64_t> sites, verts;
        std::vector<std::uint8_t> parabolic, primary;
        for (const auto& e : es) {
          sites.insert(sites.end(), {e.site[0], e.site[1]});
          verts.insert(verts.end(), {index_value(e.vertex[0]), index_value(e.vertex[1])});
          parabolic.push_back(e.parabolic);
          primary.push_back(e.primary);
        }
        py::dict d;
        d["sites"] = copy_array(sites.data(), {static_cast<py::ssize_t>(es.size()), 2});
        d["vertices"] = copy_array(verts.data(), {static_cast<py::ssize_t>(es.size()), 2});
        d["parabolic"] = bool_array(parabolic);
        d["primary"] = bool_array(primary);
        return d;
      }, "Edges: dict of sites (m, 2), vertices (m, 2; -1 for an unbounded end), parabolic, primary")
      .def("cells", [](const SegmentVoronoi& v) {
        py::list out;
        for (const auto& c : v.cells()) out.append(index_array(c));
        return out;
      }, "For each site, the ids of the edges bounding its cell")
      .def("medial_axis", [](const SegmentVoronoi& v) { return index_array(without_gil([&] { return v.medial_axis(); })); },
           "Ids of the primary edges inside the polygons the segments bound (even-odd): int64 (k,)")
      .def("sample_edge", [](const SegmentVoronoi& v, std::uint32_t e, double step, const py::object& box) {
        if (e >= v.edges().size()) throw Error("sample_edge: no edge " + std::to_string(e));
        return points_array(v.sample_edge(e, step, box_of(v, box)));
      }, py::arg("edge"), py::arg("step"), py::arg("box") = py::none(),
           "Points along an edge, at most about `step` apart, float64 (k, 2); unbounded ends clipped to box (x0, y0, x1, y1)")
      .def("edge_clearance", [](const SegmentVoronoi& v, std::uint32_t e) {
        if (e >= v.edges().size()) throw Error("edge_clearance: no edge " + std::to_string(e));
        return v.edge_clearance(e);
      }, "Least distance from the edge to its two sites")
      .def("site_distance", [](const SegmentVoronoi& v, std::uint32_t site, const py::object& x) {
        if (site >= v.num_sites()) throw Error("site_distance: no site " + std::to_string(site));
        return v.site_distance(site, point_of<double, 2>(x, "site_distance"));
      }, "Distance from x = (x, y) to a site (point or segment)")
      .def("validate", &SegmentVoronoi::validate, "Checks every invariant; raises geods.Error if one fails")
      .def("stats", [](const SegmentVoronoi& v) {
        const auto s = v.stats();
        py::dict d;
        d["input_points"] = s.input_points;
        d["input_segments"] = s.input_segments;
        d["points"] = s.points;
        d["segments"] = s.segments;
        d["splits"] = s.splits;
        d["vertices"] = s.vertices;
        d["edges"] = s.edges;
        d["parabolic_edges"] = s.parabolic_edges;
        d["secondary_edges"] = s.secondary_edges;
        d["infinite_edges"] = s.infinite_edges;
        d["bytes"] = s.bytes;
        return d;
      }, "dict: input_points, input_segments, points, segments, splits, vertices, edges, ..., bytes");

  py::class_<MotionPlanner, std::shared_ptr<MotionPlanner>>(m, "MotionPlanner",
                                                            "Disc robot planning among polygons on the segment Voronoi diagram")
      .def(py::init([](const py::object& obstacles, const py::object& bounds, double margin) {
             PlanOptions o;
             o.margin = margin;
             const auto polys = polygons_of(obstacles);
             if (bounds.is_none()) throw Error("MotionPlanner: bounds (x0, y0, x1, y1) are required");
             const std::vector<double> c = bounds.cast<std::vector<double>>();
             if (c.size() != 4) throw Error("MotionPlanner: bounds must be (x0, y0, x1, y1)");
             o.use_bounds = true;
             o.bounds = AABB2d(Vec2d(c[0], c[1]), Vec2d(c[2], c[3]));
             return without_gil([&] { return std::make_shared<MotionPlanner>(polys, o); });
           }),
           py::arg("obstacles"), py::arg("bounds"), py::arg("margin") = 0.25,
           "obstacles: polygons, each float64 (k, 2); bounds: (x0, y0, x1, y1)")
      .def("plan", [](const MotionPlanner& p, const py::object& start, const py::object& goal, double radius) {
        const Vec2d s = point_of<double, 2>(start, "start"), g = point_of<double, 2>(goal, "goal");
        return plan_dict(without_gil([&] { return p.plan(s, g, radius); }));
      }, py::arg("start"), py::arg("goal"), py::arg("radius"),
           "dict: found, reason, path (n, 2) or None, length, min_clearance, max_radius")
      .def("max_radius", [](const MotionPlanner& p, const py::object& start, const py::object& goal) {
        return p.max_radius(point_of<double, 2>(start, "start"), point_of<double, 2>(goal, "goal"));
      }, "The largest disc radius that can move from start to goal, each (x, y)")
      .def("clearance", [](const MotionPlanner& p, const py::object& x) { return p.clearance(point_of<double, 2>(x, "x")); },
           "Distance from x = (x, y) to the nearest obstacle");

  m.def("plan_path", [](const py::object& obstacles, const py::object& start, const py::object& goal, double radius,
                        double margin) {
    const auto polys = polygons_of(obstacles);
    const Vec2d s = point_of<double, 2>(start, "start"), g = point_of<double, 2>(goal, "goal");
    PlanOptions o;
    o.margin = margin;
    const PathPlan p = without_gil([&] { return voronoi::plan_path(polys, s, g, radius, o); });
    return py::make_tuple(p.found ? py::object(points_array(p.path)) : py::none(), p.found ? p.length : py::float_(INFINITY).cast<double>(),
                          p.found ? p.min_clearance : 0.0);
  }, py::arg("obstacles"), py::arg("start"), py::arg("goal"), py::arg("radius"), py::arg("margin") = 0.25,
        "Shortest path of a disc robot: (path (n, 2) or None, length (inf if none), min clearance)");
}

}  // namespace geods::python
