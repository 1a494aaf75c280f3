#pragma once
// Tables of numbers, n rows of d columns: the one reader behind read_points,
// read_segments and every input of the CLI.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "geods/core/dtype.hpp"

namespace geods::io {

/// n rows of `cols` finite numbers, row-major, converted to double; `dtype` is
/// the element type the file stores (f64 for text and PLY).
struct Table {
  std::size_t rows = 0, cols = 0;
  DType dtype = DType::f64;
  std::vector<double> values;  // rows * cols

  std::span<const double> row(std::size_t i) const { return {values.data() + i * cols, cols}; }
  /// The file stores integers (an integer .npy): indices rather than coordinates.
  bool integer() const { return dtype != DType::f32 && dtype != DType::f64; }
};

/// Reads a table by extension: .npy (a 2-D array of any numeric dtype), .csv
/// (comma-separated; a first line that does not start with a number is a
/// header), .txt (numbers separated by blanks or commas, a header allowed),
/// .xyz (separated by blanks) or .ply (the vertices' x, y and z if present).
/// In text files blank lines and lines starting with '#' are skipped and
/// every row has as many numbers as the first. `row_name` names a row in
/// messages ("point" gives "no points", "point 3 has a non-finite value").
/// With `cols` > 0 a table of another width is an error, found before its values are read.
/// Throws geods::Error naming the file (and the line) for malformed input,
/// non-finite values or no rows.
Table read_table(const std::filesystem::path& path, const std::string& row_name = "row", std::size_t cols = 0);

}  // namespace geods::io
