// Python bindings of the Voronoi side of the voronoi module: geods.Voronoi2,
// geods.MetricVoronoi, and the applications (emst, closest_pair, circles...).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "without_gil.hpp"
#include "bindings.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/circles.hpp"
#include "geods/voronoi/metric_voronoi.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/proximity.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using voronoi::Voronoi2;
// An (n, 2) array (or a single point (2,) when `single` is allowed) as points.
std::vector<Vec2d> to_points(const py::handle& object, const char* what, bool* single = nullptr) {
  return points_of<double, 2>(object, what, single);
}

AABB2d to_box(const py::object& box, const char* what) {
  const std::vector<double> v = box.cast<std::vector<double>>();
  if (v.size() != 4 || !(v[0] < v[2]) || !(v[1] < v[3]))
    throw Error(std::string(what) + ": box must be (x0, y0, x1, y1) with x0 < x1 and y0 < y1");
  return AABB2d({v[0], v[1]}, {v[2], v[3]});
}

py::list to_polygons(const std::vector<std::vector<Vec2d>>& cells) {
  py::list out;
  for (const auto& cell : cells) out.append(points_array(cell));
  return out;
}

// The nearest site of each query ((m, 2) -> (m,) int64, or (2,) -> int) by a locator.
template <typename Locator>
py::object nearest_sites(const Locator& locator, const py::handle& queries, const char* what) {
  bool single = false;
  const std::vector<Vec2d> q = to_points(queries, what, &single);
  const std::vector<std::uint32_t> result = without_gil([&] { return locator.nearest_batch(q); });
  if (single) return py::int_(result[0]);
  return index_array(result);
}

class PyVoronoi2 {
 public:
  PyVoronoi2(const py::handle& points, const py::object& box) {
    const std::vector<Vec2d> p = to_points(points, "Voronoi2");
    {
      py::gil_scoped_release release;
      diagram_ = std::make_unique<Voronoi2>(p);
    }
    box_ = box.is_none() ? diagram_->default_box() : to_box(box, "Voronoi2");
  }
  PyVoronoi2(Voronoi2 diagram, const py::object& box)
      : diagram_(std::make_unique<Voronoi2>(std::move(diagram))),
        box_(box.is_none() ? diagram_->default_box() : to_box(box, "Voronoi2")) {}

  void save(const std::filesystem::path& path) const { diagram_->save(path); }
  static PyVoronoi2 load(const std::filesystem::path& path, const py::object& box) {
    return PyVoronoi2(Voronoi2::load(path), box);
  }

  py::tuple box() const { return py::make_tuple(box_.lo[0], box_.lo[1], box_.hi[0], box_.hi[1]); }
  py::array_t<double> points() const { return points_array(diagram_->points()); }
  py::array_t<double> vertices() const { return points_array(diagram_->vertices().span()); }

  py::list cells() const {
    const std::vector<std::vector<Vec2d>> cells = without_gil([&] { return diagram_->cell_polygons(box_); });
    return to_polygons(cells);
  }

  // One row per edge (a pair of twin half-edges): left site, right site, origin, target (-1: infinity).
  py::array_t<std::int64_t> edges() const {
    const auto& e = diagram_->edges();
    std::vector<std::uint32_t> rows;
    for (std::uint32_t k = 0; k < e.size(); ++k)
      if (e[k].twin > k) rows.insert(rows.end(), {e[k].site, diagram_->opposite_site(k), e[k].origin, e[k].target});
    return index_array(rows, {py::ssize_t(rows.size() / 4), 4});  // kInfinity becomes -1
  }

  // Unit direction from origin to target of each row of edges().
  py::array_t<double> edge_directions() const {
    std::vector<Vec2d> d;
    for (std::uint32_t k = 0; k < diagram_->edges().size(); ++k)
      if (diagram_->edges()[k].twin > k) d.push_back(diagram_->direction(k));
    return points_array(d);
  }

  // Each row of edges() clipped to the box: x0, y0, x1, y1 (NaN when outside).
  py::array_t<double> edge_segments() const {
    std::vector<double> rows;
    const double nan = std::nan("");
    for (std::uint32_t k = 0; k < diagram_->edges().size(); ++k) {
      if (diagram_->edges()[k].twin < k) continue;
      const auto s = diagram_->clipped_edge(k, box_);
      rows.insert(rows.end(), s ? std::initializer_list<double>{s->first[0], s->first[1], s->second[0], s->second[1]}
                                : std::initializer_list<double>{nan, nan, nan, nan});
    }
    return copy_array(rows.data(), {py::ssize_t(rows.size() / 4), 4});
  }

  py::array_t<std::int64_t> representatives() const {
    std::vector<std::uint32_t> r(diagram_->size());
    for (std::uint32_t i = 0; i < r.size(); ++i) r[i] = diagram_->representative(i);
    return index_array(r);
  }

  py::array_t<std::int64_t> neighbors(std::uint32_t site) const {
    check_index(site);
    const auto n = diagram_->neighbors(diagram_->representative(site));
    return index_array(std::vector<std::uint32_t>(n.begin(), n.end()));
  }

  // method: the locator's name, SlabLocator or WalkLocator, in lower case without "Locator".
  py::object nearest(const py::handle& queries, const std::string& method) {
    if (method == "slab") {
      if (!slab_) slab_ = std::make_unique<voronoi::SlabLocator>(*diagram_);
      return nearest_sites(*slab_, queries, "Voronoi2.nearest");
    }
    if (method == "walk") return nearest_sites(walk(), queries, "Voronoi2.nearest");
    throw Error("Voronoi2.nearest: method must be 'slab' or 'walk', got '" + method + "'");
  }

  py::array_t<std::int64_t> k_nearest(const py::handle& query, std::size_t k) {
    bool single = false;
    const std::vector<Vec2d> q = to_points(query, "Voronoi2.k_nearest", &single);
    if (!single) throw Error("Voronoi2.k_nearest: expected one query point (2,)");
    return index_array(voronoi::k_nearest_sites(walk(), q[0], k));
  }

  py::dict stats() const {
    return stats_dict(diagram_->stats());
  }

  void validate() const { diagram_->validate(); }
  std::size_t size() const { return diagram_->size(); }
  const Voronoi2& diagram() const { return *diagram_; }

 private:
  void check_index(std::uint32_t i) const {
    if (i >= diagram_->size()) throw Error("Voronoi2: point index " + std::to_string(i) + " out of range");
  }
  const voronoi::WalkLocator& walk() {
    if (!walk_) walk_ = std::make_unique<voronoi::WalkLocator>(*diagram_);
    return *walk_;
  }

  std::unique_ptr<Voronoi2> diagram_;
  AABB2d box_;
  std::unique_ptr<voronoi::SlabLocator> slab_;
  std::unique_ptr<voronoi::WalkLocator> walk_;
};

// geods.SlabLocator and geods.WalkLocator over a Voronoi2, which they keep alive.
template <typename Locator>
class PyLocator {
 public:
  explicit PyLocator(const PyVoronoi2& v) : locator_(v.diagram()) {}
  py::object nearest(const py::handle& queries) const { return nearest_sites(locator_, queries, "nearest"); }
  const Locator& locator() const { return locator_; }

 private:
  Locator locator_;
};

class PyMetricVoronoi {
 public:
  PyMetricVoronoi(const py::handle& points, const std::string& metric, const py::object& box) {
    const std::vector<Vec2d> p = to_points(points, "MetricVoronoi");
    const voronoi::Metric m = voronoi::parse_metric(metric);
    const AABB2d b = box.is_none() ? voronoi::frame_around(p) : to_box(box, "MetricVoronoi");
    py::gil_scoped_release release;
    diagram_ = std::make_unique<voronoi::MetricVoronoi>(p, m, b);
  }
  std::string metric() const { return voronoi::metric_name(diagram_->metric()); }
  py::tuple box() const {
    const AABB2d& b = diagram_->box();
    return py::make_tuple(b.lo[0], b.lo[1], b.hi[0], b.hi[1]);
  }
  py::list cells() const { return to_polygons(diagram_->cells()); }
  // One row per piece of the diagram: site a, site b (integer columns) ...
  py::tuple edges() const {
    std::vector<std::uint32_t> sites;
    std::vector<double> segments;
    for (const auto& e : diagram_->edges()) {
      sites.insert(sites.end(), {e.a, e.b});
      segments.insert(segments.end(), {e.p0[0], e.p0[1], e.p1[0], e.p1[1]});
    }
    return py::make_tuple(index_array(sites, {py::ssize_t(sites.size() / 2), 2}),
                          copy_array(segments.data(), {py::ssize_t(segments.size() / 4), 4}));
  }
  py::dict stats() const { return stats_dict(diagram_->stats()); }
  void validate() const { diagram_->validate(); }

 private:
  std::unique_ptr<voronoi::MetricVoronoi> diagram_;
};

}  // namespace

void bind_voronoi(py::module_& m) {
  py::class_<PyVoronoi2>(m, "Voronoi2",
                         "Voronoi diagram of 2D points, the dual of their Delaunay triangulation (seed §5.1).\n"
                         "box = (x0, y0, x1, y1) clips the cells (default: the points' bounding box grown by 25%).")
      .def(py::init<const py::handle&, const py::object&>(), py::arg("points"), py::arg("box") = py::none(),
           "points: float64 (n, 2)")
      .def("__len__", &PyVoronoi2::size)
      .def("save", &PyVoronoi2::save, py::arg("path"), "Writes the diagram to a geods archive.")
      .def_static("load", &PyVoronoi2::load, py::arg("path"), py::arg("box") = py::none(),
                  "Reads a diagram written by save(); box as in the constructor.")
      .def_property_readonly("box", &PyVoronoi2::box)
      .def_property_readonly("points", &PyVoronoi2::points)
      .def_property_readonly("cells", &PyVoronoi2::cells,
                             "One counter-clockwise (k, 2) polygon per input point, clipped to box "
                             "(duplicates repeat their first occurrence's cell).")
      .def_property_readonly("vertices", &PyVoronoi2::vertices, "(v, 2) Voronoi vertices (circumcentres; co-circular ones merged).")
      .def_property_readonly("edges", &PyVoronoi2::edges,
                             "(m, 4) int64 per edge: the site on its left, the site on its right, origin and "
                             "target vertex (-1: the edge runs to infinity).")
      .def_property_readonly("edge_directions", &PyVoronoi2::edge_directions, "(m, 2) unit direction origin -> target.")
      .def_property_readonly("edge_segments", &PyVoronoi2::edge_segments,
                             "(m, 4) each edge clipped to box: x0, y0, x1, y1 (NaN if outside).")
      .def_property_readonly("representatives", &PyVoronoi2::representatives, "First occurrence of each point.")
      .def("neighbors", &PyVoronoi2::neighbors, py::arg("i"), "Delaunay neighbours of point i's site: int64 (k,).")
      .def("nearest", &PyVoronoi2::nearest, py::arg("queries"), py::arg("method") = "walk",
           "Index of a nearest site of each query ((m, 2) -> (m,), or (2,) -> int): 'walk' (WalkLocator, "
           "O(n) memory) or 'slab' (SlabLocator, Theorem 8: O(log n) queries, up to O(n^1.5) memory).")
      .def("k_nearest", &PyVoronoi2::k_nearest, py::arg("query"), py::arg("k"),
           "The k nearest distinct sites of one query point (x, y), nearest first: int64 (k,).")
      .def("stats", &PyVoronoi2::stats, "dict: sites, distinct, vertices, edges, unbounded_cells, bytes")
      .def("validate", &PyVoronoi2::validate, "Checks every invariant; raises geods.Error if one fails.");

  py::class_<PyLocator<voronoi::SlabLocator>>(
      m, "SlabLocator", "The slab structure of seed Theorem 8 over a Voronoi2: O(log n) nearest-site queries.")
      .def(py::init<const PyVoronoi2&>(), py::arg("voronoi"), py::keep_alive<1, 2>())
      .def("nearest", &PyLocator<voronoi::SlabLocator>::nearest, py::arg("queries"),
           "Index of a nearest site of each query ((m, 2) -> (m,), or (2,) -> int).")
      .def(
          "stats", [](const PyLocator<voronoi::SlabLocator>& l) { return stats_dict(l.locator().stats()); },
          "dict: slabs, crossings, max_crossings, bytes");
  py::class_<PyLocator<voronoi::WalkLocator>>(m, "WalkLocator",
                                              "Nearest sites by walking in the Delaunay graph of a Voronoi2.")
      .def(py::init<const PyVoronoi2&>(), py::arg("voronoi"), py::keep_alive<1, 2>())
      .def("nearest", &PyLocator<voronoi::WalkLocator>::nearest, py::arg("queries"),
           "Index of a nearest site of each query ((m, 2) -> (m,), or (2,) -> int).");

  py::class_<PyMetricVoronoi>(m, "MetricVoronoi",
                              "Voronoi diagram under metric 'l1', 'linf' or 'l2', clipped to box (seed §5.3.3).")
      .def(py::init<const py::handle&, const std::string&, const py::object&>(), py::arg("points"),
           py::arg("metric") = "l1", py::arg("box") = py::none(),
           "points: float64 (n, 2); box: (xmin, ymin, xmax, ymax)")
      .def_property_readonly("metric", &PyMetricVoronoi::metric)
      .def_property_readonly("box", &PyMetricVoronoi::box)
      .def_property_readonly("cells", &PyMetricVoronoi::cells, "One counter-clockwise (k, 2) polygon per input point.")
      .def_property_readonly("edges", &PyMetricVoronoi::edges,
                             "(sites (m, 2) int64, segments (m, 4) float64): bisector pieces inside the box.")
      .def("stats", &PyMetricVoronoi::stats, "dict: sites, distinct, edges, cell_vertices, max_candidates")
      .def("validate", &PyMetricVoronoi::validate, "Checks every invariant; raises geods.Error if one fails.");

  // (n, 3) points take the 3D versions (from Delaunay3), anything else the 2D ones.
  const auto three_columns = [](const py::handle& points) {
    const py::array a = py::array::ensure(points);
    return a && a.ndim() == 2 && a.shape(1) == 3;
  };
  m.def(
      "emst",
      [three_columns](const py::handle& points) {
        voronoi::SpanningTree tree;
        if (three_columns(points)) {
          const std::vector<Vec3d> p = points_of<double, 3>(points, "emst");
          tree = without_gil([&] { return voronoi::emst(p); });
        } else {
          const std::vector<Vec2d> p = to_points(points, "emst");
          tree = without_gil([&] { return voronoi::emst(p); });
        }
        std::vector<std::uint32_t> ends;
        for (const auto& [a, b] : tree.edges) ends.insert(ends.end(), {a, b});
        return py::make_tuple(index_array(ends, {py::ssize_t(tree.edges.size()), 2}), tree.length);
      },
      py::arg("points"),
      "Euclidean minimum spanning tree of (n, 2) or (n, 3) points: ((n - 1, 2) int64 edges by increasing length, "
      "total length).");
  m.def(
      "closest_pair",
      [three_columns](const py::handle& points) {
        const voronoi::ClosestPair c = three_columns(points)
                                           ? voronoi::closest_pair(points_of<double, 3>(points, "closest_pair"))
                                           : voronoi::closest_pair(to_points(points, "closest_pair"));
        return py::make_tuple(c.i, c.j, c.distance);
      },
      py::arg("points"), "The two nearest of (n, 2) or (n, 3) points: (i, j, distance) with i < j.");
  m.def(
      "all_nearest_neighbors",
      [three_columns](const py::handle& points) {
        return index_array(three_columns(points)
                               ? voronoi::all_nearest_neighbors(points_of<double, 3>(points, "all_nearest_neighbors"))
                               : voronoi::all_nearest_neighbors(to_points(points, "all_nearest_neighbors")));
      },
      py::arg("points"), "For each of (n, 2) or (n, 3) points the index of its nearest other point: int64 (n,).");
  m.def(
      "largest_empty_circle",
      [](const py::handle& points) {
        const voronoi::Circle c = voronoi::largest_empty_circle(to_points(points, "largest_empty_circle"));
        return py::make_tuple(points_array(std::vector<Vec2d>{c.center}).reshape({2}), c.radius);
      },
      py::arg("points"), "Largest circle centred in the convex hull with no point inside: (center, radius).");
  m.def(
      "smallest_enclosing_circle",
      [](const py::handle& points, std::uint64_t seed) {
        const voronoi::Circle c = voronoi::smallest_enclosing_circle(to_points(points, "smallest_enclosing_circle"), seed);
        return py::make_tuple(points_array(std::vector<Vec2d>{c.center}).reshape({2}), c.radius);
      },
      py::arg("points"), py::arg("seed") = 0, "Smallest circle containing every point (Welzl): (center, radius).");
}

}  // namespace geods::python
