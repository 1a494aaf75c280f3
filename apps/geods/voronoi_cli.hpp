#pragma once
// What the voronoi and nearest commands and the voronoi demo share: reading 2D
// points, parsing a box, and drawing a diagram's cells, edges and sites into an SVG.
#include <fmt/format.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/error.hpp"
#include "geods/io/svg.hpp"
#include "geods/io/table_io.hpp"

namespace geods::cli {

/// An n x 2 table of points (io::read_table: .npy, .csv, .txt, .xyz, .ply). Throws geods::Error naming the file.
inline std::vector<Vec2d> read_points_2d(const std::filesystem::path& path) {
  const io::Table t = io::read_table(path, "point", 2);
  std::vector<Vec2d> points(t.rows);
  for (std::size_t i = 0; i < t.rows; ++i) points[i] = {t.values[2 * i], t.values[2 * i + 1]};
  return points;
}

/// An n x 3 table of points (io::read_table: .npy, .csv, .txt, .xyz, .ply). Throws geods::Error naming the file.
inline std::vector<Vec3d> read_points_3d(const std::filesystem::path& path) {
  const io::Table t = io::read_table(path, "point", 3);
  std::vector<Vec3d> points(t.rows);
  for (std::size_t i = 0; i < t.rows; ++i) points[i] = {t.values[3 * i], t.values[3 * i + 1], t.values[3 * i + 2]};
  return points;
}

/// "x0,y0,x1,y1" with x0 < x1 and y0 < y1.
/// The comma-separated numbers of `text` (a field that is not a number gives NaN).
inline std::vector<double> parse_numbers(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string field;
  while (std::getline(in, field, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(field, &used));
      if (used != field.size()) v.push_back(std::nan(""));
    } catch (const std::exception&) {
      v.push_back(std::nan(""));
    }
  }
  return v;
}

inline AABB2d parse_box(const std::string& text) {
  const std::vector<double> v = parse_numbers(text);
  if (v.size() != 4 || !(v[0] < v[2]) || !(v[1] < v[3]) || !std::isfinite(v[2] - v[0]) || !std::isfinite(v[3] - v[1]))
    throw Error("--box: expected x0,y0,x1,y1 with x0 < x1 and y0 < y1, got '" + text + "'");
  return AABB2d({v[0], v[1]}, {v[2], v[3]});
}

/// A light colour per cell, so that neighbouring cells are told apart.
inline std::string cell_colour(std::size_t i) {
  static const char* palette[] = {"#fde2e4", "#e2ece9", "#dfe7fd", "#fff1e6", "#e9f5db",
                                  "#f0e6ef", "#fad2e1", "#d7e3fc", "#eae4e9", "#cddafd"};
  return palette[(i * 7) % 10];
}

/// Cells (filled, one colour each), edges and sites.
inline void draw_diagram(io::SvgWriter& svg, const std::vector<std::vector<Vec2d>>& cells,
                         const std::vector<std::pair<Vec2d, Vec2d>>& edges, std::span<const Vec2d> sites,
                         const std::string& edge_colour = "#1f4e79", double site_radius = 2.0) {
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (!cells[i].empty()) svg.polygon(cells[i], {.stroke = "none", .fill = cell_colour(i)});
  for (const auto& [a, b] : edges) svg.segment(a, b, {.stroke = edge_colour, .stroke_width = 1.2});
  svg.points(sites, {.stroke = "none", .fill = "black", .radius = site_radius});
}

}  // namespace geods::cli
