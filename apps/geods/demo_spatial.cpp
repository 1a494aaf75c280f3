// Demo steps of the spatial module: a 2-d tree with a range query, like the seed's Figure 3.
#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "demo.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/spatial/stats_fields.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

using Tree2 = spatial::KdTree<double, 2>;

// Draws the split line of every inner node across its cell; shallow splits are drawn thicker.
// Cells meet at the middle of the gap between a node's low and high values, so they tile the box.
void draw_splits(io::SvgWriter& svg, const Tree2& tree, std::uint32_t v, AABB2d cell, int depth) {
  const Tree2::Node& node = tree.nodes()[v];
  if (node.leaf()) return;
  const int axis = int(node.axis);
  const double split = (double(node.low) + double(node.high)) / 2;
  Vec2d a = cell.lo, b = cell.hi;
  a[axis] = b[axis] = split;
  const double width = std::max(0.4, 2.4 - 0.3 * depth);
  svg.segment(a, b, {.stroke = axis == 0 ? "#c0392b" : "#2471a3", .stroke_width = width, .opacity = 0.8});
  AABB2d left = cell, right = cell;
  left.hi[axis] = split;
  right.lo[axis] = split;
  draw_splits(svg, tree, v + 1, left, depth + 1);
  draw_splits(svg, tree, node.right, right, depth + 1);
}

void run_kdtree(const DemoContext& context, DemoResult& result) {
  const io::PointMatrix matrix = io::read_points(context.data_dir / "land_points.npy");
  const std::size_t n = std::size_t(matrix.rows());

  // The whole set: build and a range count, timed.
  Stopwatch build_watch;
  const Tree2 full(spatial::PointView<double>(matrix.data(), n, 2));
  result.timing("build k-d tree over all points", build_watch.seconds());

  // A legible subset of about 200 points with one point per leaf, as in the seed's Figure 3.
  const std::size_t step = std::max<std::size_t>(1, n / 200);
  std::vector<Vec2d> points;
  for (std::size_t i = 0; i < n; i += step) points.push_back({matrix(Eigen::Index(i), 0), matrix(Eigen::Index(i), 1)});
  const Tree2 tree(spatial::PointView<double>(std::span<const Vec2d>(points)), 1);
  tree.validate();

  // The query rectangle: Europe and North Africa in longitude/latitude.
  const AABB2d box({-12, 20}, {45, 62});
  std::size_t visited = 0;
  const std::vector<std::uint32_t> inside = tree.query_box(std::span<const double>(box.lo.data(), 2),
                                                           std::span<const double>(box.hi.data(), 2), &visited);
  Stopwatch count_watch;
  std::size_t full_visited = 0;
  const std::size_t full_count =
      full.count_box(std::span<const double>(box.lo.data(), 2), std::span<const double>(box.hi.data(), 2), &full_visited);
  result.timing("count_box over all points", count_watch.seconds());

  const AABB2d view({-180, -90}, {180, 90});
  io::SvgWriter svg(view, 1000);
  svg.title(fmt::format("2-d tree of {} land points and a range query", points.size()));
  svg.rect(box, {.stroke = "#1e8449", .fill = "#abebc6", .stroke_width = 2.0, .opacity = 0.6});
  draw_splits(svg, tree, 0, view, 0);
  svg.points(points, {.stroke = "none", .fill = "black", .radius = 2.2});
  std::vector<Vec2d> reported;
  for (std::uint32_t i : inside) reported.push_back(points[i]);
  svg.points(reported, {.stroke = "black", .fill = "#f1c40f", .stroke_width = 0.8, .radius = 4.0});
  svg.save(context.out_dir / "kdtree_range.svg");

  result.text = "A balanced 2-d tree (seed §2.2, Figure 3): each inner node splits its points at the median of the "
                "axis of widest spread (red: vertical split lines, blue: horizontal; thicker = nearer the root). "
                "The range query reports the points in the green rectangle (yellow) by visiting only the nodes "
                "whose cells meet it: O(sqrt(n) + a) nodes (Theorem 4).";
  result.figures.push_back({"kdtree_range.svg",
                            fmt::format("{} points, one per leaf; the query reports {} of them after visiting {} of "
                                        "{} nodes",
                                        points.size(), inside.size(), visited, tree.nodes().size())});
  const spatial::KdTreeStats stats = tree.stats();
  result.stat("points shown", std::to_string(points.size()));
  result.stat("KdTree", stats_text(stats));
  result.stat("reported / nodes visited", fmt::format("{} / {}", inside.size(), visited));
  result.stat("all points, leaf size 10: KdTree", stats_text(full.stats()));
  result.stat("all points: count in the rectangle / nodes visited", fmt::format("{} / {}", full_count, full_visited));
}

const bool registered = register_demo_step({"spatial", "kdtree", "A 2-d tree and a range query", &run_kdtree});

}  // namespace
}  // namespace geods::cli
