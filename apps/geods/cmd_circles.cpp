// geods circles: the circle problems of seed §5.4.3 on 2D points: the smallest enclosing
// circle, the largest empty circle and, with --colors, the smallest color-spanning circle.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "command.hpp"
#include "geods/io/svg.hpp"
#include "geods/voronoi/circles.hpp"
#include "geods/voronoi/color_spanning.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"
#include "voronoi_generalized_cli.hpp"

namespace geods::cli {
namespace {

Json circle_json(const voronoi::Circle& c) { return {{"center", {c.center[0], c.center[1]}}, {"radius", c.radius}}; }

class CirclesCommand : public Command {
 public:
  std::string name() const override { return "circles"; }
  std::string summary() const override {
    return "smallest enclosing, largest empty and (with --colors) smallest color-spanning circle of 2D points";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "points", points_, "Points, n x 2 (.npy, .csv, .txt, .xyz, .ply)");
    app.add_option("--colors", colors_, "A color per point (non-negative integers: 1-D .npy or n x 1 table): "
                                        "also the smallest circle holding a point of every color");
    add_output(app, "--svg", svg_, "Output: a figure of the points and circles", io::OutputKind::svg);
  }

  void run(const RunContext&, Report& report) override {
    const std::vector<Vec2d> points = read_points_2d(points_);
    std::vector<std::uint32_t> colors;
    if (!colors_.empty()) {
      for (double c : read_per_point(colors_, points.size(), "--colors")) {
        if (!(c >= 0 && c == std::floor(c) && c < 4294967296.0))
          throw Error("--colors: " + colors_ + " holds " + format_number(c) + ", not a non-negative integer color");
        colors.push_back(std::uint32_t(c));
      }
    }
    Stopwatch watch;
    const voronoi::Circle enclosing = voronoi::smallest_enclosing_circle(points);
    const double enclosing_s = watch.seconds();
    watch = Stopwatch();
    const voronoi::Circle empty = voronoi::largest_empty_circle(points);
    const double empty_s = watch.seconds();
    std::optional<voronoi::ColorSpanningCircle> spanning;
    double spanning_s = 0;
    if (!colors.empty()) {
      watch = Stopwatch();
      spanning = voronoi::smallest_color_spanning_circle(points, colors);
      spanning_s = watch.seconds();
    }

    if (!svg_.empty()) {
      const Vec2d reach = Vec2d::Constant(enclosing.radius * 1.05 + 1e-9);
      io::SvgWriter svg(AABB2d(enclosing.center - reach, enclosing.center + reach), 800);
      svg.title(fmt::format("Circles of {} points", points.size()));
      svg.circle(enclosing.center, enclosing.radius, {.stroke = "#1f4e79", .stroke_width = 2});
      svg.circle(empty.center, empty.radius, {.stroke = "#2a9d8f", .fill = "#2a9d8f", .stroke_width = 2, .opacity = 0.25});
      if (spanning) {
        static const char* palette[] = {"#e63946", "#f4a261", "#2a9d8f", "#264653", "#8338ec", "#3a86ff", "#ffbe0b", "#6a994e"};
        for (std::size_t i = 0; i < points.size(); ++i) {
          const std::size_t c = std::size_t(std::lower_bound(spanning->colors.begin(), spanning->colors.end(), colors[i]) -
                                            spanning->colors.begin());
          svg.points(std::span(&points[i], 1), {.stroke = "none", .fill = palette[c % 8], .radius = 2.5});
        }
        svg.circle(spanning->circle.center, spanning->circle.radius, {.stroke = "#e63946", .stroke_width = 2.5});
      } else {
        svg.points(points, {.stroke = "none", .fill = "black", .radius = 2});
      }
      svg.save(svg_);
    }

    Json& j = report.json;
    j["points"] = points.size();
    j["enclosing"] = circle_json(enclosing);
    j["largest_empty"] = circle_json(empty);
    j["enclosing_s"] = enclosing_s;
    j["largest_empty_s"] = empty_s;
    report.lines.push_back(fmt::format("circles of {} points: smallest enclosing r = {:.6g} at ({:.6g}, {:.6g}), largest empty r = {:.6g} at ({:.6g}, {:.6g})",
                                       points.size(), enclosing.radius, enclosing.center[0], enclosing.center[1], empty.radius,
                                       empty.center[0], empty.center[1]));
    if (spanning) {
      Json s = circle_json(spanning->circle);
      s["support"] = spanning->support;
      s["colors"] = spanning->colors;
      s["chosen"] = spanning->chosen;
      j["color_spanning"] = std::move(s);
      j["color_spanning_s"] = spanning_s;
      report.lines.push_back(fmt::format("  smallest color-spanning ({} colors) r = {:.6g} at ({:.6g}, {:.6g}) in {:.3f} s",
                                         spanning->colors.size(), spanning->circle.radius, spanning->circle.center[0],
                                         spanning->circle.center[1], spanning_s));
    }
    j["compute_s"] = enclosing_s + empty_s + spanning_s;
    if (!svg_.empty()) report.lines.push_back("  wrote " + svg_);
  }

 private:
  std::string points_, colors_, svg_;
};

const bool registered_circles = register_command<CirclesCommand>();

}  // namespace
}  // namespace geods::cli
