#include <fmt/format.h>

#include <cmath>

#include "file_util.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/point_io.hpp"
#include "ply.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

void require_finite(const fs::path& path, const std::vector<double>& values, std::size_t dim, const char* what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) fail(path, std::string(what) + " " + std::to_string(i / dim) + " has a non-finite coordinate");
}

// Numbers of the text lines of .xyz, .csv, .edg and .cin files, with line numbers for messages.
struct TextRow {
  std::size_t line;
  std::vector<std::string_view> fields;
};

std::vector<TextRow> text_rows(std::string_view text, bool commas) {
  std::vector<TextRow> rows;
  detail::LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const std::string_view t = detail::trim(line);
    if (t.empty() || t[0] == '#') continue;
    rows.push_back({lines.line_number(), detail::split_fields(t, commas)});
  }
  return rows;
}

double number(const fs::path& path, const TextRow& row, std::size_t column) {
  double v = 0;
  if (column >= row.fields.size())
    fail(path, "line " + std::to_string(row.line) + ": expected at least " + std::to_string(column + 1) + " numbers");
  if (!detail::parse_double(row.fields[column], v))
    fail(path, "line " + std::to_string(row.line) + ": '" + std::string(row.fields[column].substr(0, 40)) + "' is not a number");
  if (!std::isfinite(v)) fail(path, "line " + std::to_string(row.line) + ": non-finite coordinate");
  return v;
}

PointMatrix to_matrix(const std::vector<double>& values, std::size_t dim) {
  PointMatrix m(Eigen::Index(values.size() / dim), Eigen::Index(dim));
  if (!values.empty()) std::copy(values.begin(), values.end(), m.data());
  return m;
}

// Text point files: 2 columns are 2D points, 3 or more are 3D (extra columns such as normals are ignored).
PointMatrix read_text_points(const fs::path& path, bool csv) {
  const auto bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  std::vector<TextRow> rows = text_rows(detail::as_text(bytes), csv);
  if (csv && !rows.empty()) {
    double v = 0;
    if (!detail::parse_double(rows[0].fields[0], v)) rows.erase(rows.begin());  // a header line
  }
  if (rows.empty()) fail(path, "no points");
  const std::size_t dim = rows[0].fields.size() >= 3 ? 3 : 2;
  if (rows[0].fields.size() < 2) fail(path, "line " + std::to_string(rows[0].line) + ": expected 2 or 3 coordinates");
  std::vector<double> values;
  values.reserve(rows.size() * dim);
  for (const TextRow& row : rows)
    for (std::size_t c = 0; c < dim; ++c) values.push_back(number(path, row, c));
  return to_matrix(values, dim);
}

PointMatrix read_npy_points(const fs::path& path, std::size_t cols_lo, std::size_t cols_hi, const char* what) {
  const NpyArray a = read_npy(path);
  if (a.shape.size() != 2 || a.shape[1] < cols_lo || a.shape[1] > cols_hi)
    fail(path, std::string("expected an n x ") + (cols_lo == cols_hi ? std::to_string(cols_lo) : "2 or n x 3") + " array of " +
                   what + "s");
  if (a.shape[0] == 0) fail(path, std::string("no ") + what + "s");
  std::vector<double> values;
  try {
    values = a.to_vector<double>();
  } catch (const Error& e) {
    fail(path, e.what());
  }
  require_finite(path, values, a.shape[1], what);
  return to_matrix(values, a.shape[1]);
}

std::string number_text(double v) { return fmt::format("{}", v); }  // shortest exact round trip

}  // namespace

PointMatrix read_points(const fs::path& path) {
  const std::string ext = detail::extension(path);
  if (ext == ".npy") return read_npy_points(path, 2, 3, "point");
  if (ext == ".xyz" || ext == ".txt") return read_text_points(path, false);
  if (ext == ".csv") return read_text_points(path, true);
  if (ext == ".ply") {
    const auto bytes = detail::read_file(path);
    const detail::PlyData ply = detail::read_ply(path, bytes);
    if (ply.positions.empty()) fail(path, "no points");
    return to_matrix(ply.positions, std::size_t(ply.dim));
  }
  fail(path, "unsupported point format '" + ext + "' (expected .npy, .xyz, .csv or .ply)");
}

void write_points(const fs::path& path, const PointMatrix& points) {
  const std::size_t n = std::size_t(points.rows()), dim = std::size_t(points.cols());
  if (dim != 2 && dim != 3) fail(path, "points must have 2 or 3 coordinates, not " + std::to_string(dim));
  const std::string ext = detail::extension(path);
  if (ext == ".npy") {
    write_npy<double>(path, std::span<const double>(points.data(), n * dim), {n, dim});
    return;
  }
  std::string out;
  const char* sep = ext == ".csv" ? "," : " ";
  if (ext == ".csv") out = dim == 2 ? "x,y\n" : "x,y,z\n";
  else if (ext == ".ply")
    out = fmt::format("ply\nformat ascii 1.0\ncomment written by geods\nelement vertex {}\nproperty double x\n"
                      "property double y\n{}end_header\n",
                      n, dim == 3 ? "property double z\n" : "");
  else if (ext != ".xyz" && ext != ".txt")
    fail(path, "unsupported point format '" + ext + "' for writing (expected .npy, .xyz, .csv or .ply)");
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < dim; ++c) {
      if (c) out += sep;
      out += number_text(points(Eigen::Index(i), Eigen::Index(c)));
    }
    out += '\n';
  }
  detail::write_file(path, out);
}

SegmentMatrix read_segments(const fs::path& path) {
  const std::string ext = detail::extension(path);
  if (ext == ".npy") return read_npy_points(path, 4, 4, "segment");
  if (ext != ".edg" && ext != ".cin") fail(path, "unsupported segment format '" + ext + "' (expected .npy, .edg or .cin)");
  const auto bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  std::vector<TextRow> rows = text_rows(detail::as_text(bytes), false);
  std::vector<double> values;
  if (ext == ".edg") {
    std::size_t count = 0;
    if (rows.empty() || rows[0].fields.size() != 1 || !detail::parse_size(rows[0].fields[0], count))
      fail(path, "first line must be the number of segments");
    if (rows.size() - 1 < count)
      fail(path, "truncated: expected " + std::to_string(count) + " segments, file has " + std::to_string(rows.size() - 1));
    if (rows.size() - 1 > count)
      fail(path, "expected " + std::to_string(count) + " segments, file has " + std::to_string(rows.size() - 1) + " lines of them");
    for (std::size_t r = 1; r < rows.size(); ++r) {
      if (rows[r].fields.size() != 4) fail(path, "line " + std::to_string(rows[r].line) + ": expected x0 y0 x1 y1");
      for (std::size_t c = 0; c < 4; ++c) values.push_back(number(path, rows[r], c));
    }
  } else {
    for (const TextRow& row : rows) {
      if (row.fields[0] == "p") {
        if (row.fields.size() != 3) fail(path, "line " + std::to_string(row.line) + ": expected 'p x y'");
        continue;  // point sites are not segments
      }
      if (row.fields[0] != "s" || row.fields.size() != 5)
        fail(path, "line " + std::to_string(row.line) + ": expected 's x0 y0 x1 y1' or 'p x y'");
      for (std::size_t c = 1; c < 5; ++c) values.push_back(number(path, row, c));
    }
  }
  if (values.empty()) fail(path, "no segments");
  return to_matrix(values, 4);
}

}  // namespace geods::io
