// Demo step of the voronoi module's generalized diagrams (seed §5.3.2, §5.3.3, §5.4.3):
// a power diagram with its weight circles, the farthest-point diagram, the
// 2nd and 3rd order diagrams, a constrained diagram, and the smallest color-spanning circle.
#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "demo.hpp"
#include "geods/core/rng.hpp"
#include "geods/io/svg.hpp"
#include "geods/voronoi/color_spanning.hpp"
#include "geods/voronoi/constrained_voronoi.hpp"
#include "geods/voronoi/farthest_voronoi.hpp"
#include "geods/voronoi/kth_order_voronoi.hpp"
#include "geods/voronoi/power_diagram.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

const AABB2d kUnit({0, 0}, {1, 1});

// Stronger colours than cell_colour's, for regions that are the picture.
std::string region_colour(std::size_t i) {
  static const char* palette[] = {"#8ecae6", "#ffb703", "#90be6d", "#f28482", "#cdb4db",
                                  "#f6bd60", "#84a59d", "#a2d2ff", "#e9c46a", "#b5838d"};
  return palette[(i * 7) % 10];
}

void draw_cells(io::SvgWriter& svg, const std::vector<std::vector<Vec2d>>& cells) {
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (!cells[i].empty()) svg.polygon(cells[i], {.stroke = "#1f4e79", .fill = region_colour(i), .stroke_width = 1.0});
}

void run_generalized(const DemoContext& context, DemoResult& result) {
  Rng rng(2024);
  std::vector<Vec2d> points;
  std::vector<double> weights;
  for (int i = 0; i < 120; ++i) {
    points.push_back({rng.uniform(0.05, 0.95), rng.uniform(0.05, 0.95)});
    weights.push_back(std::pow(rng.uniform(0.0, 0.07), 2));  // radius up to 0.07
  }

  Stopwatch watch;
  const voronoi::PowerDiagram power(points, weights, kUnit);
  result.timing("power diagram (regular triangulation + cells)", watch.seconds());
  {
    io::SvgWriter svg(kUnit, 700);
    svg.title("Power diagram of weighted points");
    draw_cells(svg, power.cells());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const bool redundant = power.triangulation().is_redundant(std::uint32_t(i));
      svg.circle(points[i], std::sqrt(weights[i]), {.stroke = redundant ? "#c0392b" : "#333333", .stroke_width = 1.0});
      svg.points(std::span(&points[i], 1), {.stroke = "none", .fill = redundant ? "#c0392b" : "black", .radius = 2});
    }
    svg.save(context.out_dir / "voronoi_power.svg");
  }
  result.figures.push_back({"voronoi_power.svg", fmt::format("{} weighted points (circles of radius sqrt(w)); {} redundant ones "
                                                             "(red) have no cell",
                                                             points.size(), power.triangulation().redundant().size())});

  watch = Stopwatch();
  const voronoi::FarthestVoronoi farthest(points, kUnit);
  result.timing("farthest-point diagram", watch.seconds());
  {
    io::SvgWriter svg(kUnit, 700);
    svg.title("Farthest-point Voronoi diagram");
    draw_cells(svg, farthest.cells());
    std::vector<Vec2d> corners;
    for (std::uint32_t c : farthest.corners()) corners.push_back(points[c]);
    svg.polygon(corners, {.stroke = "#555555", .stroke_width = 1.0});
    svg.points(points, {.stroke = "none", .fill = "black", .radius = 2});
    svg.points(corners, {.stroke = "none", .fill = "#c0392b", .radius = 3.5});
    svg.save(context.out_dir / "voronoi_farthest.svg");
  }
  result.figures.push_back({"voronoi_farthest.svg", fmt::format("only the {} hull corners (red) have cells: each holds the points "
                                                                "to which that corner is the farthest site",
                                                                farthest.corners().size())});

  const std::vector<Vec2d> few(points.begin(), points.begin() + 40);
  for (std::size_t k : {2u, 3u}) {
    watch = Stopwatch();
    const voronoi::KthOrderVoronoi order(few, k, kUnit);
    result.timing(fmt::format("order-{} diagram of {} points", k, few.size()), watch.seconds());
    io::SvgWriter svg(kUnit, 700);
    svg.title(fmt::format("Order-{} Voronoi diagram", k));
    std::vector<std::vector<Vec2d>> cells;
    for (const auto& r : order.regions()) cells.push_back(r.polygon);
    draw_cells(svg, cells);
    svg.points(few, {.stroke = "none", .fill = "black", .radius = 2.5});
    const std::string name = fmt::format("voronoi_order{}.svg", k);
    svg.save(context.out_dir / name);
    result.figures.push_back({name, fmt::format("{} regions of points sharing their {} nearest of {} sites", order.regions().size(), k,
                                                few.size())});
  }

  {
    // A floor plan: walls between sites (a room with a door, a corridor wall), and the sites around.
    std::vector<Vec2d> sites(points.begin(), points.begin() + 60);
    const auto n = std::uint32_t(sites.size());
    for (const Vec2d& v : {Vec2d(0.3, 0.3), Vec2d(0.7, 0.3), Vec2d(0.7, 0.7), Vec2d(0.3, 0.7), Vec2d(0.45, 0.7), Vec2d(0.1, 0.15),
                           Vec2d(0.9, 0.15)})
      sites.push_back(v);
    const std::vector<voronoi::ConstrainedVoronoi::Segment> walls{{n, n + 1}, {n + 1, n + 2}, {n + 3, n}, {n + 2, n + 4}, {n + 5, n + 6}};
    watch = Stopwatch();
    const voronoi::ConstrainedVoronoi constrained(sites, walls, kUnit);
    result.timing("constrained Voronoi diagram", watch.seconds());
    io::SvgWriter svg(kUnit, 700);
    svg.title("Constrained Voronoi diagram");
    for (const auto& piece : constrained.pieces())
      svg.polygon(piece.polygon, {.stroke = "none", .fill = region_colour(piece.site)});
    for (const auto& w : constrained.constraints()) svg.segment(sites[w[0]], sites[w[1]], {.stroke = "#c0392b", .stroke_width = 3});
    svg.points(sites, {.stroke = "none", .fill = "black", .radius = 2.5});
    svg.save(context.out_dir / "voronoi_constrained.svg");
    result.figures.push_back({"voronoi_constrained.svg", fmt::format("{} sites and {} walls (red): each region holds the points to "
                                                                     "which its site is the nearest visible one",
                                                                     sites.size(), walls.size())});
  }

  std::vector<std::uint32_t> colors(points.size());
  for (auto& c : colors) c = std::uint32_t(rng.below(4));
  watch = Stopwatch();
  const voronoi::ColorSpanningCircle spanning = voronoi::smallest_color_spanning_circle(points, colors);
  result.timing("smallest color-spanning circle", watch.seconds());
  {
    static const char* palette[] = {"#e63946", "#2a9d8f", "#f4a261", "#3a86ff"};
    io::SvgWriter svg(kUnit, 700);
    svg.title("Smallest color-spanning circle");
    svg.circle(spanning.circle.center, spanning.circle.radius, {.stroke = "#222222", .fill = "#eeeeee", .stroke_width = 2});
    for (std::size_t i = 0; i < points.size(); ++i)
      svg.points(std::span(&points[i], 1), {.stroke = "none", .fill = palette[colors[i]], .radius = 4});
    svg.save(context.out_dir / "voronoi_color_spanning.svg");
  }
  result.figures.push_back({"voronoi_color_spanning.svg",
                            fmt::format("the smallest circle holding one point of each of 4 colors: radius {:.4f}", spanning.circle.radius)});
  result.text = "Seed §5.3.3's generalizations: the power diagram (its dual, the regular triangulation, built with exact "
                "power tests), the farthest-point diagram and k-th order diagrams; of §5.3.2 the constrained diagram "
                "(walls block sight); and of §5.4.3 the smallest color-spanning circle.";
  result.stat("power diagram", fmt::format("{} cells, {} redundant", power.stats().cells, power.stats().redundant));
}

const bool registered = register_demo_step(
    {"voronoi", "voronoi_generalized", "Power, farthest-point, k-th order and constrained diagrams; color-spanning circle", &run_generalized});

}  // namespace
}  // namespace geods::cli
