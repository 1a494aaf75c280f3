#pragma once
// What the knn and range commands share: reading an n x d table of numbers,
// building the k-d tree of the right dimension over it, or loading a saved one.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "geods/core/error.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/point_io.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "stopwatch.hpp"

namespace geods::cli {

/// n rows of `cols` numbers, row-major.
struct Table {
  std::vector<double> values;
  std::size_t rows = 0, cols = 0;
};

/// A .csv/.txt table: rows of numbers separated by commas or blanks; blank
/// lines and '#' comments are skipped, and so is a first line that is a header.
inline Table read_text_table(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open");
  Table t;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    std::vector<double> row;
    std::string field;
    bool numeric = true;
    while (fields >> field) {
      char* end = nullptr;
      row.push_back(std::strtod(field.c_str(), &end));
      numeric = numeric && end == field.c_str() + field.size();
    }
    if (row.empty()) continue;
    if (!numeric) {
      if (t.rows == 0 && number == 1) continue;  // a header
      throw Error(path.string() + ":" + std::to_string(number) + ": not a number");
    }
    if (t.rows > 0 && row.size() != t.cols)
      throw Error(path.string() + ":" + std::to_string(number) + ": " + std::to_string(row.size()) +
                  " values, the rows above have " + std::to_string(t.cols));
    t.cols = row.size();
    t.values.insert(t.values.end(), row.begin(), row.end());
    ++t.rows;
  }
  if (t.rows == 0) throw Error(path.string() + ": no rows");
  return t;
}

/// .npy: any 2-D numeric array; .csv/.txt: rows of numbers (any number of
/// columns); other point formats through io::read_points (2 or 3 columns).
/// Throws geods::Error naming the file.
inline Table read_table(const std::filesystem::path& path) {
  Table t;
  if (path.extension() == ".csv" || path.extension() == ".txt") {
    t = read_text_table(path);
  } else if (path.extension() == ".npy") {
    const io::NpyArray array = io::read_npy(path);
    if (array.shape.size() != 2 || array.shape[1] == 0)
      throw Error(path.string() + ": expected a 2-D array of shape (n, d), got " + std::to_string(array.shape.size()) +
                  " dimensions");
    t.rows = array.shape[0];
    t.cols = array.shape[1];
    t.values = array.to_vector<double>();
  } else {
    const io::PointMatrix m = io::read_points(path);
    t.rows = std::size_t(m.rows());
    t.cols = std::size_t(m.cols());
    t.values.assign(m.data(), m.data() + m.size());
  }
  for (std::size_t i = 0; i < t.values.size(); ++i)
    if (!std::isfinite(t.values[i]))
      throw Error(path.string() + ": non-finite value in row " + std::to_string(i / t.cols) + ", column " +
                  std::to_string(i % t.cols));
  return t;
}

/// Calls fn(tree) with the tree over `points` built for its dimension: the
/// compile-time trees for 2 and 3 columns, the run-time one otherwise.
template <typename Fn>
void with_kd_tree(const Table& points, std::size_t leaf_size, const Fn& fn) {
  const spatial::PointView<double> view(points.values.data(), points.rows, points.cols);
  if (points.cols == 2) {
    fn(spatial::KdTree<double, 2>(view, leaf_size));
  } else if (points.cols == 3) {
    fn(spatial::KdTree<double, 3>(view, leaf_size));
  } else {
    fn(spatial::KdTree<double, spatial::Dynamic>(view, leaf_size));
  }
}

/// The tree a command queries: built over --points, or loaded from --tree (a
/// file written by --save, which writes the tree the command built).
struct KdTreeInput {
  std::string points, tree, save;
  std::size_t leaf_size = spatial::KdTree<double>::kDefaultLeafSize;

  void add_options(CLI::App& app) {
    CLI::Option* p = app.add_option("--points", points, "Points, n x d (.npy any d; .xyz/.csv/.ply)");
    app.add_option("--tree", tree, "Instead of --points: a k-d tree written by --save (float64 points)")->excludes(p);
    app.add_option("--leaf-size", leaf_size, "Points per leaf of the k-d tree")->check(CLI::PositiveNumber);
    app.add_option("--save", save, "Output: the k-d tree and its points as a geods archive, for --tree");
  }
  /// The file the points come from.
  const std::string& source() const { return tree.empty() ? points : tree; }

  /// Calls fn(tree, build_s) with the tree for its dimension (the compile-time
  /// trees for 2 and 3, the run-time one otherwise); build_s is 0 for a loaded tree.
  template <typename Fn>
  void with_tree(const std::string& command, const Fn& fn) const {
    if (points.empty() == tree.empty()) throw Error(command + ": give the points with --points or a saved tree with --tree");
    auto use = [&](const auto& t, double build_s) {
      if (!save.empty()) t.save(save);
      fn(t, build_s);
    };
    if (!tree.empty()) {
      const std::size_t dim = spatial::read_kd_tree_info(tree).dim;
      if (dim == 2) {
        use(spatial::KdTree<double, 2>::load(tree), 0.0);
      } else if (dim == 3) {
        use(spatial::KdTree<double, 3>::load(tree), 0.0);
      } else {
        use(spatial::KdTree<double, spatial::Dynamic>::load(tree), 0.0);
      }
      return;
    }
    const Table table = read_table(points);
    Stopwatch build_watch;
    with_kd_tree(table, leaf_size, [&](const auto& t) { use(t, build_watch.seconds()); });
  }
};

}  // namespace geods::cli
