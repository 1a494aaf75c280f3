// geods delaunay: Delaunay triangulation of 2D points, optionally constrained by segments.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "command.hpp"
#include "geods/core/aabb.hpp"
#include "geods/core/error.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/table_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

using voronoi::Delaunay2;

class DelaunayCommand : public Command {
 public:
  std::string name() const override { return "delaunay"; }
  std::string summary() const override {
    return "Delaunay triangulation of 2D points (constrained by --segments): triangles as int64 .npy";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "points", points_, "Points, n x 2 (.npy, .csv, .txt, .xyz, .ply)");
    app.add_option("--segments", segments_,
                   "Constraints: int m x 2 point indices (.npy), or m x 4 end coordinates x0 y0 x1 y1 "
                   "(.npy/.edg/.cin; the end points are appended to the points)");
    add_output(app, "-o,--output", output_,
               "Output: int64 m x 3 counter-clockwise triangles, indices into the points (duplicates map to "
               "their first occurrence)",
               io::OutputKind::table);
    add_output(app, "--svg", svg_, "Output: a picture of the triangulation", io::OutputKind::svg);
    add_save(app, save_, "the triangulation", "Delaunay2.load");
  }

  void run(const RunContext&, Report& report) override {
    const std::vector<Vec2d> points = read_points_2d(points_);

    std::vector<Delaunay2::Segment> index_segments;
    std::vector<std::array<Vec2d, 2>> end_segments;
    if (!segments_.empty()) read_segments(points.size(), index_segments, end_segments);

    Stopwatch watch;
    Delaunay2 dt = !end_segments.empty()   ? Delaunay2::from_segment_ends(points, end_segments)
                   : !segments_.empty() ? Delaunay2(points, index_segments)
                                          : Delaunay2(points);
    const double build_s = watch.seconds();
    const voronoi::Delaunay2Stats stats = dt.stats();

    if (!output_.empty()) {
      std::vector<std::int64_t> tri(dt.triangles().begin(), dt.triangles().end());
      io::write_table(output_, std::span<const std::int64_t>(tri), {dt.triangle_count(), 3});
    }
    if (!svg_.empty()) write_svg(dt);
    if (!save_.empty()) dt.save(save_);

    Json& j = report.json;
    put_stats(j, stats);
    j["points"] = points.size();  // the input points: the stats' count, with appended ones, is all_points
    j["all_points"] = stats.points;
    j["degenerate"] = dt.degenerate();
    j["segments"] = index_segments.size() + end_segments.size();
    j["constrained_edges"] = dt.constrained_edges().size();
    j["intersection_points"] = dt.intersection_points().size();
    j["build_s"] = build_s;
    j["compute_s"] = build_s;
    const std::string added =
        dt.points().size() > points.size()
            ? fmt::format(" + {} segment end and intersection points", dt.points().size() - points.size())
            : "";
    report.lines.push_back(fmt::format("delaunay: {} points{} ({} distinct, {} duplicates) -> {} triangles, {} on the hull{}",
                                       points.size(), added, stats.vertices, stats.duplicates, stats.triangles, stats.hull,
                                       dt.degenerate() ? " (degenerate: fewer than 3 points or all collinear)" : ""));
    if (!segments_.empty())
      report.lines.push_back(fmt::format("  {} segments: {} constrained edges, {} intersection points added",
                                         index_segments.size() + end_segments.size(), dt.constrained_edges().size(),
                                         dt.intersection_points().size()));
    report.lines.push_back(fmt::format("  built in {:.3f} s ({} flips)", build_s, stats.flips));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
    if (!svg_.empty()) report.lines.push_back("  wrote " + svg_);
    if (!save_.empty()) report.lines.push_back("  saved " + save_);
  }

 private:
  void read_segments(std::size_t n, std::vector<Delaunay2::Segment>& indices, std::vector<std::array<Vec2d, 2>>& ends) {
    // Integer .npy m x 2: point indices; anything else: end coordinates.
    const bool npy = segments_.size() > 4 && segments_.substr(segments_.size() - 4) == ".npy";
    if (npy) {
      const io::Table t = io::read_table(segments_, "segment");
      if (t.integer()) {
        if (t.cols != 2) throw Error(fmt::format("{}: integer segments must be m x 2 point indices", segments_));
        for (std::size_t k = 0; k < t.rows; ++k) {
          for (const double v : t.row(k))
            if (v < 0 || v >= double(n))
              throw Error(fmt::format("{}: segment {} refers to point {}, but there are {} points", segments_, k, v, n));
          indices.push_back({std::uint32_t(t.row(k)[0]), std::uint32_t(t.row(k)[1])});
        }
        return;
      }
    }
    const io::SegmentMatrix m = io::read_segments(segments_);
    for (long k = 0; k < m.rows(); ++k) ends.push_back({Vec2d(m(k, 0), m(k, 1)), Vec2d(m(k, 2), m(k, 3))});
  }

  void write_svg(const Delaunay2& dt) const {
    const auto p = dt.points();
    AABB2d box = bounds_of<double, 2>(p);
    if (p.empty()) box = AABB2d(Vec2d(0, 0), Vec2d(1, 1));
    const Vec2d pad = ((box.hi - box.lo) * 0.02).cwiseMax(Vec2d(1e-9, 1e-9).cwiseMax(box.hi.cwiseAbs() * 1e-9));
    io::SvgWriter svg(AABB2d(box.lo - pad, box.hi + pad));
    svg.title(fmt::format("Delaunay triangulation of {} points", p.size()));
    const auto& tri = dt.triangles();
    const std::vector<std::uint8_t> inside = dt.segments().empty() ? std::vector<std::uint8_t>() : dt.inside();
    for (std::size_t t = 0; t < dt.triangle_count(); ++t) {
      const std::vector<Vec2d> corners = {p[tri[3 * t]], p[tri[3 * t + 1]], p[tri[3 * t + 2]]};
      svg.polygon(corners, {.stroke = "#4a6fa5", .fill = !inside.empty() && inside[t] ? "#dde8f5" : "none",
                            .stroke_width = 0.5});
    }
    for (const auto& e : dt.constrained_edges()) svg.segment(p[e[0]], p[e[1]], {.stroke = "#c0392b", .stroke_width = 1.5});
    if (dt.degenerate())
      for (std::size_t k = 1; k < dt.hull().size(); ++k) svg.segment(p[dt.hull()[k - 1]], p[dt.hull()[k]], {.stroke = "#4a6fa5"});
    if (p.size() <= 20000) svg.points(p, {.fill = "black", .radius = 1.2});
    svg.save(svg_);
  }

  std::string points_, segments_, output_, svg_, save_;
};

const bool registered_delaunay = register_command<DelaunayCommand>();

}  // namespace
}  // namespace geods::cli
