// geods range: how many points lie in each of a batch of axis-parallel boxes (k-d tree).
#include <fmt/format.h>

#include <cstdint>
#include <variant>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/table_io.hpp"
#include "geods/spatial/kd_tree_dimensions.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class RangeCommand : public Command {
 public:
  std::string name() const override { return "range"; }
  std::string summary() const override { return "Count the points in axis-parallel boxes (k-d tree range counting)"; }
  void add_options(CLI::App& app) override {
    add_input(app, "points", points_, "Points, n x d (.npy, .csv, .txt, .xyz, .ply)", "--points");
    app.add_option("--boxes", boxes_, "Boxes, m x 2d: the low corner, then the high corner (closed)")->required();
    app.add_option("-o,--output", output_, "Output: int64 counts, one per box");
    app.add_option("--leaf-size", leaf_size_, "Points per leaf of the k-d tree")->check(CLI::PositiveNumber);
  }

  void run(const RunContext&, Report& report) override {
    const io::Table points = io::read_table(points_, "point");
    const io::Table boxes = io::read_table(boxes_, "box row");
    if (boxes.cols != 2 * points.cols)
      throw Error(fmt::format("{}: boxes need 2 x {} = {} columns (low corner, high corner) for the points of {}, got {}",
                              boxes_, points.cols, 2 * points.cols, points_, boxes.cols));
    double build_s = 0, query_s = 0;
    std::vector<std::size_t> counts;
    Stopwatch build_watch;
    const auto any_tree =
        spatial::make_kd_tree(spatial::PointView<double>(points.values.data(), points.rows, points.cols), leaf_size_);
    build_s = build_watch.seconds();
    std::visit(
        [&](const auto& tree) {
          Stopwatch query_watch;
          counts = tree.count_box_batch(spatial::PointView<double>(boxes.values.data(), boxes.rows, boxes.cols));
          query_s = query_watch.seconds();
        },
        any_tree);
    const std::vector<std::int64_t> out(counts.begin(), counts.end());
    if (!output_.empty()) io::write_npy<std::int64_t>(output_, out, {boxes.rows});
    std::size_t total = 0;
    for (std::size_t c : counts) total += c;

    Json& j = report.json;
    j["points"] = points.rows;
    j["boxes"] = boxes.rows;
    j["dim"] = points.cols;
    j["leaf_size"] = leaf_size_;
    j["total_count"] = total;
    j["build_s"] = build_s;
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    report.lines.push_back(fmt::format("range: {} points of dimension {}, {} boxes", points.rows, points.cols,
                                       boxes.rows));
    report.lines.push_back(fmt::format("  k-d tree built in {:.3f} s, boxes counted in {:.3f} s; {} points in all boxes",
                                       build_s, query_s, total));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
  }

 private:
  std::string points_, boxes_, output_;
  std::size_t leaf_size_ = spatial::KdTree<double>::kDefaultLeafSize;
};

const bool registered = register_command<RangeCommand>();

}  // namespace
}  // namespace geods::cli
