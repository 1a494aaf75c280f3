#include <fmt/format.h>

#include <cmath>

#include "file_util.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/table_io.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

PointMatrix to_matrix(const std::vector<double>& values, std::size_t dim) {
  PointMatrix m(Eigen::Index(values.size() / dim), Eigen::Index(dim));
  if (!values.empty()) std::copy(values.begin(), values.end(), m.data());
  return m;
}

// The first `cols` columns of the table.
PointMatrix columns(const Table& t, std::size_t cols) {
  PointMatrix m(Eigen::Index(t.rows), Eigen::Index(cols));
  for (std::size_t i = 0; i < t.rows; ++i)
    for (std::size_t c = 0; c < cols; ++c) m(Eigen::Index(i), Eigen::Index(c)) = t.values[i * t.cols + c];
  return m;
}

std::string number_text(double v) { return fmt::format("{}", v); }  // shortest exact round trip

}  // namespace

PointMatrix read_points(const fs::path& path) {
  const Table t = read_table(path, "point");
  // A .npy array is exactly the points; text columns after x, y, z (normals...) are ignored.
  if (detail::extension(path) == ".npy" ? t.cols != 2 && t.cols != 3 : t.cols < 2)
    fail(path, "expected an n x 2 or n x 3 array of points, got " + std::to_string(t.cols) + " columns");
  return t.cols <= 3 ? to_matrix(t.values, t.cols) : columns(t, 3);
}

void write_points(const fs::path& path, const PointMatrix& points) {
  const std::size_t n = std::size_t(points.rows()), dim = std::size_t(points.cols());
  if (dim != 2 && dim != 3) fail(path, "points must have 2 or 3 coordinates, not " + std::to_string(dim));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < dim; ++c)
      if (!std::isfinite(points(Eigen::Index(i), Eigen::Index(c))))
        fail(path, fmt::format("cannot write points: point {} has a non-finite coordinate ({:g} in column {})", i,
                               points(Eigen::Index(i), Eigen::Index(c)), c));
  const std::string ext = detail::output_extension(path);
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
  if (ext != ".edg" && ext != ".cin") {
    if (ext != ".npy" && ext != ".csv" && ext != ".txt")
      fail(path, "unsupported segment format '" + ext + "' (expected .npy, .csv, .txt, .edg or .cin)");
    return to_matrix(read_table(path, "segment", 4).values, 4);
  }
  const auto bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  std::vector<detail::TextRow> rows = detail::text_rows(detail::as_text(bytes), false);
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
      for (std::size_t c = 0; c < 4; ++c) values.push_back(detail::number(path, rows[r], c));
    }
  } else {
    for (const detail::TextRow& row : rows) {
      if (row.fields[0] == "p") {
        if (row.fields.size() != 3) fail(path, "line " + std::to_string(row.line) + ": expected 'p x y'");
        continue;  // point sites are not segments
      }
      if (row.fields[0] != "s" || row.fields.size() != 5)
        fail(path, "line " + std::to_string(row.line) + ": expected 's x0 y0 x1 y1' or 'p x y'");
      for (std::size_t c = 1; c < 5; ++c) values.push_back(detail::number(path, row, c));
    }
  }
  if (values.empty()) fail(path, "no segments");
  return to_matrix(values, 4);
}

}  // namespace geods::io
