// geods knn: k nearest neighbours of query points with a k-d tree.
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "command.hpp"
#include "geods/io/table_io.hpp"
#include "geods/spatial/stats_fields.hpp"
#include "kd_tree_cli.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class KnnCommand : public Command {
 public:
  std::string name() const override { return "knn"; }
  std::string summary() const override {
    return "k nearest neighbours of query points (k-d tree): indices and distances as .npy";
  }
  void add_options(CLI::App& app) override {
    input_.add_options(app);
    app.add_option("--queries", queries_, "Query points, m x d")->required();
    app.add_option("--k", k_, "Neighbours per query")->required()->check(at_least(1));
    app.add_option("--radius", radius_, "Only neighbours within this distance (fewer than k: index -1, distance inf)");
    app.add_option("--eps", eps_, "Approximation: distances within (1 + eps) of the true ones (default 0: exact)");
    add_output(app, "--indices", indices_, "Output: int64 m x k neighbour indices, -1 where missing", io::OutputKind::table);
    add_output(app, "--distances", distances_, "Output: float64 m x k Euclidean distances, ascending, inf where missing",
               io::OutputKind::table);
  }

  void run(const RunContext&, Report& report) override {
    if (radius_ && !(*radius_ >= 0)) throw Error("knn: --radius must be >= 0");
    if (!(eps_ >= 0)) throw Error("knn: --eps must be >= 0");
    const io::Table queries = io::read_table(queries_, "query point");
    const spatial::KnnRequest request{k_, eps_, radius_.value_or(std::numeric_limits<double>::infinity())};

    double build_s = 0, query_s = 0;
    std::size_t n = 0, dim = 0, leaf_size = 0;
    spatial::KdTreeStats stats;
    std::vector<spatial::Neighbor<double>> result;
    input_.with_tree("knn", [&](const auto& tree, double build_seconds) {
      build_s = build_seconds;
      n = tree.size();
      dim = tree.dim();
      leaf_size = tree.leaf_size();
      if (queries.cols != dim)
        throw Error(fmt::format("{}: queries of dimension {}, but the points ({}) have dimension {}", queries_,
                                queries.cols, input_.source(), dim));
      stats = tree.stats();
      using T = typename std::decay_t<decltype(tree)>::Scalar;
      std::vector<T> rounded;
      const spatial::PointView<T> at = points_as<T>(queries, rounded);
      Stopwatch query_watch;
      const std::vector<spatial::Neighbor<T>> found = tree.query_batch(at, request);
      query_s = query_watch.seconds();
      result.resize(found.size());
      for (std::size_t i = 0; i < found.size(); ++i) result[i] = {found[i].index, double(found[i].squared_distance)};
    });

    std::vector<std::int64_t> indices(result.size());
    std::vector<double> distances(result.size());
    std::size_t found = 0;
    for (std::size_t i = 0; i < result.size(); ++i) {
      const bool missing = result[i].index == spatial::kNoIndex;
      indices[i] = missing ? -1 : std::int64_t(result[i].index);
      distances[i] = missing ? std::numeric_limits<double>::infinity() : std::sqrt(result[i].squared_distance);
      found += !missing;
    }
    const std::vector<std::size_t> shape = {queries.rows, k_};
    if (!indices_.empty()) io::write_table(indices_, std::span<const std::int64_t>(indices), shape);
    if (!distances_.empty()) io::write_table(distances_, std::span<const double>(distances), shape);

    Json& j = report.json;
    j["points"] = n;
    j["queries"] = queries.rows;
    j["k"] = k_;
    j["dim"] = dim;
    j["eps"] = eps_;
    if (radius_) j["radius"] = *radius_;
    j["leaf_size"] = leaf_size;
    if (!input_.tree.empty()) j["tree"] = input_.tree;
    if (!input_.save.empty()) j["saved"] = input_.save;
    j["found"] = found;
    put_stats(j, stats, "tree_");
    j["build_s"] = build_s;
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    j["queries_per_s"] = query_s > 0 ? double(queries.rows) / query_s : 0.0;
    report.lines.push_back(fmt::format("knn: {} points of dimension {}, {} queries, k = {}{}{}", n, dim, queries.rows,
                                       k_, eps_ > 0 ? fmt::format(", eps = {}", eps_) : "",
                                       radius_ ? fmt::format(", radius = {}", *radius_) : ""));
    report.lines.push_back(input_.tree.empty()
                               ? fmt::format("  k-d tree: {} nodes, depth {}, built in {:.3f} s", stats.nodes,
                                             stats.depth, build_s)
                               : fmt::format("  k-d tree: {} nodes, depth {}, loaded from {}", stats.nodes, stats.depth,
                                             input_.tree));
    report.lines.push_back(fmt::format("  {} neighbours found in {:.3f} s ({:.0f} queries/s)", found, query_s,
                                       query_s > 0 ? double(queries.rows) / query_s : 0.0));
    if (!indices_.empty()) report.lines.push_back("  wrote " + indices_);
    if (!distances_.empty()) report.lines.push_back("  wrote " + distances_);
    if (!input_.save.empty()) report.lines.push_back("  wrote the k-d tree to " + input_.save);
  }

 private:
  KdTreeInput input_;
  std::string queries_, indices_, distances_;
  std::size_t k_ = 1;
  std::optional<double> radius_;
  double eps_ = 0;
};

const bool registered_knn = register_command<KnnCommand>();

}  // namespace
}  // namespace geods::cli
