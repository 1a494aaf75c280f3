#include "geods/io/table_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "file_util.hpp"
#include "geods/core/error.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/output.hpp"
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
  // A header is a first row none of whose fields is a number: "x,y" is one;
  // "0x10,2" is a row with a bad number, reported, not dropped.
  if (header && !rows.empty()) {
    double v = 0;
    const auto& fields = rows[0].fields;
    if (std::none_of(fields.begin(), fields.end(), [&](std::string_view f) { return detail::parse_double(f, v); }))
      rows.erase(rows.begin());
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

template <typename T>
void write_any_table(const fs::path& path, std::span<const T> values, const std::vector<std::size_t>& shape) {
  check_output_extension(path, OutputKind::table);
  if (shape.empty() || shape.size() > 2)
    fail(path, "cannot write a table of " + std::to_string(shape.size()) + " dimensions (1 or 2)");
  const std::size_t rows = shape[0], cols = shape.size() == 2 ? shape[1] : 1;
  if (detail::checked_mul(path, rows, cols) != values.size())
    fail(path, "table shape holds " + std::to_string(rows * cols) + " values, given " + std::to_string(values.size()));
  const std::string ext = detail::output_extension(path);
  if (ext == ".npy") return write_npy<T>(path, values, shape);
  const char separator = ext == ".csv" ? ',' : ' ';
  fmt::memory_buffer out;
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t c = 0; c < cols; ++c) {
      if (c) out.push_back(separator);
      fmt::format_to(std::back_inserter(out), "{}", values[i * cols + c]);  // shortest exact round trip
    }
    out.push_back('\n');
  }
  detail::write_file(path, std::string_view(out.data(), out.size()));
}

}  // namespace

std::string input_format(const fs::path& path) { return detail::extension(path); }

void write_table(const fs::path& path, std::span<const double> values, const std::vector<std::size_t>& shape) {
  write_any_table(path, values, shape);
}

void write_table(const fs::path& path, std::span<const std::int64_t> values, const std::vector<std::size_t>& shape) {
  write_any_table(path, values, shape);
}

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
