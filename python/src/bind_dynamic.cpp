// Python bindings of the dynamic module: geods.DynamicKdTree.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>
#include <variant>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/dynamic/stats_fields.hpp"
#include "geods/spatial/knn_result.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

using dynamic::DynamicKdTree;
using dynamic::Id;

class PyDynamicKdTree {
 public:
  PyDynamicKdTree(std::size_t dim, const std::string& variant, double max_dead_fraction) {
    dynamic::DynamizeOptions options;
    if (variant == "amortized") {
      options.variant = dynamic::Variant::amortized;
    } else if (variant == "worst_case") {
      options.variant = dynamic::Variant::worst_case;
    } else {
      throw Error("DynamicKdTree: variant must be \"amortized\" or \"worst_case\", got \"" + variant + "\"");
    }
    options.max_dead_fraction = max_dead_fraction;
    if (dim == 2) {
      tree_.emplace<DynamicKdTree<double, 2>>(options);
    } else if (dim == 3) {
      tree_.emplace<DynamicKdTree<double, 3>>(options);
    } else {
      tree_.emplace<DynamicKdTree<double, spatial::Dynamic>>(dim, options);
    }
    variant_ = variant;
  }

  void save(const std::string& path) const {
    std::visit([&](const auto& t) { t.save(path); }, tree_);
  }

  /// A tree saved by save(): the dimension picks the C++ type.
  static PyDynamicKdTree load(const std::string& path) {
    using Any = DynamicKdTree<double, spatial::Dynamic>;
    const std::uint64_t dim = Archive::open(path, Any::kArchiveKind, Any::kArchiveVersion, Archive::Verify::structure_only)
                                  .value<std::uint64_t>("dim");
    PyDynamicKdTree out;
    if (dim == 2) {
      out.tree_ = DynamicKdTree<double, 2>::load(path);
    } else if (dim == 3) {
      out.tree_ = DynamicKdTree<double, 3>::load(path);
    } else {
      out.tree_ = DynamicKdTree<double, spatial::Dynamic>::load(path);
    }
    const bool worst_case = std::visit([](const auto& t) { return t.structure().options().variant; }, out.tree_) ==
                            dynamic::Variant::worst_case;
    out.variant_ = worst_case ? "worst_case" : "amortized";
    return out;
  }

  std::size_t dim() const {
    return std::visit([](const auto& t) { return t.dim(); }, tree_);
  }
  const std::string& variant() const { return variant_; }
  std::size_t size() const {
    return std::visit([](const auto& t) { return t.size(); }, tree_);
  }
  bool contains(std::int64_t id) const {
    return id >= 0 && std::visit([&](const auto& t) { return t.contains(Id(id)); }, tree_);
  }

  py::array_t<std::int64_t> insert(const py::handle& points) {
    const PointRows<double> rows = point_rows<double>(points, dim(), "DynamicKdTree.insert");
    std::vector<Id> ids;
    {
      py::gil_scoped_release release;
      ids = std::visit([&](auto& t) { return t.insert(rows.view()); }, tree_);
    }
    py::array_t<std::int64_t> out = index_array(ids);
    if (rows.single) return out.reshape(std::vector<py::ssize_t>{});
    return out;
  }

  void remove(const py::handle& ids) {
    auto array = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(ids);
    if (!array || array.ndim() > 1) throw Error("DynamicKdTree.remove: ids must be an integer or a 1-d array of them");
    std::vector<Id> list(std::size_t(array.size()));
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::int64_t id = array.data()[i];
      if (id < 0) throw Error("DynamicKdTree.remove: id " + std::to_string(id) + " is not stored");
      list[i] = Id(id);
    }
    py::gil_scoped_release release;
    std::visit([&](auto& t) { t.remove(list); }, tree_);
  }

  py::tuple query(const py::handle& q, std::size_t k, double eps, double max_distance) const {
    const PointRows<double> rows = point_rows<double>(q, dim(), "DynamicKdTree.query");
    return std::visit(
        [&](const auto& t) {
          using Neighbor = typename std::decay_t<decltype(t)>::Neighbor;
          std::vector<Neighbor> result;
          {
            py::gil_scoped_release release;
            result = t.query_batch(rows.view(), spatial::KnnRequest{k, eps, max_distance});
          }
          return neighbor_arrays(std::span<const Neighbor>(result), rows.count, k, rows.single, &Neighbor::index);
        },
        tree_);
  }

  py::array_t<std::int64_t> query_radius(const py::handle& q, double r) const {
    const PointRows<double> rows = point_rows<double>(q, dim(), "DynamicKdTree.query_radius");
    if (!rows.single) throw Error("DynamicKdTree.query_radius: q is one point");
    return std::visit(
        [&](const auto& t) {
          using Neighbor = typename std::decay_t<decltype(t)>::Neighbor;
          std::vector<std::vector<Neighbor>> result(1);
          {
            py::gil_scoped_release release;
            result[0] = t.query_radius(std::span<const double>(rows.data(), dim()), r);
          }
          return py::array_t<std::int64_t>(neighbor_lists(result, true, &Neighbor::index));
        },
        tree_);
  }

  py::array_t<std::int64_t> query_box(const py::handle& lo, const py::handle& hi) const {
    const PointRows<double> l = point_rows<double>(lo, dim(), "DynamicKdTree.query_box lo");
    const PointRows<double> h = point_rows<double>(hi, dim(), "DynamicKdTree.query_box hi");
    if (!l.single || !h.single) throw Error("DynamicKdTree.query_box: lo and hi are single points");
    std::vector<Id> ids;
    {
      py::gil_scoped_release release;
      ids = std::visit(
          [&](const auto& t) {
            return t.query_box(std::span<const double>(l.data(), dim()), std::span<const double>(h.data(), dim()));
          },
          tree_);
    }
    return index_array(ids);
  }

  void validate() const {
    std::visit([](const auto& t) { t.validate(); }, tree_);
  }
  void rebuild() {
    std::visit([](auto& t) { t.rebuild(); }, tree_);
  }

  py::dict stats() const {
    return stats_dict(std::visit([](const auto& t) { return t.stats(); }, tree_));
  }

 private:
  PyDynamicKdTree() = default;

  std::variant<DynamicKdTree<double, 2>, DynamicKdTree<double, 3>, DynamicKdTree<double, spatial::Dynamic>> tree_;
  std::string variant_;
};

}  // namespace

void bind_dynamic(py::module_& m) {
  py::class_<PyDynamicKdTree>(m, "DynamicKdTree", R"doc(
A k-d tree with insert and delete (seed §7.4, Dyn(k-d)) over float64 points of any dimension dim >= 1.

Made of static k-d trees (the same as geods.KdTree) of 2^i slots (the binary structure). variant="amortized" rebuilds
merged trees at once (Theorem 11); variant="worst_case" builds them in small steps spread
over later inserts, so no single insert pays for a large rebuild (Theorem 14). Deleted
points are hidden at once and dropped (memory freed) when more than max_dead_fraction of
the stored slots are dead. insert returns new int64 ids, never reused; removing an id that
is not stored raises ValueError and removes nothing.
)doc")
      .def(py::init<std::size_t, const std::string&, double>(), py::arg("dim") = 3, py::arg("variant") = "amortized",
           py::arg("max_dead_fraction") = 0.5,
           "An empty tree of points (d,) with d = dim; variant: amortized or worst_case")
      .def("insert", &PyDynamicKdTree::insert, py::arg("points"),
           "Inserts one point (d,) or rows (n, d); returns their ids (int64 array, or one int64 for one point).")
      .def("remove", &PyDynamicKdTree::remove, py::arg("ids"), "Removes the items with these ids (an int or int64 (n,)).")
      .def("query", &PyDynamicKdTree::query, py::arg("q"), py::arg("k") = 1, py::arg("eps") = 0.0,
           py::arg("max_distance") = std::numeric_limits<double>::infinity(),
           "k nearest stored points of one point (d,) or m points (m, d): (distances float64, ids int64), each (k,) "
           "or (m, k), ascending by distance, ties by id; -1 / inf where fewer than k are stored or within "
           "max_distance. eps > 0: each distance within (1 + eps) of the true one (as KdTree.query).")
      .def("query_radius", &PyDynamicKdTree::query_radius, py::arg("q"), py::arg("r"),
           "Ids (int64 (k,)) within distance r of q = (x, y, ...) (inclusive), sorted by distance.")
      .def("query_box", &PyDynamicKdTree::query_box, py::arg("lo"), py::arg("hi"),
           "Ids (int64 (k,), ascending) of the stored points p with lo <= p <= hi (corners (d,)).")
      .def("validate", &PyDynamicKdTree::validate,
           "Checks the decomposition into trees of 2^i slots, the id locator and every tree; raises if one fails.")
      .def("rebuild", &PyDynamicKdTree::rebuild, "Rebuilds from the live points now, freeing deleted ones.")
      .def("stats", &PyDynamicKdTree::stats,
           "dict: live, dead, structures, building, per_level (trees of 2^i slots on level i), rebuilds, "
           "forced_builds, bytes")
      .def("save", &PyDynamicKdTree::save, py::arg("path"),
           "Writes the tree (its blocks, ids and deletions) to a geods archive file.")
      .def_static("load", &PyDynamicKdTree::load, py::arg("path"),
                  "A tree written by save(): the same ids, points and answers. Raises ValueError for a bad file.")
      .def("__len__", &PyDynamicKdTree::size)
      .def("__contains__", &PyDynamicKdTree::contains)
      .def_property_readonly("dim", &PyDynamicKdTree::dim)
      .def_property_readonly("variant", &PyDynamicKdTree::variant);
}

}  // namespace geods::python
