// Python bindings of the spatial module: geods.KdTree.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "bindings.hpp"
#include "geods/core/error.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using spatial::Dynamic;
using spatial::KdTree;

// float32 points stay float (half the memory, like the caller's array); anything else is float64.
// Dimensions 2 and 3 get the compile-time trees, others the run-time one.
using AnyTree = std::variant<KdTree<float, 2>, KdTree<float, 3>, KdTree<float, Dynamic>, KdTree<double, 2>,
                             KdTree<double, 3>, KdTree<double, Dynamic>>;

template <typename T>
AnyTree make_tree(spatial::PointView<T> view, std::size_t leaf_size) {
  if (view.dim == 2) return KdTree<T, 2>(view, leaf_size);
  if (view.dim == 3) return KdTree<T, 3>(view, leaf_size);
  return KdTree<T, Dynamic>(view, leaf_size);
}

template <typename T>
AnyTree load_tree(const std::filesystem::path& path, std::size_t dim) {
  if (dim == 2) return KdTree<T, 2>::load(path);
  if (dim == 3) return KdTree<T, 3>::load(path);
  return KdTree<T, Dynamic>::load(path);
}

template <typename T>
using Rows = py::array_t<T, py::array::c_style | py::array::forcecast>;

// Query points as C-order rows of the tree's scalar type; `single` if given as one point (d,).
template <typename T>
struct QueryRows {
  Rows<T> array;
  bool single;
  std::size_t count, dim;
  const T* data() const { return array.data(); }
  spatial::PointView<T> view() const { return {array.data(), count, dim}; }
};

template <typename T>
QueryRows<T> as_rows(const py::handle& q, std::size_t dim, const char* what) {
  auto a = Rows<T>::ensure(q);
  if (!a) throw Error(std::string(what) + ": expected an array of numbers");
  if (a.ndim() == 1 && std::size_t(a.shape(0)) == dim) return {a, true, 1, dim};
  if (a.ndim() == 2 && std::size_t(a.shape(1)) == dim) return {a, false, std::size_t(a.shape(0)), dim};
  throw Error(std::string(what) + ": expected shape (" + std::to_string(dim) + ",) or (m, " + std::to_string(dim) +
              ") for a tree of dimension " + std::to_string(dim));
}

class PyKdTree {
 public:
  PyKdTree(const py::array& points, std::size_t leaf_size) {
    if (points.ndim() != 2) throw Error("KdTree: points must be an (n, d) array, got " + std::to_string(points.ndim()) +
                                        " dimensions");
    if (points.dtype().is(py::dtype::of<float>())) {
      build<float>(points, leaf_size);
    } else {
      build<double>(points, leaf_size);
    }
  }
  explicit PyKdTree(AnyTree tree) : tree_(std::move(tree)) {}

  static PyKdTree load(const std::filesystem::path& path) {
    const spatial::KdTreeFileInfo info = spatial::read_kd_tree_info(path);
    py::gil_scoped_release release;
    return PyKdTree(info.scalar == DType::f32 ? load_tree<float>(path, info.dim) : load_tree<double>(path, info.dim));
  }

  std::size_t size() const {
    return std::visit([](const auto& t) { return t.size(); }, tree_);
  }
  std::size_t dim() const {
    return std::visit([](const auto& t) { return t.dim(); }, tree_);
  }
  std::size_t leaf_size() const {
    return std::visit([](const auto& t) { return t.leaf_size(); }, tree_);
  }
  py::dtype dtype() const {
    return std::visit([](const auto& t) { return py::dtype::of<typename std::decay_t<decltype(t)>::Scalar>(); },
                      tree_);
  }

  py::tuple query(const py::handle& q, std::size_t k, double eps) const {
    return std::visit(
        [&](const auto& tree) {
          using T = typename std::decay_t<decltype(tree)>::Scalar;
          const QueryRows<T> rows = as_rows<T>(q, tree.dim(), "KdTree.query");
          const bool single = rows.single;
          const spatial::PointView<T> view = rows.view();
          const spatial::KnnRequest request{k, eps};
          std::vector<spatial::Neighbor<T>> result;
          {
            py::gil_scoped_release release;
            result = tree.query_batch(view, request);
          }
          py::array_t<double> distances(std::vector<py::ssize_t>{py::ssize_t(view.count), py::ssize_t(k)});
          py::array_t<std::int64_t> indices(std::vector<py::ssize_t>{py::ssize_t(view.count), py::ssize_t(k)});
          double* d = distances.mutable_data();
          std::int64_t* idx = indices.mutable_data();
          for (std::size_t i = 0; i < result.size(); ++i) {
            const bool missing = result[i].index == spatial::kNoIndex;
            d[i] = missing ? std::numeric_limits<double>::infinity() : std::sqrt(double(result[i].squared_distance));
            idx[i] = missing ? -1 : std::int64_t(result[i].index);
          }
          if (single) return py::make_tuple(distances.reshape({py::ssize_t(k)}), indices.reshape({py::ssize_t(k)}));
          return py::make_tuple(distances, indices);
        },
        tree_);
  }

  py::object query_radius(const py::handle& q, double r) const {
    return std::visit(
        [&](const auto& tree) -> py::object {
          using T = typename std::decay_t<decltype(tree)>::Scalar;
          const QueryRows<T> rows = as_rows<T>(q, tree.dim(), "KdTree.query_radius");
          std::vector<std::vector<spatial::Neighbor<T>>> result;
          {
            py::gil_scoped_release release;
            result = tree.query_radius_batch(rows.view(), r);
          }
          py::list out;
          for (const auto& neighbors : result) {
            py::array_t<std::int64_t> idx(py::ssize_t(neighbors.size()));
            std::int64_t* p = idx.mutable_data();
            for (std::size_t i = 0; i < neighbors.size(); ++i) p[i] = neighbors[i].index;
            out.append(idx);
          }
          if (rows.single) return out[0];
          return out;
        },
        tree_);
  }

  py::array_t<std::int64_t> query_box(const py::handle& lo, const py::handle& hi) const {
    return std::visit(
        [&](const auto& tree) {
          using T = typename std::decay_t<decltype(tree)>::Scalar;
          const QueryRows<T> l = as_rows<T>(lo, tree.dim(), "KdTree.query_box lo");
          const QueryRows<T> h = as_rows<T>(hi, tree.dim(), "KdTree.query_box hi");
          if (!l.single || !h.single) throw Error("KdTree.query_box: lo and hi are single points");
          std::vector<std::uint32_t> found;
          {
            py::gil_scoped_release release;
            found = tree.query_box(std::span<const T>(l.data(), tree.dim()), std::span<const T>(h.data(), tree.dim()));
            std::sort(found.begin(), found.end());
          }
          return py::array_t<std::int64_t>(py::ssize_t(found.size()),
                                           std::vector<std::int64_t>(found.begin(), found.end()).data());
        },
        tree_);
  }

  py::object count_box(const py::handle& lo, const py::handle& hi) const {
    return std::visit(
        [&](const auto& tree) -> py::object {
          using T = typename std::decay_t<decltype(tree)>::Scalar;
          const std::size_t d = tree.dim();
          const QueryRows<T> l = as_rows<T>(lo, d, "KdTree.count_box lo");
          const QueryRows<T> h = as_rows<T>(hi, d, "KdTree.count_box hi");
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
          return py::array_t<std::int64_t>(py::ssize_t(m), std::vector<std::int64_t>(counts.begin(), counts.end()).data());
        },
        tree_);
  }

  py::dict stats() const {
    const spatial::KdTreeStats s = std::visit([](const auto& t) { return t.stats(); }, tree_);
    py::dict d;
    d["points"] = s.points;
    d["nodes"] = s.nodes;
    d["leaves"] = s.leaves;
    d["depth"] = s.depth;
    d["bytes"] = s.bytes;
    return d;
  }
  void validate() const {
    std::visit([](const auto& t) { t.validate(); }, tree_);
  }
  void save(const std::filesystem::path& path) const {
    std::visit([&](const auto& t) { t.save(path); }, tree_);
  }

 private:
  template <typename T>
  void build(const py::array& points, std::size_t leaf_size) {
    // Zero-copy when every row is contiguous; otherwise one converted C-order copy.
    py::array_t<T> rows;
    const auto item = py::ssize_t(sizeof(T));
    if (points.dtype().is(py::dtype::of<T>()) && (points.shape(1) <= 1 || points.strides(1) == item) &&
        points.strides(0) % item == 0 && points.strides(0) >= points.shape(1) * item) {
      rows = py::reinterpret_borrow<py::array_t<T>>(points);
    } else {
      rows = Rows<T>::ensure(points);
      if (!rows) throw Error("KdTree: points must be numbers");
    }
    const std::size_t n = std::size_t(rows.shape(0)), d = std::size_t(rows.shape(1));
    const std::size_t stride = rows.shape(0) > 1 ? std::size_t(rows.strides(0) / item) : d;
    const spatial::PointView<T> view(rows.data(), n, d, std::max(stride, d));
    {
      py::gil_scoped_release release;
      tree_ = make_tree<T>(view, leaf_size);
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

Built in O(n log n) by median splits on the axis of widest spread. The tree reads a
row-contiguous `points` array in place (no copy): do not modify it while the tree is in use.
Queries are thread-safe and release the GIL; batches run in parallel.
)doc")
      .def(py::init<const py::array&, std::size_t>(), py::arg("points"), py::arg("leaf_size") = 10)
      .def("query", &PyKdTree::query, py::arg("q"), py::arg("k") = 1, py::arg("eps") = 0.0,
           "k nearest neighbours of one point (d,) or of m points (m, d): (distances float64, indices int64), "
           "each (k,) or (m, k), ascending by distance, ties by index; -1 / inf where fewer than k points exist. "
           "eps > 0: each distance within (1 + eps) of the true one.")
      .def("query_radius", &PyKdTree::query_radius, py::arg("q"), py::arg("r"),
           "Indices within distance r (inclusive), sorted by distance: an int64 array for one point, a list of "
           "arrays for (m, d) queries.")
      .def("query_box", &PyKdTree::query_box, py::arg("lo"), py::arg("hi"),
           "Indices (ascending) of the points p with lo <= p <= hi.")
      .def("count_box", &PyKdTree::count_box, py::arg("lo"), py::arg("hi"),
           "Number of points with lo <= p <= hi; for (m, d) corners an int64 array of m counts.")
      .def("stats", &PyKdTree::stats, "dict: points, nodes, leaves, depth, bytes")
      .def("validate", &PyKdTree::validate, "Checks every invariant of the tree; raises if one fails.")
      .def("save", &PyKdTree::save, py::arg("path"),
           "Writes the tree and its points to a geods archive (the file format of every structure).")
      .def_static("load", &PyKdTree::load, py::arg("path"),
                  "Maps a tree written by save() (float32 or float64, any dimension): its arrays are read in\n"
                  "place from the file. Raises ValueError for a truncated, corrupt or other file.")
      .def("__len__", &PyKdTree::size)
      .def_property_readonly("dim", &PyKdTree::dim)
      .def_property_readonly("leaf_size", &PyKdTree::leaf_size)
      .def_property_readonly("dtype", &PyKdTree::dtype);
}

}  // namespace geods::python
