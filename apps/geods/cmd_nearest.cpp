// geods nearest: the nearest site of each query point (post office problem) by the
// slab structure, walking in the Delaunay graph, or the k-d tree.
#include <fmt/format.h>

#include <cstdint>

#include "command.hpp"
#include "geods/io/table_io.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "stats_json.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

class NearestCommand : public Command {
 public:
  std::string name() const override { return "nearest"; }
  std::string summary() const override {
    return "nearest site of 2D query points: slab structure (Theorem 8), Delaunay walk, or k-d tree";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "sites", sites_, "Sites, n x 2 (.npy, .csv, .txt, .xyz, .ply)", "--sites");
    app.add_option("--queries", queries_, "Query points, m x 2")->required();
    add_output(app, "-o,--output", output_, "Output: int64 (m,) index of the nearest site (first occurrence of duplicates)",
               io::OutputKind::table);
    app.add_option("--method", method_, "walk (WalkLocator, the default: O(n) memory), slab (SlabLocator: "
                                        "O(n^1.5) memory in the worst case) or kd_tree (KdTree); kdtree is the "
                                        "deprecated spelling of kd_tree")
        ->check(CLI::IsMember({"slab", "walk", "kd_tree", "kdtree"}));
  }

  void run(const RunContext&, Report& report) override {
    const std::vector<Vec2d> sites = read_points_2d(sites_);
    const std::vector<Vec2d> queries = read_points_2d(queries_);
    std::vector<std::uint32_t> nearest;
    double build_s = 0, query_s = 0;
    Json& j = report.json;
    if (method_ == "kdtree") method_ = "kd_tree";
    if (method_ == "kd_tree") {
      Stopwatch build_watch;
      const spatial::KdTree<double, 2> tree{spatial::PointView<double>(std::span<const Vec2d>(sites))};
      build_s = build_watch.seconds();
      Stopwatch query_watch;
      const auto result = tree.query_batch(spatial::PointView<double>(std::span<const Vec2d>(queries)), {1});
      nearest.resize(result.size());
      for (std::size_t i = 0; i < result.size(); ++i) nearest[i] = result[i].index;
      query_s = query_watch.seconds();
    } else {
      Stopwatch build_watch;
      const voronoi::Voronoi2 diagram(sites);
      if (method_ == "slab") {
        const voronoi::SlabLocator locator(diagram);
        build_s = build_watch.seconds();
        put_stats(j, locator.stats(), "locator_");
        Stopwatch query_watch;
        nearest = locator.nearest_batch(queries);
        query_s = query_watch.seconds();
      } else {
        const voronoi::WalkLocator locator(diagram);
        build_s = build_watch.seconds();
        Stopwatch query_watch;
        nearest = locator.nearest_batch(queries);
        query_s = query_watch.seconds();
      }
    }
    if (!output_.empty()) {
      std::vector<std::int64_t> indices(nearest.begin(), nearest.end());
      io::write_table(output_, std::span<const std::int64_t>(indices), {indices.size()});
    }
    j["sites"] = sites.size();
    j["queries"] = queries.size();
    j["method"] = method_;
    j["build_s"] = build_s;
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    j["queries_per_s"] = query_s > 0 ? double(queries.size()) / query_s : 0.0;
    report.lines.push_back(fmt::format("nearest ({}): {} sites, {} queries", method_, sites.size(), queries.size()));
    report.lines.push_back(fmt::format("  built in {:.3f} s, queried in {:.3f} s ({:.0f} queries/s)", build_s, query_s,
                                       query_s > 0 ? double(queries.size()) / query_s : 0.0));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
  }

 private:
  std::string sites_, queries_, output_, method_ = "walk";
};

const bool registered_nearest = register_command<NearestCommand>();

}  // namespace
}  // namespace geods::cli
