#pragma once
// Shared by `geods segvoronoi`, `geods plan` and the demo: reading segment
// sites and obstacle maps, and drawing a segment Voronoi diagram.
#include <cmath>
#include <string>
#include <vector>

#include "geods/io/polygon_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/io/table_io.hpp"
#include "geods/voronoi/segment_voronoi.hpp"

namespace geods::cli {

/// Sites of a segment Voronoi diagram: an n x 4 table (.npy, .csv, .txt) of
/// segments, or a map (.wkt, .geojson, .json, .shp, .gpkg, .kml, .cin, .svg).
inline io::PolygonSet read_segment_sites(const std::string& path) {
  const std::string ext = io::input_format(path);
  if (ext == ".npy" || ext == ".csv" || ext == ".txt") {
    const io::Table t = io::read_table(path, "segment", 4);
    io::PolygonSet set;
    for (std::size_t i = 0; i < t.rows; ++i) set.segments.push_back({t.row(i)[0], t.row(i)[1], t.row(i)[2], t.row(i)[3]});
    return set;
  }
  return io::read_polygons(path);
}

inline std::vector<double> flat_points(const std::vector<Vec2d>& points) {
  std::vector<double> out;
  for (const Vec2d& p : points) out.insert(out.end(), {p[0], p[1]});
  return out;
}

/// The diagram in `view`: segments black, point sites dots, primary edges
/// blue, secondary ones (a segment and its endpoint) light grey, the edges
/// listed in `highlight` (e.g. the medial axis) red and thicker.
inline void draw_segment_voronoi(io::SvgWriter& svg, const voronoi::SegmentVoronoi& v, const AABB2d& view,
                                 const std::vector<std::uint32_t>& highlight = {}, bool secondary = true) {
  const double step = (view.hi - view.lo).maxCoeff() / 300;
  std::vector<char> hot(v.edges().size(), 0);
  for (std::uint32_t e : highlight) hot[e] = 1;
  // Finite edges whose coarse outline misses the view are not drawn.
  auto visible = [&](std::uint32_t e) {
    const auto c = v.edge_curve(e);
    if (!std::isfinite(c.t0) || !std::isfinite(c.t1)) return true;
    AABB2d b;
    for (int k = 0; k <= 8; ++k) b.extend(c.point(c.t0 + (c.t1 - c.t0) * k / 8));
    return !(b.lo[0] > view.hi[0] || b.hi[0] < view.lo[0] || b.lo[1] > view.hi[1] || b.hi[1] < view.lo[1]);
  };
  for (std::uint32_t e = 0; e < v.edges().size(); ++e) {
    const auto& ed = v.edges()[e];
    if (hot[e] || (!ed.primary && !secondary) || !visible(e)) continue;
    const auto pts = v.sample_edge(e, step, view);
    if (pts.size() < 2) continue;
    io::SvgStyle style;
    style.stroke = ed.primary ? "#3b6fd6" : "#cccccc";
    style.stroke_width = 0.8;
    svg.polyline(pts, style);
  }
  for (std::uint32_t e : highlight) {
    if (!visible(e)) continue;
    const auto pts = v.sample_edge(e, step, view);
    if (pts.size() < 2) continue;
    io::SvgStyle style;
    style.stroke = "#d62728";
    style.stroke_width = 1.6;
    svg.polyline(pts, style);
  }
  io::SvgStyle seg;
  seg.stroke_width = 1.4;
  for (std::uint32_t s = 0; s < v.num_segments(); ++s) svg.segment(v.point(v.segment(s)[0]), v.point(v.segment(s)[1]), seg);
  io::SvgStyle dot;
  dot.fill = "black";
  dot.radius = 1.8;
  for (std::uint32_t p = 0; p < v.num_points(); ++p)
    if (v.point_source(p) != voronoi::SegmentVoronoi::kInfinity) svg.point(v.point(p), dot);
}

}  // namespace geods::cli
