// Demo steps of the segment Voronoi diagram and motion planning: the diagram
// and medial axis of the North Carolina county map, and a disc robot's
// shortest paths for two radii among some of the counties.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "demo.hpp"
#include "geods/core/error.hpp"
#include "geods/io/polygon_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/voronoi/motion_planning.hpp"
#include "geods/voronoi/segment_voronoi.hpp"
#include "segment_voronoi_cli.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

AABB2d padded(const AABB2d& b, double fraction) {
  const Vec2d m = Vec2d::Constant(fraction * (b.hi - b.lo).maxCoeff());
  return AABB2d(b.lo - m, b.hi + m);
}

void run_diagram(const DemoContext& context, DemoResult& result) {
  const io::PolygonSet nc = io::read_polygons(context.data_dir / "nc_counties.shp");
  Stopwatch watch;
  const voronoi::SegmentVoronoi v({}, nc.all_segments());
  const double build_s = watch.seconds();
  Stopwatch axis_watch;
  const std::vector<std::uint32_t> axis = v.medial_axis();
  const double axis_s = axis_watch.seconds();
  AABB2d box;
  for (std::uint32_t p = 0; p < v.num_points(); ++p) box.extend(v.point(p));
  const AABB2d view = padded(box, 0.02);
  {
    io::SvgWriter svg(view, 1400);
    svg.title("segment Voronoi diagram of the North Carolina counties");
    draw_segment_voronoi(svg, v, view, {}, true);
    svg.save(context.out_dir / "segment_voronoi_nc.svg");
  }
  {
    io::SvgWriter svg(view, 1400);
    svg.title("medial axes of the North Carolina counties");
    draw_segment_voronoi(svg, v, view, axis, false);
    svg.save(context.out_dir / "segment_voronoi_nc_medial_axis.svg");
  }
  // A zoom on a few counties, where the parabolic arcs show.
  const AABB2d zoom(Vec2d(-80.0, 35.4), Vec2d(-79.2, 36.0));
  {
    io::SvgWriter svg(zoom, 900);
    svg.title("zoom: lines and parabolic arcs");
    draw_segment_voronoi(svg, v, zoom, axis, true);
    svg.save(context.out_dir / "segment_voronoi_nc_zoom.svg");
  }
  const auto s = v.stats();
  result.figures.push_back({"segment_voronoi_nc.svg",
                            fmt::format("Voronoi diagram of the {} county boundary segments (shared borders once): {} "
                                        "vertices, {} edges ({} parabolic; grey: a segment and its own endpoint)",
                                        s.segments, s.vertices, s.edges, s.parabolic_edges)});
  result.figures.push_back({"segment_voronoi_nc_medial_axis.svg",
                            fmt::format("Medial axis (red): the {} primary edges inside the counties", axis.size())});
  result.figures.push_back({"segment_voronoi_nc_zoom.svg", "Zoom on central North Carolina: blue lines and parabolic arcs, "
                                                           "red medial axis, grey secondary edges"});
  result.stat("segments", std::to_string(s.segments));
  result.stat("vertices", std::to_string(s.vertices));
  result.stat("parabolic edges", std::to_string(s.parabolic_edges));
  result.timing("diagram", build_s);
  result.timing("medial axis", axis_s);
  result.text =
      "The Voronoi diagram of line segments (seed §5.3.3, Figure 47) by Fortune's sweep generalized to segment "
      "sites, on an exact 2^25 integer snap of the input; every segment is three sites (its endpoints and its "
      "interior), so bisectors are lines and parabolic arcs, kept exactly and sampled only for drawing. The medial "
      "axis of each county is the part of the diagram inside it. Map: data/nc_counties.shp (lon/lat as plane "
      "coordinates).";
}

void run_planning(const DemoContext& context, DemoResult& result) {
  const io::PolygonSet nc = io::read_polygons(context.data_dir / "nc_counties.shp");
  // Every third county is an obstacle; a disc travels from the west to the east end of the state.
  std::vector<std::vector<Vec2d>> obstacles;
  for (std::size_t i = 0; i < nc.rings.size(); i += 3) obstacles.push_back(nc.rings[i]);
  const Vec2d start(-84.0, 35.2), goal(-76.2, 35.6);
  Stopwatch watch;
  const voronoi::MotionPlanner planner(obstacles, voronoi::PlanOptions{}, start, goal);
  const double build_s = watch.seconds();
  const double rmax = planner.max_radius(start, goal);
  const double radii[2] = {0.1 * rmax, 0.9 * rmax};
  const char* colours[2] = {"#e07b00", "#8b1fa9"};
  io::SvgWriter svg(planner.frame(), 1400);
  svg.title("disc robot paths among counties");
  io::SvgStyle fill;
  fill.fill = "#c8c8c8";
  fill.stroke = "#666666";
  for (const auto& ring : obstacles) svg.polygon(ring, fill);
  draw_segment_voronoi(svg, planner.diagram(), planner.frame(), {}, false);
  std::string lines;
  for (int k = 0; k < 2; ++k) {
    Stopwatch query;
    const voronoi::PathPlan plan = planner.plan(start, goal, radii[k]);
    result.timing(fmt::format("path, r = {:.3g}", radii[k]), query.seconds());
    if (!plan.found) throw Error("demo: no path for radius " + std::to_string(radii[k]) + ": " + plan.reason);
    io::SvgStyle path;
    path.stroke = colours[k];
    path.stroke_width = 3;
    svg.polyline(plan.path, path);
    io::SvgStyle disc;
    disc.stroke = colours[k];
    svg.circle(start, radii[k], disc);
    svg.circle(goal, radii[k], disc);
    lines += fmt::format("{}r = {:.3f}: length {:.3f}, clearance {:.3f}", k ? "; " : "", radii[k], plan.length,
                         plan.min_clearance);
  }
  svg.save(context.out_dir / "motion_planning_nc.svg");
  result.figures.push_back({"motion_planning_nc.svg",
                            fmt::format("Shortest paths on the diagram (blue) for a small disc (orange) and one of 0.9 "
                                        "times the largest radius {:.3f} that gets through (purple): {}",
                                        rmax, lines)});
  result.stat("obstacles", std::to_string(obstacles.size()));
  result.stat("largest radius", fmt::format("{:.4f}", rmax));
  result.timing("planner (diagram + graph)", build_s);
  result.text =
      "Motion planning for a disc robot (seed §5.4.2, Theorem 9): start and goal are retracted onto the segment "
      "Voronoi diagram of the obstacles, edges with clearance below the radius are removed, and Dijkstra by exact "
      "arc length finds the path; the largest radius with a path comes from a bottleneck search on the same graph. "
      "Obstacles: every third county of data/nc_counties.shp, inside a frame around them.";
}

const bool registered_diagram = register_demo_step(
    {"voronoi", "segment_voronoi", "Voronoi diagram of segments and the medial axis", &run_diagram});
const bool registered_planning =
    register_demo_step({"voronoi", "motion_planning", "Motion planning for a disc robot", &run_planning});

}  // namespace
}  // namespace geods::cli
