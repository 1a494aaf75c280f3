// Demo steps of the core and io modules: info on every data file, and the
// Morton (Z-order) curve through the demo points.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "demo.hpp"
#include "file_info.hpp"
#include "geods/core/morton.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

namespace fs = std::filesystem;

void run_info(const DemoContext& context, DemoResult& result) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(context.data_dir)) {
    // (a shapefile's .dbf, .shx and .prj go with its .shp)
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && ext != ".md" && ext != ".dbf" && ext != ".shx" && ext != ".prj")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  result.text = "geods info on every file in data/: what it holds, its bounds and the problems validate() finds.";
  for (const fs::path& file : files) {
    Stopwatch watch;
    const Report report = describe_file(file);
    std::string summary = report.lines.empty() ? "" : report.lines.front();
    summary = summary.substr(summary.find(':') + 2);
    for (std::size_t i = 1; i < report.lines.size(); ++i) {
      if (report.lines[i].find("problem") != std::string::npos || report.lines[i].find("closed") != std::string::npos)
        summary += ";" + report.lines[i].substr(1);
    }
    result.stat(file.filename().string(), summary);
    result.timing("read + describe " + file.filename().string(), watch.seconds());
  }
}

// Hue h in [0, 1) to an SVG colour at full saturation and value.
std::string hue_color(double h) {
  const double r = std::clamp(std::abs(h * 6 - 3) - 1, 0.0, 1.0);
  const double g = std::clamp(2 - std::abs(h * 6 - 2), 0.0, 1.0);
  const double b = std::clamp(2 - std::abs(h * 6 - 4), 0.0, 1.0);
  return fmt::format("rgb({},{},{})", int(r * 220), int(g * 220), int(b * 220));
}

double tour_length(const std::vector<Vec2d>& points, const std::vector<std::uint32_t>& order) {
  double length = 0;
  for (std::size_t i = 1; i < order.size(); ++i) length += (points[order[i]] - points[order[i - 1]]).norm();
  return length;
}

void run_morton(const DemoContext& context, DemoResult& result) {
  const io::PointMatrix matrix = io::read_points(context.data_dir / "land_points.npy");
  std::vector<Vec2d> points(matrix.rows());
  for (Eigen::Index i = 0; i < matrix.rows(); ++i) points[i] = {matrix(i, 0), matrix(i, 1)};

  Stopwatch watch;
  const std::vector<std::uint32_t> order = morton_order(points);
  result.timing("morton_order", watch.seconds());

  const AABB2d box = bounds_of<double, 2>(points);
  io::SvgWriter svg(box, 1000);
  svg.title("Morton order of the Natural Earth land points");
  // The curve in 64 pieces coloured along its length, so the Z pattern reads at a glance.
  constexpr std::size_t kPieces = 64;
  for (std::size_t piece = 0; piece < kPieces; ++piece) {
    const std::size_t begin = piece * order.size() / kPieces;
    const std::size_t end = std::min(order.size(), (piece + 1) * order.size() / kPieces + 1);
    std::vector<Vec2d> line;
    for (std::size_t i = begin; i < end; ++i) line.push_back(points[order[i]]);
    svg.polyline(line, {.stroke = hue_color(0.8 * double(piece) / kPieces), .stroke_width = 0.8});
  }
  svg.points(points, {.stroke = "none", .fill = "black", .radius = 0.8});
  svg.save(context.out_dir / "morton_order.svg");
  result.figures.push_back({"morton_order.svg", fmt::format("{} land points joined in Z order (red first, violet last)",
                                                            points.size())});

  std::vector<std::uint32_t> input_order(points.size());
  for (std::uint32_t i = 0; i < input_order.size(); ++i) input_order[i] = i;
  result.text = "Morton codes interleave the bits of quantized coordinates; sorting by them gives the Z-order "
                "curve, the pointer-free layout of linear quadtrees and octrees.";
  result.stat("points", std::to_string(points.size()));
  result.stat("tour length in Z order (degrees)", fmt::format("{:.1f}", tour_length(points, order)));
  result.stat("tour length in file order (degrees)", fmt::format("{:.1f}", tour_length(points, input_order)));
}

const bool registered_info = register_demo_step({"core", "info", "What the data files hold", &run_info});
const bool registered_morton = register_demo_step({"core", "morton", "Morton order of the demo points", &run_morton});

}  // namespace
}  // namespace geods::cli
