// geods segvoronoi: the Voronoi diagram of line segments and points, and the medial axis of polygons.
#include <fmt/format.h>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "segment_voronoi_cli.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class SegVoronoiCommand : public Command {
 public:
  std::string name() const override { return "segvoronoi"; }
  std::string summary() const override {
    return "Voronoi diagram of line segments and points (lines and parabolic arcs); the medial axis of polygons";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "SEGMENTS", input_,
              "Segments as an n x 4 table (.npy, .csv, .txt: x0 y0 x1 y1), or polygons, lines and points "
              "(.wkt, .geojson, .json, .shp, .gpkg, .kml, .cin, .svg)");
    add_output(app, "-o,--output", output_,
               "The diagram as JSON: sites, vertices (x, y, clearance), edges (sites, vertices, parabolic, primary)",
               io::OutputKind::json);
    add_output(app, "--svg", svg_, "A picture of the sites and the diagram", io::OutputKind::svg);
    app.add_flag("--medial-axis", medial_, "Also the medial axis: the primary edges inside the polygons (even-odd)");
  }

  void run(const RunContext&, Report& report) override {
    const io::PolygonSet set = read_segment_sites(input_);
    const std::vector<double> segments = set.all_segments(), points = flat_points(set.points);
    Stopwatch watch;
    const voronoi::SegmentVoronoi v(points, segments);
    const double build_s = watch.seconds();
    Stopwatch medial_watch;
    std::vector<std::uint32_t> axis;
    if (medial_) axis = v.medial_axis();
    const double medial_s = medial_ ? medial_watch.seconds() : 0.0;
    const auto st = v.stats();

    if (!output_.empty()) {
      Json out;
      Json pts = Json::array(), segs = Json::array(), verts = Json::array(), edges = Json::array();
      for (std::uint32_t p = 0; p < v.num_points(); ++p) pts.push_back({v.point(p)[0], v.point(p)[1]});
      for (std::uint32_t s = 0; s < v.num_segments(); ++s) segs.push_back({v.segment(s)[0], v.segment(s)[1]});
      for (const auto& x : v.vertices()) verts.push_back({x.position[0], x.position[1], x.clearance});
      auto idx = [](std::uint32_t i) { return i == voronoi::SegmentVoronoi::kInfinity ? std::int64_t(-1) : std::int64_t(i); };
      for (const auto& e : v.edges())
        edges.push_back({{"sites", {e.site[0], e.site[1]}},
                         {"vertices", {idx(e.vertex[0]), idx(e.vertex[1])}},
                         {"parabolic", e.parabolic},
                         {"primary", e.primary}});
      out["points"] = pts;
      out["segments"] = segs;
      out["vertices"] = verts;
      out["edges"] = edges;
      if (medial_) out["medial_axis"] = axis;
      io::write_text(output_, out.dump() + "\n");
    }
    if (!svg_.empty()) {
      AABB2d view;
      for (std::uint32_t p = 0; p < v.num_points(); ++p) view.extend(v.point(p));
      const Vec2d m = Vec2d::Constant(0.05 * std::max((view.hi - view.lo).maxCoeff(), 1e-9));
      view = AABB2d(view.lo - m, view.hi + m);
      io::SvgWriter svg(view, 900);
      svg.title("segment Voronoi diagram of " + input_);
      draw_segment_voronoi(svg, v, view, axis);
      svg.save(svg_);
    }

    Json& j = report.json;
    j["input"] = input_;
    j["input_points"] = st.input_points;
    j["input_segments"] = st.input_segments;
    j["points"] = st.points;
    j["segments"] = st.segments;
    j["splits"] = st.splits;
    j["vertices"] = st.vertices;
    j["edges"] = st.edges;
    j["parabolic_edges"] = st.parabolic_edges;
    j["secondary_edges"] = st.secondary_edges;
    j["infinite_edges"] = st.infinite_edges;
    if (medial_) j["medial_axis_edges"] = axis.size();
    j["build_s"] = build_s;
    if (medial_) j["medial_axis_s"] = medial_s;
    j["compute_s"] = build_s + medial_s;
    report.lines.push_back(fmt::format("segvoronoi: {} segments and {} points ({} after splitting {} crossings)",
                                       st.input_segments, st.input_points, st.segments, st.splits));
    report.lines.push_back(fmt::format("  {} vertices, {} edges ({} parabolic, {} secondary) in {:.3f} s", st.vertices,
                                       st.edges, st.parabolic_edges, st.secondary_edges, build_s));
    if (medial_) report.lines.push_back(fmt::format("  medial axis: {} edges", axis.size()));
    if (st.splits > 0)
      report.lines.push_back(fmt::format("  note: crossing segments were split at their intersections ({} cuts)", st.splits));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
    if (!svg_.empty()) report.lines.push_back("  wrote " + svg_);
  }

 private:
  std::string input_, output_, svg_;
  bool medial_ = false;
};

const bool registered_segvoronoi = register_command<SegVoronoiCommand>();

}  // namespace
}  // namespace geods::cli
