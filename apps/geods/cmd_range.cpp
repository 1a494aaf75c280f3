// geods range: how many points lie in each of a batch of axis-parallel boxes (k-d tree).
#include <fmt/format.h>

#include <cstdint>

#include "command.hpp"
#include "geods/io/table_io.hpp"
#include "kd_tree_cli.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class RangeCommand : public Command {
 public:
  std::string name() const override { return "range"; }
  std::string summary() const override { return "Count the points in axis-parallel boxes (k-d tree range counting)"; }
  void add_options(CLI::App& app) override {
    input_.add_options(app);
    app.add_option("--boxes", boxes_, "Boxes, m x 2d: the low corner, then the high corner (closed)")->required();
    add_output(app, "-o,--output", output_, "Output: int64 counts, one per box", io::OutputKind::table);
  }

  void run(const RunContext&, Report& report) override {
    const io::Table boxes = io::read_table(boxes_, "box row");
    double build_s = 0, query_s = 0;
    std::size_t n = 0, dim = 0, leaf_size = 0;
    std::vector<std::size_t> counts;
    input_.with_tree("range", [&](const auto& tree, double build_seconds) {
      build_s = build_seconds;
      n = tree.size();
      dim = tree.dim();
      leaf_size = tree.leaf_size();
      if (boxes.cols != 2 * dim)
        throw Error(fmt::format("{}: boxes need 2 x {} = {} columns (low corner, high corner) for the points of {}, got {}",
                                boxes_, dim, 2 * dim, input_.source(), boxes.cols));
      using T = typename std::decay_t<decltype(tree)>::Scalar;
      std::vector<T> rounded;
      const spatial::PointView<T> corners = points_as<T>(boxes, rounded);
      Stopwatch query_watch;
      counts = tree.count_box_batch(corners);
      query_s = query_watch.seconds();
    });
    const std::vector<std::int64_t> out(counts.begin(), counts.end());
    if (!output_.empty()) io::write_table(output_, std::span<const std::int64_t>(out), {boxes.rows});
    std::size_t total = 0;
    for (std::size_t c : counts) total += c;

    Json& j = report.json;
    j["points"] = n;
    j["boxes"] = boxes.rows;
    j["dim"] = dim;
    j["leaf_size"] = leaf_size;
    if (!input_.tree.empty()) j["tree"] = input_.tree;
    if (!input_.save.empty()) j["saved"] = input_.save;
    j["total_count"] = total;
    j["build_s"] = build_s;
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    report.lines.push_back(fmt::format("range: {} points of dimension {}, {} boxes", n, dim, boxes.rows));
    report.lines.push_back(fmt::format("  k-d tree built in {:.3f} s, boxes counted in {:.3f} s; {} points in all boxes",
                                       build_s, query_s, total));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
    if (!input_.save.empty()) report.lines.push_back("  wrote the k-d tree to " + input_.save);
  }

 private:
  KdTreeInput input_;
  std::string boxes_, output_;
};

const bool registered_range = register_command<RangeCommand>();

}  // namespace
}  // namespace geods::cli
