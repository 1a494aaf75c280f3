// Demo steps of the Delaunay triangulation (module voronoi): the constrained
// triangulation of the coastline and of a polygon with holes, like the seed's Figure 49.
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "demo.hpp"
#include "geods/core/rng.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

using voronoi::Delaunay2;

// Triangles (shaded when inside the segments, if `shade`), constrained edges on top.
void draw(io::SvgWriter& svg, const Delaunay2& dt, double edge_width, bool shade) {
  const auto p = dt.points();
  const auto& tri = dt.triangles();
  std::vector<std::uint8_t> inside = dt.inside();
  if (!shade) inside.assign(inside.size(), 0);
  for (std::size_t t = 0; t < dt.triangle_count(); ++t) {
    const std::vector<Vec2d> corners = {p[tri[3 * t]], p[tri[3 * t + 1]], p[tri[3 * t + 2]]};
    svg.polygon(corners, {.stroke = "#7f8c8d", .fill = inside[t] ? "#d6eaf8" : "none", .stroke_width = edge_width});
  }
  for (const auto& e : dt.constrained_edges())
    svg.segment(p[e[0]], p[e[1]], {.stroke = "#c0392b", .stroke_width = 3 * edge_width});
}

void run_constrained(const DemoContext& context, DemoResult& result) {
  // The coastline: land points plus the coastline segments as constraints.
  const io::PointMatrix land = io::read_points(context.data_dir / "land_points.npy");
  const io::SegmentMatrix coast = io::read_segments(context.data_dir / "land_segments.npy");
  std::vector<Vec2d> points;
  for (Eigen::Index i = 0; i < land.rows(); ++i) points.emplace_back(land(i, 0), land(i, 1));
  // Segments that wrap around the antimeridian (from x = 179 to x = -180) would cut
  // across the whole map: they are left out.
  std::vector<std::array<Vec2d, 2>> segments;
  std::size_t wrapping = 0;
  for (Eigen::Index k = 0; k < coast.rows(); ++k) {
    if (std::abs(coast(k, 2) - coast(k, 0)) > 180) {
      ++wrapping;
      continue;
    }
    segments.push_back({Vec2d(coast(k, 0), coast(k, 1)), Vec2d(coast(k, 2), coast(k, 3))});
  }

  Stopwatch plain_watch;
  const Delaunay2 plain(points);
  result.timing("Delaunay triangulation of the land points", plain_watch.seconds());
  Stopwatch watch;
  const Delaunay2 cdt = Delaunay2::from_segment_ends(points, segments);
  result.timing("constrained Delaunay triangulation with the coastline", watch.seconds());
  cdt.validate();

  io::SvgWriter world(AABB2d({-182, -92}, {182, 86}), 1200);
  world.title("Constrained Delaunay triangulation of the land points and the coastline");
  draw(world, cdt, 0.25, false);
  world.save(context.out_dir / "delaunay_coast.svg");

  // A polygon with two holes and scattered points inside, legible at full size.
  std::vector<Vec2d> poly;
  std::vector<Delaunay2::Segment> rings;
  const auto ring = [&](Vec2d center, double radius, int corners, double wobble, Rng& rng) {
    const std::uint32_t first = std::uint32_t(poly.size());
    for (int k = 0; k < corners; ++k) {
      const double angle = 2 * std::numbers::pi * k / corners;
      const double r = radius * (1 + wobble * rng.uniform(-1, 1));
      poly.push_back(center + r * Vec2d(std::cos(angle), std::sin(angle)));
      rings.push_back({first + std::uint32_t(k), first + std::uint32_t((k + 1) % corners)});
    }
  };
  Rng rng(49);
  ring({0, 0}, 10, 28, 0.25, rng);
  ring({-3.5, 1.5}, 2.5, 9, 0.2, rng);
  ring({4, -2}, 2, 7, 0.2, rng);
  for (int i = 0; i < 120; ++i) poly.emplace_back(rng.uniform(-9, 9), rng.uniform(-9, 9));
  const Delaunay2 holes(poly, rings);
  holes.validate();
  std::size_t holes_inside = 0;
  for (std::uint8_t in : holes.inside()) holes_inside += in;
  io::SvgWriter figure(AABB2d({-13, -13}, {13, 13}), 600);
  figure.title("Polygon with two holes: constrained Delaunay triangulation, inside shaded");
  draw(figure, holes, 0.8, true);
  figure.points(std::span<const Vec2d>(poly), {.fill = "black", .radius = 1.5});
  figure.save(context.out_dir / "delaunay_holes.svg");

  result.text =
      "Constrained Delaunay triangulations (seed §5.3.2, Figure 49): the segments (red) are edges, every other edge "
      "is locally Delaunay among the points it can see. Crossing coastline segments are split at a new point. In "
      "the polygon with holes, the triangles inside (even-odd from outside the hull) are shaded.";
  result.figures.push_back(
      {"delaunay_coast.svg",
       fmt::format("Coastline: {} points, {} segments ({} wrapping around the antimeridian left out), {} triangles, "
                   "{} crossings split",
                   points.size(), segments.size(), wrapping, cdt.triangle_count(), cdt.intersection_points().size())});
  result.figures.push_back({"delaunay_holes.svg", fmt::format("Polygon with two holes: {} triangles, {} inside",
                                                              holes.triangle_count(), holes_inside)});
  result.stat("land points: triangles (unconstrained)", std::to_string(plain.triangle_count()));
  result.stat("land points: hull vertices", std::to_string(plain.hull().size()));
  result.stat("coastline: constrained edges", std::to_string(cdt.constrained_edges().size()));
  result.stat("coastline: duplicate end points merged", std::to_string(cdt.duplicate_count()));
}

const bool registered =
    register_demo_step({"voronoi", "constrained", "Constrained Delaunay triangulation", &run_constrained});

}  // namespace
}  // namespace geods::cli
