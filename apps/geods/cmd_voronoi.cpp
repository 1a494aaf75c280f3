// geods voronoi: the Voronoi diagram of 2D points under L2, L1 or L-infinity, or a generalized one (power diagram
// with --weights, farthest-point with --farthest, k-th order with --order), as an SVG and/or cells in JSON.
#include <fmt/format.h>

#include <optional>

#include "command.hpp"
#include "geods/voronoi/metric_voronoi.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"
#include "voronoi_generalized_cli.hpp"

namespace geods::cli {
namespace {

class VoronoiCommand : public Command {
 public:
  std::string name() const override { return "voronoi"; }
  std::string summary() const override {
    return "Voronoi diagram of 2D points (L2 from the Delaunay triangulation, or L1 / L-infinity): SVG and cells as JSON";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "points", points_, "Points, n x 2 (.npy, .csv, .txt, .xyz, .ply)");
    app.add_option("--metric", metric_, "l2 (default), l1 or linf");
    app.add_option("--box", box_, "Clip cells to x0,y0,x1,y1 (default: the points' bounding box grown by 25%)");
    add_output(app, "--svg", svg_, "Output: a figure of the cells, edges and sites", io::OutputKind::svg);
    add_output(app, "-o,--output", output_, "Output: JSON with the box, each point's cell polygon and the edges",
               io::OutputKind::json);
    add_save(app, save_, "the l2 diagram", "Voronoi2.load");
    auto* weights = app.add_option("--weights", weights_, "Power diagram of the points weighted by W (n x 1 .npy, .csv, .txt)");
    auto* farthest = app.add_flag("--farthest", farthest_, "Farthest-point Voronoi diagram");
    auto* order = app.add_option("--order", order_, "K-th order Voronoi diagram (regions of equal k nearest sites)")
                      ->check(CLI::PositiveNumber);
    auto* constraints = app.add_option("--constraints", constraints_,
                                       "Constrained Voronoi diagram VD(S, L): segments as int m x 2 point indices (non-crossing)");
    weights->excludes(farthest)->excludes(order)->excludes(constraints);
    farthest->excludes(order)->excludes(constraints);
    order->excludes(constraints);
  }

  void run(const RunContext&, Report& report) override {
    const voronoi::Metric metric = voronoi::parse_metric(metric_);
    if (!save_.empty() && metric != voronoi::Metric::l2)
      throw Error("--save: only the l2 diagram can be saved, not --metric " + metric_);
    const std::vector<Vec2d> points = read_points_2d(points_);
    const AABB2d box = box_.empty() ? voronoi::frame_around(points) : parse_box(box_);

    std::vector<std::vector<Vec2d>> cells;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edge_sites;
    std::vector<std::pair<Vec2d, Vec2d>> edges;
    Json stats = Json::object();  // the diagram's stats: distinct sites, vertices (L2), ...
    double build_s = 0, cells_s = 0;
    const bool generalized = !weights_.empty() || farthest_ || order_ > 0 || !constraints_.empty();
    std::string kind = voronoi::metric_name(metric), title;
    Json extra;
    if (generalized && (metric != voronoi::Metric::l2 || !save_.empty()))
      throw Error("--weights, --farthest, --order and --constraints take neither --metric nor --save");
    if (generalized) {
      Stopwatch build_watch;
      GeneralizedDiagram g = build_generalized(points, box, weights_, farthest_, order_, constraints_);
      build_s = build_watch.seconds();
      cells = std::move(g.cells), edges = std::move(g.edges), edge_sites = std::move(g.edge_sites);
      stats = std::move(g.stats), extra = std::move(g.extra), kind = g.kind, title = g.title;
    } else if (metric == voronoi::Metric::l2) {
      Stopwatch build_watch;
      const voronoi::Voronoi2 diagram(points);
      build_s = build_watch.seconds();
      Stopwatch cells_watch;
      cells = diagram.cell_polygons(box);
      for (std::uint32_t e = 0; e < diagram.edges().size(); ++e) {
        if (diagram.edges()[e].twin < e) continue;
        if (const auto segment = diagram.clipped_edge(e, box)) {
          edges.push_back(*segment);
          edge_sites.push_back({diagram.edges()[e].site, diagram.opposite_site(e)});
        }
      }
      cells_s = cells_watch.seconds();
      put_stats(stats, diagram.stats());
      if (!save_.empty()) diagram.save(save_);
    } else {
      Stopwatch build_watch;
      const voronoi::MetricVoronoi diagram(points, metric, box);
      build_s = build_watch.seconds();
      cells = diagram.cells();
      for (const auto& e : diagram.edges()) {
        edges.push_back({e.p0, e.p1});
        edge_sites.push_back({e.a, e.b});
      }
      put_stats(stats, diagram.stats());
    }

    if (!svg_.empty()) {
      io::SvgWriter svg(box, 900);
      svg.title(generalized ? title : fmt::format("{} Voronoi diagram of {} points", voronoi::metric_name(metric), points.size()));
      if (kind == "constrained") {  // pieces coloured by their site (a region is several pieces)
        const Json& sites = extra["piece_sites"];
        for (std::size_t k = 0; k < cells.size(); ++k)
          svg.polygon(cells[k], {.stroke = "none", .fill = cell_colour(sites[k].get<std::size_t>())});
        draw_diagram(svg, {}, edges, points, "#1f4e79", points.size() > 2000 ? 0.8 : 2.0);
      } else {
        draw_diagram(svg, cells, edges, points, "#1f4e79", points.size() > 2000 ? 0.8 : 2.0);
      }
      if (kind == "order")  // regions have no edge list: outline them
        for (const auto& cell : cells) svg.polygon(cell, {.stroke = "#1f4e79", .fill = "none", .stroke_width = 1.2});
      if (kind == "constrained")  // the constraints
        for (const auto& s : extra["constraints"]) svg.segment(points[s[0].get<std::size_t>()], points[s[1].get<std::size_t>()], {.stroke = "#c0392b", .stroke_width = 2.5});
      svg.save(svg_);
    }
    if (!output_.empty()) {
      Json out;
      out["metric"] = voronoi::metric_name(metric);
      if (generalized) out["diagram"] = kind, out.update(extra);
      out["box"] = {box.lo[0], box.lo[1], box.hi[0], box.hi[1]};
      Json cell_list = Json::array();
      for (const auto& cell : cells) {
        Json polygon = Json::array();
        for (const Vec2d& v : cell) polygon.push_back({v[0], v[1]});
        cell_list.push_back(std::move(polygon));
      }
      out["cells"] = std::move(cell_list);
      Json edge_list = Json::array();
      for (std::size_t k = 0; k < edges.size(); ++k)
        edge_list.push_back({{"sites", {edge_sites[k].first, edge_sites[k].second}},
                             {"from", {edges[k].first[0], edges[k].first[1]}},
                             {"to", {edges[k].second[0], edges[k].second[1]}}});
      out["edges"] = std::move(edge_list);
      io::write_text(output_, out.dump() + '\n');
    }

    Json& j = report.json;
    j["points"] = points.size();
    j.update(stats);
    j["metric"] = voronoi::metric_name(metric);
    if (generalized) j["diagram"] = kind;
    j["box"] = {box.lo[0], box.lo[1], box.hi[0], box.hi[1]};
    j["edges_in_box"] = edges.size();
    j["build_s"] = build_s;
    j["cells_s"] = cells_s;
    j["compute_s"] = build_s + cells_s;
    report.lines.push_back(fmt::format("voronoi ({}): {} points ({} distinct), {} edges in the box{}",
                                       kind, points.size(), stats["distinct"].get<std::size_t>(), edges.size(),
                                       stats.contains("vertices") ? fmt::format(", {} vertices", stats["vertices"].get<std::size_t>()) : ""));
    report.lines.push_back(fmt::format("  built in {:.3f} s, cells clipped in {:.3f} s", build_s, cells_s));
    if (!svg_.empty()) report.lines.push_back("  wrote " + svg_);
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
    if (!save_.empty()) report.lines.push_back("  saved " + save_);
  }

 private:
  std::string points_, metric_ = "l2", box_, svg_, output_, save_, weights_, constraints_;
  bool farthest_ = false;
  std::size_t order_ = 0;
};

const bool registered_voronoi = register_command<VoronoiCommand>();

}  // namespace
}  // namespace geods::cli
