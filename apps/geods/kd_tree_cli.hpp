#pragma once
// What the knn and range commands share: reading an n x d table of numbers and
// building the k-d tree of the right dimension over it.
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/point_io.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace geods::cli {

/// n rows of `cols` numbers, row-major.
struct Table {
  std::vector<double> values;
  std::size_t rows = 0, cols = 0;
};

/// .npy: any 2-D numeric array (any number of columns); other point formats
/// through io::read_points (2 or 3 columns). Throws geods::Error naming the file.
inline Table read_table(const std::filesystem::path& path) {
  Table t;
  if (path.extension() == ".npy") {
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

}  // namespace geods::cli
