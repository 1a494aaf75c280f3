#pragma once
// What the knn and range commands share: the k-d tree they query, built over the
// points (the first argument) or loaded from a tree written by --save (or by
// save() in C++ or Python, of float32 or float64 points).
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/io/table_io.hpp"
#include "geods/spatial/kd_tree_dimensions.hpp"
#include "stopwatch.hpp"

namespace geods::cli {

struct KdTreeInput {
  std::string points, tree, save;
  std::size_t leaf_size = spatial::KdTree<double>::kDefaultLeafSize;
  std::string layout = "tree_order";

  void add_options(CLI::App& app) {
    // Not add_input: the points are optional when --tree gives a saved tree instead.
    CLI::Option* positional = app.add_option("points", points, "Points, n x d (.npy, .csv, .txt, .xyz, .ply)");
    CLI::Option* named = app.add_option("--points", points, "Deprecated: give points as the first argument");
    positional->excludes(named);
    app.add_option("--tree", tree, "Instead of the points: a k-d tree written by --save or save() (float32 or float64 points)")
        ->excludes(positional)
        ->excludes(named);
    app.add_option("--leaf-size", leaf_size, "Points per leaf of the k-d tree")->check(at_least(1));
    app.add_option("--layout", layout,
                   "tree_order (default: the tree keeps a copy of the points in leaf order, faster queries) or "
                   "zero_copy (reads the points in place: half the memory; a --tree file is then not copied)");
    app.add_option("--save", save, "Output: the k-d tree and its points as a geods archive, for --tree");
  }
  /// The file the points come from.
  const std::string& source() const { return tree.empty() ? points : tree; }

  /// Calls fn(tree, build_s) with the tree for its dimension (and, loaded, its
  /// scalar type: KdTree<float, *> or KdTree<double, *>); build_s is 0 for a loaded tree.
  template <typename Fn>
  void with_tree(const std::string& command, const Fn& fn) const {
    if (points.empty() == tree.empty()) throw Error(command + ": give the points as the first argument, or --tree");
    const spatial::PointLayout point_layout = spatial::parse_point_layout(layout);
    auto use = [&](const auto& t, double build_s) {
      if (!save.empty()) t.save(save);
      fn(t, build_s);
    };
    if (!tree.empty()) {
      const spatial::KdTreeFileInfo info = spatial::read_kd_tree_info(tree);
      const auto visit = [&](const auto& loaded) { std::visit([&](const auto& t) { use(t, 0.0); }, loaded); };
      if (info.scalar == DType::f32)
        visit(spatial::load_kd_tree<float>(tree, info.dim, point_layout));
      else
        visit(spatial::load_kd_tree<double>(tree, info.dim, point_layout));  // KdTree::load names any other type
      return;
    }
    const io::Table table = io::read_table(points, "point");
    Stopwatch build_watch;
    const auto built =
        spatial::make_kd_tree(spatial::PointView<double>(table.values.data(), table.rows, table.cols), leaf_size,
                               point_layout);
    const double build_s = build_watch.seconds();
    std::visit([&](const auto& t) { use(t, build_s); }, built);
  }
};

/// The rows of `table` as points of the tree's scalar type T: a view of the
/// table for double, for float a copy rounded to float kept in `rounded`.
template <typename T>
spatial::PointView<T> points_as(const io::Table& table, std::vector<T>& rounded) {
  if constexpr (std::is_same_v<T, double>) {
    return spatial::PointView<double>(table.values.data(), table.rows, table.cols);
  } else {
    rounded.assign(table.values.begin(), table.values.end());
    return spatial::PointView<T>(rounded.data(), table.rows, table.cols);
  }
}

}  // namespace geods::cli
