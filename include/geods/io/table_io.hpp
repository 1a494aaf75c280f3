#pragma once
// Tables of numbers, n rows of d columns: the one reader behind read_points,
// read_segments and every input of the CLI.
#include <cstddef>
#include <cstdint>
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
/// (comma-separated; a first line none of whose fields is a number is a
/// header, skipped), .txt (numbers separated by blanks or commas, a header
/// allowed), .xyz (separated by blanks) or .ply (the vertices' x, y and z if
/// present); "-" reads standard input in the format input_format sniffs.
/// Numbers are decimal or scientific ("12", "-1.5e-3"): "0x10" is not one.
/// In text files blank lines and lines starting with '#' are skipped and
/// every row has as many numbers as the first. `row_name` names a row in
/// messages ("point" gives "no points", "point 3 has a non-finite value").
/// With `cols` > 0 a table of another width is an error, found before its values are read.
/// Throws geods::Error naming the file (and the line) for malformed input,
/// non-finite values or no rows.
Table read_table(const std::filesystem::path& path, const std::string& row_name = "row", std::size_t cols = 0);

/// The lower-case extension readers dispatch on (".ply"; ".gz" for "x.ply.gz");
/// for "-", standard input, the format its bytes show: ".npy" (numpy magic),
/// ".ply" (a "ply" line), ".off" (an OFF keyword), ".gz" (gzip magic), else
/// ".txt" (a text table: blanks or commas, a header line allowed).
std::string input_format(const std::filesystem::path& path);

/// Writes a 1-D (n,) or 2-D (n, d) array of the given shape by extension: .npy
/// (float64 or int64, as given), .csv (comma-separated, no header) or .txt
/// (blank-separated), one row per line; "-" writes .npy to standard output.
/// Text holds each value's shortest exact form, "inf" for infinities. Any
/// other extension is an error naming the accepted ones (io::check_output_extension
/// with OutputKind::table checks a name before the work that fills the table).
void write_table(const std::filesystem::path& path, std::span<const double> values, const std::vector<std::size_t>& shape);
void write_table(const std::filesystem::path& path, std::span<const std::int64_t> values,
                 const std::vector<std::size_t>& shape);

}  // namespace geods::io
