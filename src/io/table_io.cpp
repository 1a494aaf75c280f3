#include "geods/io/table_io.hpp"

#include <algorithm>
#include <cmath>

#include "file_util.hpp"
#include "geods/core/error.hpp"
#include "geods/io/npy.hpp"
#include "ply.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

void check_width(const fs::path& path, const std::string& row_name, std::size_t cols, std::size_t expected) {
  if (expected && cols != expected)
    fail(path, "expected an n x " + std::to_string(expected) + " array of " + row_name + "s, got " +
                   std::to_string(cols) + " columns");
}

// Text tables: `commas` splits CSV fields (empty ones are errors); otherwise
// blanks separate, and with `blank_or_comma` commas count as blanks.
Table read_text_table(const fs::path& path, bool commas, bool blank_or_comma, bool header, const std::string& row_name,
                      std::size_t cols) {
  const auto bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  std::string text(detail::as_text(bytes));
  if (blank_or_comma) std::replace(text.begin(), text.end(), ',', ' ');
  std::vector<detail::TextRow> rows = detail::text_rows(text, commas);
  if (header && !rows.empty()) {
    double v = 0;
    if (!detail::parse_double(rows[0].fields[0], v)) rows.erase(rows.begin());
  }
  if (rows.empty()) fail(path, "no " + row_name + "s");
  Table t;
  t.rows = rows.size();
  t.cols = rows[0].fields.size();
  check_width(path, row_name, t.cols, cols);
  t.values.reserve(t.rows * t.cols);
  for (const detail::TextRow& row : rows) {
    if (row.fields.size() != t.cols)
      fail(path, "line " + std::to_string(row.line) + ": " + std::to_string(row.fields.size()) +
                     " numbers, the rows above have " + std::to_string(t.cols));
    for (std::size_t c = 0; c < t.cols; ++c) t.values.push_back(detail::number(path, row, c));
  }
  return t;
}

Table read_npy_table(const fs::path& path, const std::string& row_name, std::size_t cols) {
  const NpyArray a = read_npy(path);
  if (a.shape.size() != 2 || a.shape[1] == 0)
    fail(path, "expected a 2-D array of n x " + (cols ? std::to_string(cols) : std::string("d")) + " numbers, got " +
                   std::to_string(a.shape.size()) + " dimensions");
  check_width(path, row_name, a.shape[1], cols);
  if (a.shape[0] == 0) fail(path, "no " + row_name + "s");
  Table t;
  t.rows = a.shape[0];
  t.cols = a.shape[1];
  t.dtype = a.dtype;
  try {
    t.values = a.to_vector<double>();
  } catch (const Error& e) {
    fail(path, e.what());
  }
  for (std::size_t i = 0; i < t.values.size(); ++i)
    if (!std::isfinite(t.values[i]))
      fail(path, row_name + " " + std::to_string(i / t.cols) + " has a non-finite value (column " +
                     std::to_string(i % t.cols) + ")");
  return t;
}

Table read_ply_table(const fs::path& path, const std::string& row_name, std::size_t cols) {
  const auto bytes = detail::read_file(path);
  detail::PlyData ply = detail::read_ply(path, bytes);
  if (ply.positions.empty()) fail(path, "no " + row_name + "s");
  Table t;
  t.cols = std::size_t(ply.dim);
  check_width(path, row_name, t.cols, cols);
  t.rows = ply.positions.size() / t.cols;
  t.values = std::move(ply.positions);
  return t;
}

}  // namespace

Table read_table(const fs::path& path, const std::string& row_name, std::size_t cols) {
  const std::string ext = detail::extension(path);
  if (ext == ".npy") return read_npy_table(path, row_name, cols);
  if (ext == ".csv") return read_text_table(path, true, false, true, row_name, cols);
  if (ext == ".txt") return read_text_table(path, false, true, true, row_name, cols);
  if (ext == ".xyz") return read_text_table(path, false, false, false, row_name, cols);
  if (ext == ".ply") return read_ply_table(path, row_name, cols);
  fail(path, "unsupported table format '" + ext + "' (expected .npy, .csv, .txt, .xyz or .ply)");
}

}  // namespace geods::io
