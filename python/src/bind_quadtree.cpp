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

#include "bindings.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/spatial/quadtree.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using spatial::Orthtree;

template <typename T>
using Rows = py::array_t<T, py::array::c_style | py::array::forcecast>;

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
      options.build = spatial::OrthtreeBuild::Morton;
    } else if (build != "topdown") {
      throw Error(std::string(kName) + ": build is 'topdown' or 'morton', got '" + build + "'");
    }
    if (points.dtype().is(py::dtype::of<float>())) {
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
    const std::uint32_t u = visit([&](const auto& t) { return t.neighbor(check_node(v), dir); });
    return u == spatial::kNoNode ? -1 : std::int64_t(u);
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
    const spatial::OrthtreeStats s = visit([](const auto& t) { return t.stats(); });
    py::dict d;
    d["points"] = s.points;
    d["nodes"] = s.nodes;
    d["leaves"] = s.leaves;
    d["empty_leaves"] = s.empty_leaves;
    d["depth"] = s.depth;
    d["bytes"] = s.bytes;
    return d;
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
    const std::uint32_t p = visit([&](const auto& t) { return t.node(check_node(v)).parent; });
    return p == spatial::kNoNode ? -1 : std::int64_t(p);
  }
  py::array_t<std::int64_t> node_points(std::int64_t v) const {
    return visit([&](const auto& t) {
      const auto& n = t.node(check_node(v));
      py::array_t<std::int64_t> out(py::ssize_t(n.end - n.begin));
      std::copy(t.permutation().begin() + n.begin, t.permutation().begin() + n.end, out.mutable_data());
      return out;
    });
  }
  py::array_t<std::int64_t> leaves() const {
    return visit([&](const auto& t) {
      std::vector<std::int64_t> out;
      for (std::uint32_t v = 0; v < t.nodes().size(); ++v)
        if (t.nodes()[v].leaf()) out.push_back(v);
      return py::array_t<std::int64_t>(py::ssize_t(out.size()), out.data());
    });
  }

  // ------------------------------------------------------------ queries
  std::int64_t locate(const py::handle& p) const {
    return visit([&](const auto& t) {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      const std::uint32_t v = t.locate(one_point<T>(p, "locate"));
      return v == spatial::kNoNode ? std::int64_t(-1) : std::int64_t(v);
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
      return py::array_t<std::int64_t>(py::ssize_t(found.size()),
                                       std::vector<std::int64_t>(found.begin(), found.end()).data());
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
      const auto [rows, single] = many_points<T>(q, "query");
      const std::size_t m = std::size_t(rows.shape(0));
      py::array_t<double> distances(std::vector<py::ssize_t>{py::ssize_t(m), py::ssize_t(k)});
      py::array_t<std::int64_t> indices(std::vector<py::ssize_t>{py::ssize_t(m), py::ssize_t(k)});
      double* d = distances.mutable_data();
      std::int64_t* idx = indices.mutable_data();
      std::fill(d, d + m * k, std::numeric_limits<double>::infinity());
      std::fill(idx, idx + m * k, -1);
      for (std::size_t i = 0; i < m; ++i) {
        const auto found = t.query(row<T>(rows, i), k);
        for (std::size_t j = 0; j < found.size(); ++j) {
          d[i * k + j] = std::sqrt(double(found[j].squared_distance));
          idx[i * k + j] = found[j].index;
        }
      }
      if (single) return py::make_tuple(distances.reshape({py::ssize_t(k)}), indices.reshape({py::ssize_t(k)}));
      return py::make_tuple(distances, indices);
    });
  }

  py::object query_radius(const py::handle& q, double r) const {
    return visit([&](const auto& t) -> py::object {
      using T = typename std::decay_t<decltype(t)>::Scalar;
      const auto [rows, single] = many_points<T>(q, "query_radius");
      py::list out;
      for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
        const auto found = t.query_radius(row<T>(rows, std::size_t(i)), r);
        py::array_t<std::int64_t> idx(py::ssize_t(found.size()));
        for (std::size_t j = 0; j < found.size(); ++j) idx.mutable_data()[j] = found[j].index;
        out.append(idx);
      }
      if (single) return out[0];
      return out;
    });
  }

 private:
  template <typename T>
  void make(const py::array& points, const spatial::OrthtreeOptions& options) {
    const auto rows = Rows<T>::ensure(points);
    if (!rows) throw Error(std::string(kName) + ": points must be numbers");
    const spatial::PointView<T> view(rows.data(), std::size_t(rows.shape(0)), Dim);
    py::gil_scoped_release release;
    tree_ = Orthtree<T, Dim>(view, options);  // copies the points
  }

  static py::array_t<double> vector(const Vec<double, Dim>& v) { return py::array_t<double>(Dim, v.data()); }

  template <typename T>
  static Vec<T, Dim> one_point(const py::handle& p, const char* what) {
    const auto a = Rows<T>::ensure(p);
    if (!a || a.ndim() != 1 || a.shape(0) != Dim)
      throw Error(std::string(kName) + "." + what + ": expected a point of shape (" + std::to_string(Dim) + ",)");
    Vec<T, Dim> v;
    for (int i = 0; i < Dim; ++i) v[i] = a.data()[i];
    return v;
  }

  // (m, Dim) rows, and whether a single (Dim,) point was given.
  template <typename T>
  static std::pair<Rows<T>, bool> many_points(const py::handle& q, const char* what) {
    auto a = Rows<T>::ensure(q);
    if (a && a.ndim() == 1 && a.shape(0) == Dim) return {a.reshape({py::ssize_t(1), py::ssize_t(Dim)}), true};
    if (a && a.ndim() == 2 && a.shape(1) == Dim) return {a, false};
    throw Error(std::string(kName) + "." + what + ": expected shape (" + std::to_string(Dim) + ",) or (m, " +
                std::to_string(Dim) + ")");
  }

  template <typename T>
  static Vec<T, Dim> row(const Rows<T>& rows, std::size_t i) {
    Vec<T, Dim> v;
    for (int a = 0; a < Dim; ++a) v[a] = rows.data()[i * Dim + a];
    return v;
  }

  AnyTree tree_;
};

template <int Dim>
void bind_orthtree(py::module_& m, const char* doc) {
  using Py = PyOrthtree<Dim>;
  py::class_<Py>(m, Py::kName, doc)
      .def(py::init<const py::array&, std::size_t, const py::object&, const std::string&>(), py::arg("points"),
           py::arg("bucket") = 1, py::arg("max_depth") = py::none(), py::arg("build") = "topdown")
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
      .def("locate", &Py::locate, py::arg("p"), "The leaf whose cell contains p, or -1 outside the root cell.")
      .def("query_box", &Py::query_box, py::arg("lo"), py::arg("hi"),
           "Indices (ascending) of the points p with lo <= p <= hi.")
      .def("count_box", &Py::count_box, py::arg("lo"), py::arg("hi"), "Number of points with lo <= p <= hi.")
      .def("query", &Py::query, py::arg("q"), py::arg("k") = 1,
           "k nearest neighbours of one point or of m points: (distances float64, indices int64), each (k,) or "
           "(m, k), ascending by distance, ties by index; -1 / inf where fewer than k points exist.")
      .def("query_radius", &Py::query_radius, py::arg("q"), py::arg("r"),
           "Indices within distance r (inclusive), sorted by distance (a list of arrays for (m, d) queries).")
      .def("node_bounds", &Py::node_bounds, py::arg("node"), "(lo, hi) of the node's square / cube, float64.")
      .def("children", &Py::children, py::arg("node"), "The node's children in slot order (bit a = high half of axis a); [] for a leaf.")
      .def("is_leaf", &Py::is_leaf, py::arg("node"))
      .def("depth", &Py::depth, py::arg("node"))
      .def("parent", &Py::parent, py::arg("node"), "The parent node, -1 for the root.")
      .def("node_points", &Py::node_points, py::arg("node"), "Indices of the points in the node's cell.")
      .def("leaves", &Py::leaves, "Indices of all leaves.")
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
