// geods plan: motion planning for a disc robot among polygonal obstacles on the segment Voronoi diagram.
#include <fmt/format.h>

#include <sstream>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/motion_planning.hpp"
#include "segment_voronoi_cli.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

Vec2d parse_xy(const std::string& text, const char* what) {
  std::istringstream in(text);
  double x = 0, y = 0;
  char comma = 0;
  if (!(in >> x >> comma >> y) || comma != ',' || !(in >> std::ws).eof())
    throw Error(fmt::format("--{} must be X,Y, got '{}'", what, text));
  return Vec2d(x, y);
}

class PlanCommand : public Command {
 public:
  std::string name() const override { return "plan"; }
  std::string summary() const override {
    return "Shortest path for a disc robot among polygons, on the segment Voronoi diagram (retraction)";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "OBSTACLES", input_, "Obstacle polygons (.wkt, .geojson, .json, .shp, .gpkg, .kml, .svg)");
    app.add_option("--start", start_, "Start X,Y")->required();
    app.add_option("--goal", goal_, "Goal X,Y")->required();
    app.add_option("--radius", radius_, "The robot's radius")->required();
    app.add_option("--margin", margin_, "Frame: the bounding box grown by margin x its larger side (default 0.25)");
    add_output(app, "-o,--output", output_, "The path, n x 2 (x y)", io::OutputKind::table);
    add_output(app, "--svg", svg_, "A picture of the obstacles, the diagram and the path", io::OutputKind::svg);
  }

  void run(const RunContext&, Report& report) override {
    const Vec2d start = parse_xy(start_, "start"), goal = parse_xy(goal_, "goal");
    const io::PolygonSet set = io::read_polygons(input_);
    if (!set.segments.empty() || !set.points.empty())
      throw Error(input_ + ": obstacles must be polygons (found open lines or points)");
    voronoi::PlanOptions options;
    options.margin = margin_;
    Stopwatch watch;
    const voronoi::MotionPlanner planner(set.rings, options, start, goal);
    const double build_s = watch.seconds();
    Stopwatch query_watch;
    const voronoi::PathPlan plan = planner.plan(start, goal, radius_);
    const double query_s = query_watch.seconds();

    if (!output_.empty()) {
      std::vector<double> xy;
      for (const Vec2d& p : plan.path) xy.insert(xy.end(), {p[0], p[1]});
      io::write_table(output_, std::span<const double>(xy), {plan.path.size(), 2});
    }
    if (!svg_.empty()) {
      const AABB2d view = planner.frame();
      io::SvgWriter svg(view, 900);
      svg.title(fmt::format("path for radius {} among {}", radius_, input_));
      io::SvgStyle fill;
      fill.fill = "#bbbbbb";
      fill.stroke = "#555555";
      for (const auto& ring : set.rings) svg.polygon(ring, fill);
      draw_segment_voronoi(svg, planner.diagram(), view, {}, false);
      if (plan.found) {
        io::SvgStyle path;
        path.stroke = "#e07b00";
        path.stroke_width = 2.5;
        svg.polyline(plan.path, path);
        io::SvgStyle disc;
        disc.stroke = "#e07b00";
        for (const Vec2d& p : {start, goal}) svg.circle(p, radius_, disc);
      }
      io::SvgStyle mark;
      mark.fill = "#2ca02c";
      mark.radius = 4;
      svg.point(start, mark);
      mark.fill = "#d62728";
      svg.point(goal, mark);
      svg.save(svg_);
    }

    Json& j = report.json;
    j["input"] = input_;
    j["obstacles"] = set.rings.size();
    j["start"] = {start[0], start[1]};
    j["goal"] = {goal[0], goal[1]};
    j["radius"] = radius_;
    j["found"] = plan.found;
    if (!plan.found) j["reason"] = plan.reason;
    j["length"] = plan.found ? Json(plan.length) : Json(nullptr);
    j["min_clearance"] = plan.found ? Json(plan.min_clearance) : Json(nullptr);
    j["max_radius"] = plan.max_radius;
    j["path_points"] = plan.path.size();
    j["vertices"] = planner.diagram().vertices().size();
    j["graph_edges"] = planner.graph_edges().size();
    j["build_s"] = build_s;
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    report.lines.push_back(fmt::format("plan: {} obstacles, radius {}", set.rings.size(), radius_));
    if (plan.found)
      report.lines.push_back(fmt::format("  path of length {:.6g} ({} points), clearance {:.6g} >= {}", plan.length,
                                         plan.path.size(), plan.min_clearance, radius_));
    else
      report.lines.push_back("  no path: " + plan.reason);
    report.lines.push_back(fmt::format("  largest radius with a path: {:.6g}; {:.3f} s", plan.max_radius, build_s + query_s));
    if (!output_.empty() && plan.found) report.lines.push_back("  wrote " + output_);
    if (!svg_.empty()) report.lines.push_back("  wrote " + svg_);
  }

 private:
  std::string input_, output_, svg_, start_, goal_;
  double radius_ = 0, margin_ = 0.25;
};

const bool registered_plan = register_command<PlanCommand>();

}  // namespace
}  // namespace geods::cli
