// Python bindings of the quadtree and octree: geods.Quadtree, geods.Octree.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <variant>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/spatial/quadtree.hpp"
#include "geods/spatial/stats_fields.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using spatial::Orthtree;

// "N"/"S"/"E"/"W", "+x"/"-x"/"+y"/"-y"/"+z"/"-z", or the integer 2 * axis + (1 if negative).
spatial::Direction parse_direction(const py::handle& d, int dim, const char* cls) {
  int value = -1;
  if (py::isinstance<py::str>(d)) {
    const std::string s = d.cast<std::string>();
    const char* names[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    for (int i = 0; i < 6; ++i)
      if (s == names[i]) value = i;
    if (s == "E") value = 0;
    if (s == "W") value = 1;
    if (s == "N") value = 2;
    if (s == "S") value = 3;
    if (value < 0) throw Error(std::string(cls) + ".neighbor: unknown direction '" + s + "' (N, S, E, W or +x, -x, ...)");
  } else {
    value = d.cast<int>();
  }
  if (value < 0 || value >= 2 * dim)
    throw Error(std::string(cls) + ".neighbor: direction " + std::to_string(value) + " is not in [0, " +
                std::to_string(2 * dim) + ")");
  return spatial::Direction(value);
}

template <int Dim>
class PyOrthtree {
 public:
  using AnyTree = std::variant<Orthtree<float, Dim>, Orthtree<double, Dim>>;
  static constexpr const char* kName = Dim == 2 ? "Quadtree" : "Octree";

  PyOrthtree(const py::array& points, std::size_t bucket, const py::object& max_depth, const std::string& build) {
    if (points.ndim() != 2 || points.shape(1) != Dim)
      throw Error(std::string(kName) + ": points must be an (n, " + std::to_string(Dim) + ") array");
    spatial::OrthtreeOptions options;
    options.bucket = bucket;
    options.max_depth = max_depth.is_none() ? -1 : max_depth.cast<int>();
    if (max_depth.is_none() == false && options.max_depth < 0)
      throw Error(std::string(kName) + ": max_depth must be >= 0");
    if (build == "morton") {
      options.build = spatial::OrthtreeBuild::morton;
    } else if (build != "top_down" && build != "topdown") {  // topdown: the deprecated spelling
      throw Error(std::string(kName) + ": build is 'top_down' or 'morton', got '" + build + "'");
    }
    if (points.dtype().equal(py::dtype::of<float>())) {
      make<float>(points, options);
    } else {
      make<double>(points, options);
    }
  }
  explicit PyOrthtree(AnyTree tree) : tree_(std::move(tree)) {}

  template <typename F>
  decltype(auto) visit(F&& f) const {
    return std::visit(std::forward<F>(f), tree_);
  }

  std::size_t size() const {
    return visit([](const auto& t) { return t.size(); });
  }
  std::size_t num_nodes() const {
    return visit([](const auto& t) { return t.nodes().size(); });
  }
  py::dtype dtype() const {
    return visit([](const auto& t) { return py::dtype::of<typename std::decay_t<decltype(t)>::Scalar>(); });
  }
  bool is_balanced() const {
    return visit([](const auto& t) { return t.is_balanced(); });
  }

  std::uint32_t check_node(std::int64_t v) const {
    if (v < 0 || std::size_t(v) >= num_nodes())
      throw Error(std::string(kName) + ": node " + std::to_string(v) + " does not exist (" +
                  std::to_string(num_nodes()) + " nodes)");
    return std::uint32_t(v);
  }

  std::int64_t neighbor(std::int64_t v, const py::handle& direction) const {
    const spatial::Direction dir = parse_direction(direction, Dim, kName);
    return index_value(visit([&](const auto& t) { return t.neighbor(check_node(v), dir); }));
  }

  PyOrthtree balanced() const {
    py::gil_scoped_release release;
    return PyOrthtree(visit([](const auto& t) { return AnyTree(t.balanced()); }));
  }

  void validate() const {
    py::gil_scoped_release release;
    visit([](const auto& t) { t.validate(); });
  }

  void save(const std::filesystem::path& path) const {
    py::gil_scoped_release release;
    visit([&](const auto& t) { t.save(path); });
  }
  static PyOrthtree load(const std::filesystem::path& path) {
    py::gil_scoped_release release;
    const DType scalar = Archive::open(path, spatial::kOrthtreeArchiveKind, spatial::kOrthtreeArchiveVersion,
                                       Archive::Verify::structure_only)
                             .dtype("scalar");
    if (scalar == DType::f32) return PyOrthtree(AnyTree(Orthtree<float, Dim>::load(path)));
    return PyOrthtree(AnyTree(Orthtree<double, Dim>::load(path)));
  }

  py::dict stats() const {
    return stats_dict(visit([](const auto& t) { return t.stats(); }));
  }

  // ------------------------------------------------------------ node accessors
  py::tuple node_bounds(std::int64_t v) const {
    const AABB<double, Dim> box = visit([&](const auto& t) { return t.node_bounds(check_node(v)); });
    return py::make_tuple(vector(box.lo), vector(box.hi));
  }
  py::list children(std::int64_t v) const {
    const auto first = visit([&](const auto& t) { return t.node(check_node(v)).first_child; });
    py::list out;
    if (first != 0)
      for (std::uint32_t c = 0; c < (1u << Dim); ++c) out.append(first + c);
    return out;
  }
  bool is_leaf(std::int64_t v) const {
    return visit([&](const auto& t) { return t.node(check_node(v)).leaf(); });
  }
  std::uint32_t depth(std::int64_t v) const {
    return visit([&](const auto& t) { return t.node(check_node(v)).depth; });
  }
  std::int64_t parent(std::int64_t v) const {
    return index_value(visit([&](const auto& t) { return t.node(check_node(v)).parent; }));
  }
  py::array_t<std::int64_t> node_points(std::int64_t v) const {
    return visit([&](const auto& t) {
      const auto& n = t.node(check_node(v));
      return index_array(std::span<const std::uint32_t>(t.permutation()).subspan(n.begin, n.end - n.begin));
    });
  }
  py::array_t<std::int64_t> leaves() const {
    return visit([&](const auto& t) {
      std::vector<std::uint32_t> out;
      for (std::uint32_t v = 0; v < t.nodes().size(); ++v)
        if (t.nodes()[v].leaf()) out.push_back(v);
      return index_array(out);
    });
  }

  // ------------------------------------------------------------ queries
  std::int64_t locate(const py::handle& p) const {
    return visit([&](const auto& t) {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      return index_value(t.locate(one_point<T>(p, "locate")));
    });
  }

  py::array_t<std::int64_t> query_box(const py::handle& lo, const py::handle& hi) const {
    return visit([&](const auto& t) {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      const auto l = one_point<T>(lo, "query_box lo"), h = one_point<T>(hi, "query_box hi");
      std::vector<std::uint32_t> found;
      {
        py::gil_scoped_release release;
        found = t.query_box(l, h);
        std::sort(found.begin(), found.end());
      }
      return index_array(found);
    });
  }

  std::size_t count_box(const py::handle& lo, const py::handle& hi) const {
    return visit([&](const auto& t) {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      return t.count_box(one_point<T>(lo, "count_box lo"), one_point<T>(hi, "count_box hi"));
    });
  }

  py::tuple query(const py::handle& q, std::size_t k) const {
    return visit([&](const auto& t) {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      const PointRows<T> rows = point_rows<T>(q, Dim, std::string(kName) + ".query");
      std::vector<spatial::Neighbor<T>> result(rows.count * k);  // k per query, missing ones kNoIndex
      for (std::size_t i = 0; i < rows.count; ++i) {
        const auto found = t.query(rows.template point<Dim>(i), k);
        std::copy(found.begin(), found.end(), result.begin() + std::ptrdiff_t(i * k));
      }
      return neighbor_arrays(std::span<const spatial::Neighbor<T>>(result), rows.count, k, rows.single,
                             &spatial::Neighbor<T>::index);
    });
  }

  py::object query_radius(const py::handle& q, double r) const {
    return visit([&](const auto& t) -> py::object {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      const PointRows<T> rows = point_rows<T>(q, Dim, std::string(kName) + ".query_radius");
      std::vector<std::vector<spatial::Neighbor<T>>> result(rows.count);
      for (std::size_t i = 0; i < rows.count; ++i) result[i] = t.query_radius(rows.template point<Dim>(i), r);
      return neighbor_lists(result, rows.single, &spatial::Neighbor<T>::index);
    });
  }

 private:
  template <typename T>
  void make(const py::array& points, const spatial::OrthtreeOptions& options) {
    const PointRows<T> rows = point_rows<T>(points, Dim, kName, false);
    py::gil_scoped_release release;
    tree_ = Orthtree<T, Dim>(rows.view(), options);  // copies the points
  }

  static py::array_t<double> vector(const Vec<double, Dim>& v) { return py::array_t<double>(Dim, v.data()); }

  template <typename T>
  static Vec<T, Dim> one_point(const py::handle& p, const char* what) {
    return point_of<T, Dim>(p, std::string(kName) + "." + what);
  }

  AnyTree tree_;
};

template <int Dim>
void bind_orthtree(py::module_& m, const char* doc) {
  using Py = PyOrthtree<Dim>;
  py::class_<Py>(m, Py::kName, doc)
      .def(py::init<const py::array&, std::size_t, const py::object&, const std::string&>(), py::arg("points"),
           py::arg("bucket") = 1, py::arg("max_depth") = py::none(), py::arg("build") = "top_down",
           "points: (n, 2) for a Quadtree, (n, 3) for an Octree; float32 or float64 (kept as given)")
      .def("neighbor", &Py::neighbor, py::arg("node"), py::arg("direction"),
           "The deepest node of depth <= depth(node) across the face in `direction` ('N', 'S', 'E', 'W', '+x', "
           "'-x', '+y', '-y', '+z', '-z' or 0..5 = 2 * axis + negative); -1 at the boundary. O(depth).")
      .def("balanced", &Py::balanced, "A new, 2:1-balanced tree: face-adjacent leaves differ by at most one in depth.")
      .def("validate", &Py::validate, "Checks every invariant (and the 2:1 balance of balanced trees); raises if one fails.")
      .def("stats", &Py::stats, "dict: points, nodes, leaves, empty_leaves, depth, bytes")
      .def("save", &Py::save, py::arg("path"),
           "Writes the tree and its points to a geods archive (the file format of every structure).")
      .def_static("load", &Py::load, py::arg("path"),
                  "Maps a tree written by save(): its arrays are read in place from the file. Raises\n"
                  "ValueError for a truncated, corrupt or other file.")
      .def("locate", &Py::locate, py::arg("p"), "The leaf whose cell contains p = (x, y) or (x, y, z), or -1 outside the root cell.")
      .def("query_box", &Py::query_box, py::arg("lo"), py::arg("hi"),
           "Indices (int64 (k,), ascending) of the points p with lo <= p <= hi (corners (d,)).")
      .def("count_box", &Py::count_box, py::arg("lo"), py::arg("hi"), "Number of points with lo <= p <= hi (corners (d,)).")
      .def("query", &Py::query, py::arg("q"), py::arg("k") = 1,
           "k nearest neighbours of one point or of m points: (distances float64, indices int64), each (k,) or "
           "(m, k), ascending by distance, ties by index; -1 / inf where fewer than k points exist.")
      .def("query_radius", &Py::query_radius, py::arg("q"), py::arg("r"),
           "Indices within distance r (inclusive), sorted by distance (a list of arrays for (m, d) queries).")
      .def("node_bounds", &Py::node_bounds, py::arg("node"), "(lo, hi) of the node's square / cube, float64.")
      .def("children", &Py::children, py::arg("node"), "The node's children in slot order (bit a = high half of axis a); [] for a leaf.")
      .def("is_leaf", &Py::is_leaf, py::arg("node"), "Whether the node is a leaf.")
      .def("depth", &Py::depth, py::arg("node"), "The node's depth (the root is 0).")
      .def("parent", &Py::parent, py::arg("node"), "The parent node, -1 for the root.")
      .def("node_points", &Py::node_points, py::arg("node"), "Indices of the points in the node's cell: int64 (k,).")
      .def("leaves", &Py::leaves, "Indices of all leaves: int64 (leaves,).")
      .def("__len__", &Py::size)
      .def_property_readonly("num_nodes", &Py::num_nodes)
      .def_property_readonly("is_balanced", &Py::is_balanced)
      .def_property_readonly("dtype", &Py::dtype);
}

}  // namespace

void bind_quadtree(py::module_& m) {
  bind_orthtree<2>(m, R"doc(
Point quadtree (seed §2.1) over an (n, 2) float32 or float64 array (copied; other dtypes become float64).

The root is the smallest square enclosing the points (anchored at their low corner); a node
splits into four equal quadrants while it holds more than `bucket` points that do not all
coincide and is shallower than `max_depth` (default 32). Node 0 is the root.
build='morton' derives the same tree from sorted Morton keys (the linear quadtree).
)doc");
  bind_orthtree<3>(m, R"doc(
Point octree (seed §2.1) over an (n, 3) float32 or float64 array (copied; other dtypes become float64).

The root is the smallest cube enclosing the points; a node splits into eight equal octants
while it holds more than `bucket` points that do not all coincide and is shallower than
`max_depth` (default 21). Node 0 is the root.
)doc");
}

}  // namespace geods::python
