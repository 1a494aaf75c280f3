// Demo step spatial/quadtree: a point quadtree over land points and its 2:1-balanced version.
#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "demo.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/spatial/quadtree.hpp"
#include "geods/spatial/stats_fields.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

using Tree = spatial::Quadtree<double>;

// Leaf cells shaded by depth (deeper = darker), then the points on top.
void draw(const Tree& tree, const std::vector<Vec2d>& points, const std::string& title,
          const std::filesystem::path& file) {
  const AABB2d root = tree.root_bounds();
  io::SvgWriter svg(root, 900);
  svg.title(title);
  const double deepest = double(std::max<std::size_t>(1, tree.stats().depth));
  for (std::uint32_t v = 0; v < tree.nodes().size(); ++v) {
    if (!tree.node(v).leaf()) continue;
    const int shade = int(250 - 150 * double(tree.node(v).depth) / deepest);
    svg.rect(tree.node_bounds(v),
             {.stroke = "#34495e", .fill = fmt::format("rgb({},{},255)", shade, shade), .stroke_width = 0.6});
  }
  svg.points(points, {.stroke = "none", .fill = "#c0392b", .radius = 2.2});
  svg.save(file);
}

void run_quadtree(const DemoContext& context, DemoResult& result) {
  const io::PointMatrix matrix = io::read_points(context.data_dir / "land_points.npy");
  const std::size_t n = std::size_t(matrix.rows());
  std::vector<Vec2d> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = {matrix(Eigen::Index(i), 0), matrix(Eigen::Index(i), 1)};

  Stopwatch build_watch;
  const Tree full(all, {.bucket = 8});
  result.timing("build quadtree over all points (bucket 8)", build_watch.seconds());
  Stopwatch balance_watch;
  const Tree full_balanced = full.balanced();
  result.timing("balance it", balance_watch.seconds());

  // About 300 points, one per leaf, as in the seed's definition.
  const std::size_t step = std::max<std::size_t>(1, n / 300);
  std::vector<Vec2d> points;
  for (std::size_t i = 0; i < n; i += step) points.push_back(all[i]);
  const Tree tree(points);
  tree.validate();
  const Tree balanced = tree.balanced();
  balanced.validate();
  const spatial::OrthtreeStats before = tree.stats(), after = balanced.stats();

  draw(tree, points, fmt::format("Quadtree of {} land points", points.size()), context.out_dir / "quadtree.svg");
  draw(balanced, points, fmt::format("The 2:1-balanced quadtree of the same {} points", points.size()),
       context.out_dir / "quadtree_balanced.svg");

  result.text = "A point quadtree (seed §2.1): the root is the smallest square around the points, and every square "
                "holding two or more points splits into four equal quadrants. Beside it the balanced quadtree "
                "(§2.1.3, de Berg et al.): squares are split further until any two leaves sharing an edge differ by "
                "at most one level, found with the O(depth) neighbor search of Theorem 3. Darker squares are deeper.";
  result.figures.push_back({"quadtree.svg", fmt::format("{} leaves, depth {}", before.leaves, before.depth)});
  result.figures.push_back({"quadtree_balanced.svg", fmt::format("balanced: {} leaves, depth {}", after.leaves,
                                                                 after.depth)});
  result.stat("points shown", std::to_string(points.size()));
  result.stat("Quadtree", stats_text(before));
  result.stat("balanced: Quadtree", stats_text(after));
  result.stat("all points (bucket 8): Quadtree", stats_text(full.stats()));
  result.stat("all points balanced: Quadtree", stats_text(full_balanced.stats()));
}

const bool registered =
    register_demo_step({"spatial", "quadtree", "A quadtree and its balanced version", &run_quadtree});

}  // namespace
}  // namespace geods::cli
