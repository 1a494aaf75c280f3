// Python bindings of geods::shape: shape_distribution, histogram_distance,
// ShapeDatabase, index_collection, evaluate_retrieval.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/shape/collection.hpp"
#include "geods/shape/retrieval.hpp"
#include "geods/shape/shape_database.hpp"
#include "geods/shape/stats_fields.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

using shape::ShapeDatabase;

shape::DescriptorOptions descriptor_options(const std::string& descriptor, std::size_t samples, std::size_t bins,
                                            std::uint64_t seed, const std::string& normalization) {
  shape::DescriptorOptions o = shape::parse_descriptor(descriptor);
  o.distribution.samples = samples;
  o.distribution.bins = bins;
  o.distribution.seed = seed;
  o.distribution.normalization = shape::parse_normalization(normalization);
  shape::check_descriptor(o);
  return o;
}

py::array_t<float> float_array(const std::vector<float>& v) { return copy_array(v.data(), {py::ssize_t(v.size())}); }

std::vector<float> vector_from(const Rows<float>& a, const std::string& what) {
  if (a.ndim() != 1) throw Error(what + ": expected a 1D array");
  return std::vector<float>(a.data(), a.data() + a.size());
}

py::list matches_list(const std::vector<shape::ShapeMatch>& matches) {
  py::list out;
  for (const auto& m : matches) {
    py::dict d;
    d["id"] = m.id;
    d["name"] = m.name;
    d["label"] = m.label;
    d["distance"] = m.distance;
    out.append(d);
  }
  return out;
}

py::dict scores_dict(const shape::RetrievalScores& s) {
  py::dict d = stats_dict(s);
  d["recall"] = s.recall;
  d["precision"] = s.precision;
  return d;
}

}  // namespace

void bind_shape(py::module_& m) {
  m.def(
      "shape_distribution",
      [](const Rows<float>& v, const Rows<std::int64_t>& f, const std::string& kind, std::size_t samples,
         std::size_t bins, std::uint64_t seed, const std::string& normalization, double max_value) {
        const TriMesh mesh = mesh_from_arrays(v, f, "shape_distribution");
        const shape::DistributionOptions o{samples, bins, seed, shape::parse_normalization(normalization), max_value};
        const shape::ShapeFunction fn = shape::parse_shape_function(kind);
        return float_array(without_gil([&] { return shape::shape_distribution(mesh, fn, o); }));
      },
      py::arg("V"), py::arg("F"), py::arg("kind") = "d2", py::arg("samples") = shape::DistributionOptions{}.samples,
      py::arg("bins") = shape::DistributionOptions{}.bins, py::arg("seed") = 0, py::arg("normalization") = "mean",
      py::arg("max_value") = 0.0,
      "The shape distribution of a mesh (seed §5.6, Osada et al.): `samples` evaluations of the shape function "
      "`kind` (d1, d2, a3, d3, d4) on uniform random surface points, binned into a float32 histogram of `bins` "
      "values summing to 1. normalization: 'mean' or 'median' divides lengths by that statistic (range [0, 3) or "
      "[0, 4), or max_value), 'none' bins raw values over [0, max_value). Deterministic per seed.");
  m.def(
      "histogram_distance",
      [](const Rows<float>& a, const Rows<float>& b, const std::string& metric, std::size_t block) {
        return shape::histogram_distance(vector_from(a, "histogram_distance"), vector_from(b, "histogram_distance"),
                                         shape::parse_metric(metric), block);
      },
      py::arg("a"), py::arg("b"), py::arg("metric") = "l1", py::arg("block") = 0,
      "Distance of two histograms a, b (float32 (bins,)): 'l1', 'l2', 'chi2' or 'emd' (the L1 distance of the cumulative histograms, "
      "restarting every `block` bins for a combined descriptor).");

  py::class_<ShapeDatabase>(m, "ShapeDatabase",
                            "Shape retrieval database: descriptors of shapes in a dynamic k-d tree (exact and "
                            "approximate k-NN); adds go through the dynamization.")
      .def(py::init([](const std::string& descriptor, std::size_t samples, std::size_t bins, std::uint64_t seed,
                       const std::string& normalization) {
             return ShapeDatabase(descriptor_options(descriptor, samples, bins, seed, normalization));
           }),
           py::arg("descriptor") = "d2", py::arg("samples") = shape::DistributionOptions{}.samples,
           py::arg("bins") = shape::DistributionOptions{}.bins, py::arg("seed") = 0, py::arg("normalization") = "mean",
           "An empty database of descriptor ('d1', 'd2', 'a3', 'd3', 'd4' or a combination) histograms of `bins` bins")
      .def("__len__", &ShapeDatabase::size)
      .def_property_readonly("dimension", &ShapeDatabase::dimension)
      .def_property_readonly("descriptor_name", [](const ShapeDatabase& db) { return shape::descriptor_name(db.options()); })
      .def_property_readonly("samples", [](const ShapeDatabase& db) { return db.options().distribution.samples; })
      .def_property_readonly("bins", [](const ShapeDatabase& db) { return db.options().distribution.bins; })
      .def_property_readonly("names", &ShapeDatabase::names)
      .def_property_readonly("labels", &ShapeDatabase::labels)
      .def(
          "add",
          [](ShapeDatabase& db, const std::string& name, const Rows<float>& v, const Rows<std::int64_t>& f,
             const std::optional<std::string>& label) {
            const TriMesh mesh = mesh_from_arrays(v, f, "ShapeDatabase.add");
            return without_gil([&] { return db.add(name, mesh, label.value_or("")); });
          },
          py::arg("name"), py::arg("V"), py::arg("F"), py::arg("label") = py::none(),
          "Adds one shape, V float32 (n, 3) and F int64 (m, 3) (through the dynamization); returns its id.")
      .def(
          "add_descriptors",
          [](ShapeDatabase& db, const std::vector<std::string>& names, const Rows<float>& descriptors,
             const std::optional<std::vector<std::string>>& labels) {
            if (descriptors.ndim() != 2 || std::size_t(descriptors.shape(1)) != db.dimension())
              throw Error("ShapeDatabase.add_descriptors: descriptors must be an (n, " +
                          std::to_string(db.dimension()) + ") array");
            const std::vector<std::string> l = labels.value_or(std::vector<std::string>{});
            const std::span<const float> rows(descriptors.data(), std::size_t(descriptors.size()));
            return index_array(without_gil([&] { return db.add_descriptors(names, rows, l); }));
          },
          py::arg("names"), py::arg("descriptors"), py::arg("labels") = py::none(),
          "Adds precomputed descriptors, float32 (n, dimension) (rows as describe() makes them), as one batch; "
          "returns their ids, int64 (n,).")
      .def(
          "describe",
          [](const ShapeDatabase& db, const Rows<float>& v, const Rows<std::int64_t>& f) {
            const TriMesh mesh = mesh_from_arrays(v, f, "ShapeDatabase.describe");
            return float_array(without_gil([&] { return db.describe(mesh); }));
          },
          py::arg("V"), py::arg("F"), "The descriptor of a mesh (V float32 (n, 3), F int64 (m, 3)) under this database's options: float32 (dimension,).")
      .def(
          "descriptor", [](const ShapeDatabase& db, std::uint64_t id) { return float_array(db.descriptor(id)); },
          py::arg("id"), "The stored descriptor of shape `id`: float32 (dimension,).")
      .def(
          "query",
          [](const ShapeDatabase& db, const Rows<float>& v, const Rows<std::int64_t>& f, std::size_t k, double eps) {
            const TriMesh mesh = mesh_from_arrays(v, f, "ShapeDatabase.query");
            return matches_list(without_gil([&] { return db.query(mesh, k, eps); }));
          },
          py::arg("V"), py::arg("F"), py::arg("k") = 5, py::arg("eps") = 0.0,
          "The k nearest shapes to a mesh (V float32 (n, 3), F int64 (m, 3)): a list of {id, name, label, distance}, "
          "nearest first; eps > 0 approximates.")
      .def(
          "query_descriptor",
          [](const ShapeDatabase& db, const Rows<float>& d, std::size_t k, double eps) {
            const std::vector<float> q = vector_from(d, "ShapeDatabase.query_descriptor");
            return matches_list(without_gil([&] { return db.query_descriptor(q, k, eps); }));
          },
          py::arg("descriptor"), py::arg("k") = 5, py::arg("eps") = 0.0,
          "As query(), for a descriptor float32 (dimension,).")
      .def("stats", [](const ShapeDatabase& db) { return stats_dict(db.stats()); }, "dict of the ShapeStats fields")
      .def("validate", &ShapeDatabase::validate, "Checks every invariant; raises geods.Error if one fails.")
      .def(
          "save", [](const ShapeDatabase& db, const std::string& path) { db.save(path); }, py::arg("path"),
          "Writes the database to a geods archive.")
      .def_static(
          "load", [](const std::string& path) { return ShapeDatabase::load(path); }, py::arg("path"),
          "A database written by save(), mapped in place. Raises ValueError for a bad file or another version.");

  m.def(
      "index_collection",
      [](const std::string& path, const std::optional<std::string>& labels, const std::string& descriptor,
         std::size_t samples, std::size_t bins, std::uint64_t seed, const std::string& normalization) {
        const shape::DescriptorOptions o = descriptor_options(descriptor, samples, bins, seed, normalization);
        shape::CollectionIndex index = without_gil([&] {
          return shape::index_collection(shape::ShapeCollection::open(path, labels.value_or("")), o);
        });
        py::list skipped;
        for (const auto& s : index.skipped) skipped.append(py::make_tuple(s.name, s.reason));
        return py::make_tuple(std::move(index.database), skipped);
      },
      py::arg("path"), py::arg("labels") = py::none(), py::arg("descriptor") = "d2",
      py::arg("samples") = shape::DistributionOptions{}.samples, py::arg("bins") = shape::DistributionOptions{}.bins,
      py::arg("seed") = 0, py::arg("normalization") = "mean",
      "Describes every mesh of a directory tree, .zip or .sh3f (labels: CSV of path,label, else the catalog's "
      "categories) into a ShapeDatabase; returns (database, [(name, reason) of skipped members]).");
  m.def(
      "evaluate_retrieval",
      [](const ShapeDatabase& db, std::size_t k, std::size_t recall_levels) {
        return scores_dict(without_gil([&] { return shape::evaluate_retrieval(db, k, recall_levels); }));
      },
      py::arg("database"), py::arg("k") = 5, py::arg("recall_levels") = 20,
      "Princeton Shape Benchmark measures of a labelled database (leave-one-out): a dict with nn_rate, "
      "precision_at_k, first_tier, second_tier, mean_average_precision, recall, precision, ...");
}

}  // namespace geods::python
