// Python bindings of the spatial module: geods.KdTree.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/error.hpp"
#include "geods/spatial/kd_tree_dimensions.hpp"
#include "geods/spatial/stats_fields.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using spatial::AnyKdTree;
using spatial::KdTree;

// float32 points stay float (half the memory, like the caller's array); anything else is float64.
using AnyTree = std::variant<AnyKdTree<float>, AnyKdTree<double>>;

class PyKdTree {
 public:
  PyKdTree(const py::array& points, std::size_t leaf_size, const std::string& layout) {
    const spatial::PointLayout point_layout = spatial::parse_point_layout(layout);
    if (points.ndim() != 2) throw Error("KdTree: points must be an (n, d) array, got " + std::to_string(points.ndim()) +
                                        " dimensions");
    if (points.dtype().equal(py::dtype::of<float>())) {
      build<float>(points, leaf_size, point_layout);
    } else {
      build<double>(points, leaf_size, point_layout);
    }
  }
  explicit PyKdTree(AnyTree tree) : tree_(std::move(tree)) {}

  static PyKdTree load(const std::filesystem::path& path, const std::string& layout) {
    const spatial::PointLayout point_layout = spatial::parse_point_layout(layout);
    const spatial::KdTreeFileInfo info = spatial::read_kd_tree_info(path);
    py::gil_scoped_release release;
    if (info.scalar == DType::f32) return PyKdTree(AnyTree(spatial::load_kd_tree<float>(path, info.dim, point_layout)));
    return PyKdTree(AnyTree(spatial::load_kd_tree<double>(path, info.dim, point_layout)));
  }

  // f(tree) with the tree's concrete KdTree<T, Dim>.
  template <typename F>
  decltype(auto) visit(F&& f) const {
    return std::visit([&](const auto& any) -> decltype(auto) { return std::visit(f, any); }, tree_);
  }

  std::size_t size() const {
    return visit([](const auto& t) { return t.size(); });
  }
  std::size_t dim() const {
    return visit([](const auto& t) { return t.dim(); });
  }
  std::string layout() const {
    return visit([](const auto& t) { return std::string(spatial::to_string(t.layout())); });
  }
  std::size_t leaf_size() const {
    return visit([](const auto& t) { return t.leaf_size(); });
  }
  py::dtype dtype() const {
    return visit([](const auto& t) { return py::dtype::of<typename std::decay_t<decltype(t)>::Scalar>(); });
  }

  py::tuple query(const py::handle& q, std::size_t k, double eps) const {
    return visit([&](const auto& tree) {
      using T = typename std::decay_t<decltype(tree)>::Scalar;
      const PointRows<T> rows = point_rows<T>(q, tree.dim(), "KdTree.query");
      std::vector<spatial::Neighbor<T>> result;
      {
        py::gil_scoped_release release;
        result = tree.query_batch(rows.view(), spatial::KnnRequest{k, eps});
      }
      return neighbor_arrays(std::span<const spatial::Neighbor<T>>(result), rows.count, k, rows.single,
                             &spatial::Neighbor<T>::index);
    });
  }

  py::object query_radius(const py::handle& q, double r) const {
    return visit([&](const auto& tree) -> py::object {
      using T = typename std::decay_t<decltype(tree)>::Scalar;
      const PointRows<T> rows = point_rows<T>(q, tree.dim(), "KdTree.query_radius");
      std::vector<std::vector<spatial::Neighbor<T>>> result;
      {
        py::gil_scoped_release release;
        result = tree.query_radius_batch(rows.view(), r);
      }
      return neighbor_lists(result, rows.single, &spatial::Neighbor<T>::index);
    });
  }

  py::array_t<std::int64_t> query_box(const py::handle& lo, const py::handle& hi) const {
    return visit([&](const auto& tree) {
      using T = typename std::decay_t<decltype(tree)>::Scalar;
      const PointRows<T> l = point_rows<T>(lo, tree.dim(), "KdTree.query_box lo");
      const PointRows<T> h = point_rows<T>(hi, tree.dim(), "KdTree.query_box hi");
      if (!l.single || !h.single) throw Error("KdTree.query_box: lo and hi are single points");
      std::vector<std::uint32_t> found;
      {
        py::gil_scoped_release release;
        found = tree.query_box(std::span<const T>(l.data(), tree.dim()), std::span<const T>(h.data(), tree.dim()));
        std::sort(found.begin(), found.end());
      }
      return index_array(found);
    });
  }

  py::object count_box(const py::handle& lo, const py::handle& hi) const {
    return visit([&](const auto& tree) -> py::object {
      using T = typename std::decay_t<decltype(tree)>::Scalar;
      const std::size_t d = tree.dim();
      const PointRows<T> l = point_rows<T>(lo, d, "KdTree.count_box lo");
      const PointRows<T> h = point_rows<T>(hi, d, "KdTree.count_box hi");
      if (l.count != h.count || l.single != h.single) throw Error("KdTree.count_box: lo and hi differ in shape");
      const std::size_t m = l.count;
      std::vector<T> boxes(m * 2 * d);
      for (std::size_t i = 0; i < m; ++i) {
        std::copy(l.data() + i * d, l.data() + (i + 1) * d, boxes.begin() + i * 2 * d);
        std::copy(h.data() + i * d, h.data() + (i + 1) * d, boxes.begin() + i * 2 * d + d);
      }
      std::vector<std::size_t> counts;
      {
        py::gil_scoped_release release;
        counts = tree.count_box_batch(spatial::PointView<T>(boxes.data(), m, 2 * d));
      }
      if (l.single) return py::int_(counts[0]);
      return index_array(counts);
    });
  }

  py::dict stats() const {
    return stats_dict(visit([](const auto& t) { return t.stats(); }));
  }
  void validate() const {
    visit([](const auto& t) { t.validate(); });
  }
  void save(const std::filesystem::path& path) const {
    visit([&](const auto& t) { t.save(path); });
  }

 private:
  template <typename T>
  void build(const py::array& points, std::size_t leaf_size, spatial::PointLayout layout) {
    // Zero-copy when every row is contiguous; otherwise one converted C-order copy.
    py::array_t<T> rows;
    const auto item = py::ssize_t(sizeof(T));
    if (points.dtype().equal(py::dtype::of<T>()) && (points.shape(1) <= 1 || points.strides(1) == item) &&
        points.strides(0) % item == 0 && points.strides(0) >= points.shape(1) * item) {
      rows = py::reinterpret_borrow<py::array_t<T>>(points);
    } else {
      rows = point_rows<T>(points, std::size_t(points.shape(1)), "KdTree", false).array;
    }
    const std::size_t n = std::size_t(rows.shape(0)), d = std::size_t(rows.shape(1));
    const std::size_t stride = rows.shape(0) > 1 ? std::size_t(rows.strides(0) / item) : d;
    const spatial::PointView<T> view(rows.data(), n, d, std::max(stride, d));
    {
      py::gil_scoped_release release;
      tree_ = spatial::make_kd_tree<T>(view, leaf_size, layout);
    }
    points_ = rows;  // the tree reads the array in place: keep it alive
  }

  AnyTree tree_;
  py::object points_;
};

}  // namespace

void bind_spatial(py::module_& m) {
  py::class_<PyKdTree>(m, "KdTree", R"doc(
Balanced k-d tree over n points of dimension d (float32 or float64; other dtypes become float64).

Built in O(n log n) by median splits on the axis of widest spread. The tree keeps a reference
to a row-contiguous `points` array (no copy of it): do not modify it while the tree is in use.
layout="tree_order" (the default) also keeps a copy of the points in leaf order, which the
k-NN, radius and box queries read contiguously; layout="zero_copy" reads them in place
(half the memory, slower queries on large inputs).
Queries are thread-safe and release the GIL; batches run in parallel.
)doc")
      .def(py::init<const py::array&, std::size_t, const std::string&>(), py::arg("points"),
           py::arg("leaf_size") = 10, py::arg("layout") = "tree_order",
           "points: (n, d), float32 or float64 (kept as given; other dtypes become float64); "
           "layout: tree_order or zero_copy")
      .def("query", &PyKdTree::query, py::arg("q"), py::arg("k") = 1, py::arg("eps") = 0.0,
           "k nearest neighbours of one point (d,) or of m points (m, d): (distances float64, indices int64), "
           "each (k,) or (m, k), ascending by distance, ties by index; -1 / inf where fewer than k points exist. "
           "eps > 0: each distance within (1 + eps) of the true one.")
      .def("query_radius", &PyKdTree::query_radius, py::arg("q"), py::arg("r"),
           "Indices within distance r (inclusive), sorted by distance: an int64 array for one point, a list of "
           "arrays for (m, d) queries.")
      .def("query_box", &PyKdTree::query_box, py::arg("lo"), py::arg("hi"),
           "Indices (int64 (k,), ascending) of the points p with lo <= p <= hi (corners (d,)).")
      .def("count_box", &PyKdTree::count_box, py::arg("lo"), py::arg("hi"),
           "Number of points with lo <= p <= hi (corners (d,)); for (m, d) corners an int64 (m,) array of counts.")
      .def("stats", &PyKdTree::stats, "dict: points, nodes, leaves, depth, bytes")
      .def("validate", &PyKdTree::validate, "Checks every invariant of the tree; raises if one fails.")
      .def("save", &PyKdTree::save, py::arg("path"),
           "Writes the tree and its points to a geods archive (the file format of every structure).")
      .def_static("load", &PyKdTree::load, py::arg("path"), py::arg("layout") = "zero_copy",
                  "Maps a tree written by save() (float32 or float64, any dimension): its arrays are read in\n"
                  "place from the file (layout=\"tree_order\": its points are then copied in leaf order).\n"
                  "Raises ValueError for a truncated, corrupt or other file.")
      .def_property_readonly("layout", &PyKdTree::layout, "tree_order or zero_copy (see the constructor)")
      .def("__len__", &PyKdTree::size)
      .def_property_readonly("dim", &PyKdTree::dim)
      .def_property_readonly("leaf_size", &PyKdTree::leaf_size)
      .def_property_readonly("dtype", &PyKdTree::dtype);
}

}  // namespace geods::python
