// Demo step of the dynamic module: Dyn(k-d) over the land points, inserted,
// partly deleted and re-inserted in random order, with the decomposition into
// trees V_i of 2^i slots drawn over time for both variants.
#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "demo.hpp"
#include "geods/core/rng.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/dynamic/stats_fields.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

using Tree = dynamic::DynamicKdTree<double, 2>;

// The structures per level after every `sample`-th operation.
struct Timeline {
  std::vector<std::vector<std::size_t>> columns;
  std::size_t levels = 0;
};

struct Run {
  Timeline timeline;
  double insert_s = 0, remove_s = 0, reinsert_s = 0, query_s = 0;
  dynamic::DynamicKdTreeStats stats;
};

Run run_variant(dynamic::Variant variant, const std::vector<Tree::Point>& points, const std::vector<Tree::Point>& queries,
                std::size_t sample) {
  Run run;
  Tree tree(dynamic::DynamizeOptions{variant});
  std::size_t op = 0;
  auto record = [&] {
    if (op++ % sample) return;
    run.timeline.columns.push_back(tree.stats().structure.per_level);
    run.timeline.levels = std::max(run.timeline.levels, run.timeline.columns.back().size());
  };
  Rng rng(2024);
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);

  std::vector<dynamic::Id> ids(points.size());
  Stopwatch insert_watch;
  for (std::size_t i : order) {
    ids[i] = tree.insert(points[i]);
    record();
  }
  run.insert_s = insert_watch.seconds();

  // Delete three quarters in another random order, then insert them again (new ids).
  std::shuffle(order.begin(), order.end(), rng);
  order.resize(points.size() * 3 / 4);
  Stopwatch remove_watch;
  for (std::size_t i : order) {
    tree.remove(ids[i]);
    record();
  }
  run.remove_s = remove_watch.seconds();
  Stopwatch reinsert_watch;
  for (std::size_t i : order) {
    tree.insert(points[i]);
    record();
  }
  run.reinsert_s = reinsert_watch.seconds();

  Stopwatch query_watch;
  std::size_t found = 0;
  for (const Tree::Point& q : queries) found += tree.query(q, 10).size();
  run.query_s = query_watch.seconds();
  if (found != 10 * queries.size()) throw Error("demo dynamic/kdtree: a query found fewer than 10 points");
  tree.validate();
  run.stats = tree.stats();
  return run;
}

// One panel: a row per level i, coloured where the level holds 1, 2 or 3 trees.
void draw_timeline(io::SvgWriter& svg, const Timeline& t, double top, const std::string& title) {
  const char* colors[] = {"", "#2471a3", "#e67e22", "#c0392b"};
  const double width = 100.0 / double(t.columns.size());
  svg.label({0, top + 1.2}, title, {.fill = "black", .font_size = 15});
  for (std::size_t level = 0; level < t.levels; ++level) {
    const double y = top - 2.0 * double(level + 1);
    svg.label({-14, y + 0.3}, fmt::format("V{} ({})", level, std::size_t(1) << level), {.fill = "#555", .font_size = 10});
    std::size_t begin = 0;
    auto count = [&](std::size_t c) { return level < t.columns[c].size() ? std::min<std::size_t>(t.columns[c][level], 3) : 0; };
    for (std::size_t c = 1; c <= t.columns.size(); ++c) {
      if (c < t.columns.size() && count(c) == count(begin)) continue;
      if (count(begin) > 0)
        svg.rect(AABB2d({width * double(begin), y}, {width * double(c), y + 1.5}),
                 {.stroke = "none", .fill = colors[count(begin)]});
      begin = c;
    }
  }
}

void run_dynamic_kdtree(const DemoContext& context, DemoResult& result) {
  const io::PointMatrix matrix = io::read_points(context.data_dir / "land_points.npy");
  std::vector<Tree::Point> points(std::size_t(matrix.rows()));
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = {matrix(Eigen::Index(i), 0), matrix(Eigen::Index(i), 1)};
  Rng rng(7);
  std::vector<Tree::Point> queries(1000);
  for (auto& q : queries) q = {rng.uniform(-180, 180), rng.uniform(-60, 80)};

  const std::size_t ops = points.size() * 10 / 4;
  const std::size_t sample = std::max<std::size_t>(1, ops / 500);
  const Run amortized = run_variant(dynamic::Variant::amortized, points, queries, sample);
  const Run worst = run_variant(dynamic::Variant::worst_case, points, queries, sample);

  // The alternative the dynamization replaces: a static tree rebuilt from scratch.
  Stopwatch static_watch;
  const spatial::KdTree<double, 2> full(spatial::PointView<double>(matrix.data(), points.size(), 2));
  const double static_build_s = static_watch.seconds();

  const double rows = double(std::max(amortized.timeline.levels, worst.timeline.levels));
  const double panel = 2.0 * rows + 6;
  io::SvgWriter svg(AABB2d({-16, 0}, {102, 2 * panel}), 1000);
  svg.title("Dyn(k-d): trees V_i of 2^i slots over time");
  draw_timeline(svg, amortized.timeline, 2 * panel - 3, "amortized (Theorem 11): one V_i per set bit");
  draw_timeline(svg, worst.timeline, panel - 3, "worst case (Theorem 14): up to three V_i per level, merged in steps");
  for (const double x : {100.0 * 4 / 10, 100.0 * 7 / 10})
    svg.segment({x, 0.5}, {x, 2 * panel - 2}, {.stroke = "#888", .stroke_width = 0.8, .opacity = 0.8});
  svg.save(context.out_dir / "dynamic_kdtree.svg");

  const std::size_t n = points.size(), removed = n * 3 / 4;
  result.text = fmt::format(
      "Dyn(k-d) (seed §7.4): the {} land points inserted one at a time in random order, then {} of them deleted "
      "and inserted again, each one at a time. Every level i holds k-d trees of 2^i slots (blue: one, orange: "
      "two, red: three). Deletions (middle third) only hide points, so the trees stay as they are until more than "
      "half of the slots are dead; then one reconstruction rebuilds them from the live points alone (Theorem 12).",
      n, removed);
  result.figures.push_back({"dynamic_kdtree.svg", "Trees per level over the operations: inserts | deletes | "
                                                  "re-inserts (grey lines)"});
  for (const auto& [name, run] : {std::pair<std::string, const Run&>{"amortized", amortized},
                                  std::pair<std::string, const Run&>{"worst case", worst}}) {
    result.stat(name + ": inserts / s", fmt::format("{:.0f}", double(n) / run.insert_s));
    result.stat(name + ": deletes / s", fmt::format("{:.0f}", double(removed) / run.remove_s));
    result.stat(name + ": 10-NN queries / s", fmt::format("{:.0f}", double(queries.size()) / run.query_s));
    result.stat(name + ": DynamicKdTree at the end", stats_text(run.stats));
    result.timing(name + ": " + std::to_string(n) + " inserts", run.insert_s);
    result.timing(name + ": " + std::to_string(removed) + " deletes", run.remove_s);
  }
  result.stat("static k-d tree rebuilt from scratch, builds / s", fmt::format("{:.0f}", 1.0 / static_build_s));
  result.timing("static k-d tree build over all points", static_build_s);
  if (full.size() != n) throw Error("demo dynamic/kdtree: static tree size");
}

const bool registered = register_demo_step({"dynamic", "kdtree", "Dyn(k-d): a k-d tree with insert and delete",
                                            &run_dynamic_kdtree});

}  // namespace
}  // namespace geods::cli
