// Demo steps of the voronoi module (Voronoi side): the diagram with its
// Delaunay dual (Figures 42-43), L1 / L-infinity against L2 (Figure 46), the
// slab structure of the post office problem (Figure 50) with query timings,
// the Euclidean minimum spanning tree, the largest empty and smallest enclosing circles.
#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "demo.hpp"
#include "geods/core/rng.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/circles.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/metric_voronoi.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/proximity.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

std::vector<Vec2d> land_points(const DemoContext& context) {
  const io::PointMatrix m = io::read_points(context.data_dir / "land_points.npy");
  std::vector<Vec2d> p(std::size_t(m.rows()));
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = {m(Eigen::Index(i), 0), m(Eigen::Index(i), 1)};
  return p;
}

std::vector<Vec2d> every_kth(const std::vector<Vec2d>& p, std::size_t count) {
  std::vector<Vec2d> out;
  const std::size_t step = std::max<std::size_t>(1, p.size() / count);
  for (std::size_t i = 0; i < p.size(); i += step) out.push_back(p[i]);
  return out;
}

std::vector<Vec2d> uniform(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2d> p(n);
  for (Vec2d& v : p) v = {rng.uniform(), rng.uniform()};
  return p;
}

std::vector<std::pair<Vec2d, Vec2d>> clipped_edges(const voronoi::Voronoi2& v, const AABB2d& box) {
  std::vector<std::pair<Vec2d, Vec2d>> edges;
  for (std::uint32_t e = 0; e < v.edges().size(); ++e)
    if (v.edges()[e].twin > e)
      if (const auto s = v.clipped_edge(e, box)) edges.push_back(*s);
  return edges;
}

const AABB2d kWorld({-180, -90}, {180, 90});

void run_dual(const DemoContext& context, DemoResult& result) {
  const std::vector<Vec2d> p = uniform(60, 42);
  Stopwatch watch;
  const voronoi::Delaunay2 dt(p);
  const voronoi::Voronoi2 v(dt);
  result.timing("Delaunay2 + Voronoi2 of 60 points", watch.seconds());
  v.validate();
  const AABB2d box({-0.15, -0.15}, {1.15, 1.15});
  io::SvgWriter svg(box, 700);
  svg.title("Voronoi diagram and Delaunay triangulation");
  draw_diagram(svg, v.cell_polygons(box), clipped_edges(v, box), p, "#1f4e79", 3.0);
  const auto& t = dt.triangles();
  for (std::size_t k = 0; k < t.size(); k += 3)
    for (std::size_t i = 0; i < 3; ++i)
      svg.segment(p[t[k + i]], p[t[k + (i + 1) % 3]], {.stroke = "#c0392b", .stroke_width = 0.8, .opacity = 0.8});
  svg.points(v.vertices(), {.stroke = "none", .fill = "#1f4e79", .radius = 1.8});
  svg.save(context.out_dir / "voronoi_delaunay.svg");
  result.text = "The Voronoi diagram (blue, cells shaded) as the dual of the Delaunay triangulation (red), like the "
                "seed's Figures 42 and 43: each Voronoi vertex is the circumcentre of a Delaunay triangle, each "
                "Voronoi edge is perpendicular to the Delaunay edge of its two sites, and the cells of hull sites "
                "are unbounded (their rays are cut by the frame, the curve Gamma of Figure 42).";
  result.figures.push_back({"voronoi_delaunay.svg", "60 seeded uniform sites"});
  result.stat("Voronoi2", stats_text(v.stats()));
  result.stat("Delaunay triangles / hull vertices", fmt::format("{} / {}", dt.triangle_count(), dt.hull().size()));
  // The whole land set, timed.
  const std::vector<Vec2d> land = land_points(context);
  Stopwatch land_watch;
  const voronoi::Voronoi2 all(land);
  result.timing(fmt::format("Voronoi2 of all {} land points", land.size()), land_watch.seconds());
  result.stat("land points: Voronoi2", stats_text(all.stats()));
}

void run_metrics(const DemoContext& context, DemoResult& result) {
  const std::vector<Vec2d> p = uniform(30, 46);
  const AABB2d box({-0.1, -0.1}, {1.1, 1.1});
  result.text = "The same 30 sites under three metrics (seed §5.3.3, Figure 46). Under L1 the bisectors are made "
                "of vertical or horizontal rays joined by a 45-degree segment; under L-infinity of a segment parallel "
                "to an axis and diagonal rays. The cells are star-shaped around their sites but no longer convex, and "
                "vertices where four cells meet appear. When two sites differ by the same amount in x and y the L1 "
                "bisector contains whole quadrants; geods gives them to the site nearer in x (the documented "
                "convention).";
  for (const voronoi::Metric metric : {voronoi::Metric::l2, voronoi::Metric::l1, voronoi::Metric::linf}) {
    const std::string name = voronoi::metric_name(metric);
    Stopwatch watch;
    const voronoi::MetricVoronoi v(p, metric, box);
    result.timing(name + " diagram", watch.seconds());
    v.validate();
    io::SvgWriter svg(box, 420);
    svg.title(name + " Voronoi diagram");
    std::vector<std::pair<Vec2d, Vec2d>> edges;
    for (const auto& e : v.edges()) edges.push_back({e.p0, e.p1});
    draw_diagram(svg, v.cells(), edges, p, "#1f4e79", 3.0);
    svg.save(context.out_dir / ("voronoi_" + name + ".svg"));
    result.figures.push_back({"voronoi_" + name + ".svg", name});
    result.stat(name + ": MetricVoronoi", stats_text(v.stats()));
  }
  // The whole land set under L1, timed.
  const std::vector<Vec2d> land = every_kth(land_points(context), 1000);
  Stopwatch watch;
  const voronoi::MetricVoronoi l1(land, voronoi::Metric::l1, kWorld);
  result.timing(fmt::format("L1 diagram of {} land points", land.size()), watch.seconds());
}

void run_post_office(const DemoContext& context, DemoResult& result) {
  // Figure 50: the slabs of a small diagram and a query.
  const std::vector<Vec2d> p = uniform(12, 50);
  const voronoi::Voronoi2 v(p);
  const voronoi::SlabLocator slab(v);
  const AABB2d box({-0.2, -0.2}, {1.2, 1.2});
  io::SvgWriter svg(box, 600);
  svg.title("Slab decomposition for the post office problem");
  draw_diagram(svg, v.cell_polygons(box), clipped_edges(v, box), p, "#1f4e79", 3.5);
  for (const Vec2d& x : v.vertices())
    if (box.contains(x)) svg.segment({x[0], box.lo[1]}, {x[0], box.hi[1]}, {.stroke = "#7f8c8d", .stroke_width = 0.7});
  const Vec2d q(0.62, 0.41);
  const std::uint32_t answer = slab.nearest(q);
  svg.segment(q, p[answer], {.stroke = "#c0392b", .stroke_width = 1.5});
  svg.point(q, {.stroke = "none", .fill = "#c0392b", .radius = 4});
  svg.save(context.out_dir / "voronoi_slabs.svg");
  result.figures.push_back({"voronoi_slabs.svg",
                            fmt::format("{} slabs through the Voronoi vertices; the query (red) finds its slab, then "
                                        "its cell, by two binary searches",
                                        slab.stats().slabs)});

  // Queries per second: slab structure, walking, k-d tree.
  const std::vector<Vec2d> sites = uniform(20000, 51), queries = uniform(200000, 52);
  Stopwatch build;
  const voronoi::Voronoi2 big(sites);
  const double diagram_s = build.seconds();
  Stopwatch slab_build;
  const voronoi::SlabLocator big_slab(big);
  const double slab_s = slab_build.seconds();
  const voronoi::WalkLocator walk(big);
  Stopwatch tree_build;
  const spatial::KdTree<double, 2> tree{spatial::PointView<double>(std::span<const Vec2d>(sites))};
  const double tree_s = tree_build.seconds();
  result.timing("Voronoi2 of 20000 sites", diagram_s);
  result.timing("slab structure", slab_s);
  result.timing("k-d tree", tree_s);
  Stopwatch slab_watch;
  const auto a = big_slab.nearest_batch(queries);
  const double slab_q = slab_watch.seconds();
  Stopwatch walk_watch;
  const auto b = walk.nearest_batch(queries);
  const double walk_q = walk_watch.seconds();
  Stopwatch tree_watch;
  const auto c = tree.query_batch(spatial::PointView<double>(std::span<const Vec2d>(queries)), {1});
  const double tree_q = tree_watch.seconds();
  std::size_t disagree = 0;
  for (std::size_t i = 0; i < queries.size(); ++i)
    disagree += (sites[a[i]] - queries[i]).squaredNorm() != (sites[b[i]] - queries[i]).squaredNorm() ||
                (sites[a[i]] - queries[i]).squaredNorm() != double(c[i].squared_distance);
  result.timing("200000 queries, slab", slab_q);
  result.timing("200000 queries, walk", walk_q);
  result.timing("200000 queries, k-d tree", tree_q);
  result.stat("20000 sites: SlabLocator", stats_text(big_slab.stats()));
  result.stat("queries per second: slab / walk / k-d tree",
              fmt::format("{:.3g} / {:.3g} / {:.3g}", queries.size() / slab_q, queries.size() / walk_q,
                          queries.size() / tree_q));
  result.stat("queries whose nearest distance differs between the three", std::to_string(disagree));
  result.text = "The post office problem (seed §5.4.1): vertical lines through the Voronoi vertices cut the plane "
                "into slabs in which the Voronoi edges are totally ordered (Theorem 8: O(log n) queries, here O(n^1.5) "
                "space as stored). Walking moves from a sampled start site to nearer Delaunay neighbours until none "
                "is nearer; both finish with exact distance comparisons. Below, 200000 uniform queries among 20000 "
                "uniform sites, against the k-d tree.";
}

void run_emst(const DemoContext& context, DemoResult& result) {
  const std::vector<Vec2d> land = land_points(context);
  Stopwatch watch;
  const voronoi::Voronoi2 v(land);
  const voronoi::SpanningTree tree = voronoi::emst(v);
  result.timing(fmt::format("Voronoi2 + EMST of {} land points", land.size()), watch.seconds());
  io::SvgWriter svg(kWorld, 1000);
  svg.title("Euclidean minimum spanning tree of the land points");
  for (const auto& [i, j] : tree.edges) svg.segment(land[i], land[j], {.stroke = "#1e8449", .stroke_width = 1.0});
  svg.points(land, {.stroke = "none", .fill = "black", .radius = 0.8});
  const voronoi::ClosestPair cp = voronoi::closest_pair(v);
  svg.circle((land[cp.i] + land[cp.j]) / 2, std::max(cp.distance, 2.0), {.stroke = "#c0392b", .stroke_width = 2});
  svg.save(context.out_dir / "voronoi_emst.svg");
  result.text = "The Euclidean minimum spanning tree is a subgraph of the Delaunay triangulation (seed §5.4.3), so "
                "Kruskal's algorithm needs only its 3n edges instead of all n^2/2 pairs. The red circle marks the "
                "closest pair, also a Delaunay edge.";
  result.figures.push_back({"voronoi_emst.svg", fmt::format("{} points, {} tree edges, total length {:.1f} degrees",
                                                            land.size(), tree.edges.size(), tree.length)});
  result.stat("closest pair", fmt::format("{} and {}, {:.4g} degrees apart", cp.i, cp.j, cp.distance));
}

void run_circles(const DemoContext& context, DemoResult& result) {
  const std::vector<Vec2d> land = every_kth(land_points(context), 600);
  Stopwatch watch;
  const voronoi::Delaunay2 dt(land);
  const voronoi::Voronoi2 v(dt);
  const voronoi::Circle empty = voronoi::largest_empty_circle(v);
  result.timing("Voronoi2 + largest empty circle", watch.seconds());
  Stopwatch welzl;
  const voronoi::Circle enclosing = voronoi::smallest_enclosing_circle(land);
  result.timing("smallest enclosing circle (Welzl)", welzl.seconds());
  const Vec2d reach = Vec2d::Constant(enclosing.radius * 1.03);
  io::SvgWriter svg(AABB2d(enclosing.center - reach, enclosing.center + reach), 800);
  svg.title("Largest empty circle and smallest enclosing circle");
  std::vector<Vec2d> hull;
  for (std::uint32_t i : dt.hull()) hull.push_back(land[i]);
  svg.polygon(hull, {.stroke = "#7f8c8d", .fill = "#f4f6f6", .stroke_width = 1.0});
  svg.circle(enclosing.center, enclosing.radius, {.stroke = "#2471a3", .stroke_width = 2.0});
  svg.circle(empty.center, empty.radius, {.stroke = "#c0392b", .fill = "#fadbd8", .stroke_width = 2.0, .opacity = 0.8});
  svg.points(land, {.stroke = "none", .fill = "black", .radius = 1.5});
  svg.point(empty.center, {.stroke = "none", .fill = "#c0392b", .radius = 3});
  svg.save(context.out_dir / "voronoi_circles.svg");
  result.text = "Seed §5.4.3: the largest circle with its centre in the convex hull (grey) and no site inside (red) "
                "is centred at a Voronoi vertex or where a Voronoi edge crosses the hull; the smallest circle holding "
                "every site (blue) comes from Welzl's randomized algorithm with exact in-circle decisions.";
  result.figures.push_back({"voronoi_circles.svg", fmt::format("{} land points", land.size())});
  result.stat("largest empty circle: centre / radius",
              fmt::format("({:.2f}, {:.2f}) / {:.2f}", empty.center[0], empty.center[1], empty.radius));
  result.stat("smallest enclosing circle: centre / radius",
              fmt::format("({:.2f}, {:.2f}) / {:.2f}", enclosing.center[0], enclosing.center[1], enclosing.radius));
}

const bool registered_dual =
    register_demo_step({"voronoi", "voronoi_dual", "Voronoi diagram and Delaunay triangulation", &run_dual});
const bool registered_metrics = register_demo_step({"voronoi", "voronoi_metrics", "L2, L1 and L-infinity Voronoi diagrams", &run_metrics});
const bool registered_post_office =
    register_demo_step({"voronoi", "voronoi_post_office", "The post office problem: slabs, walking, k-d tree", &run_post_office});
const bool registered_emst = register_demo_step({"voronoi", "voronoi_emst", "Euclidean minimum spanning tree", &run_emst});
const bool registered_circles =
    register_demo_step({"voronoi", "voronoi_circles", "Largest empty and smallest enclosing circles", &run_circles});

}  // namespace
}  // namespace geods::cli
