// Demo step of the voronoi module in 3D: the Delaunay tetrahedralization of
// points in a ball (the tetrahedra behind a cut, shrunk so that each one shows)
// and the Voronoi cells of points in a box, exploded, rendered with the ray module.
#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "demo.hpp"
#include "geods/core/rng.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/ray/render.hpp"
#include "geods/voronoi/delaunay3.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "geods/voronoi/voronoi3.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

// Renders `mesh` seen from direction `view` (above and to the side), into out_dir/name.
void picture(const DemoContext& context, const TriMesh& mesh, const std::string& name, const Vec3f& view) {
  ray::RenderOptions options;
  options.width = options.height = 448;
  options.camera = ray::Camera::framing(mesh.bounds(), view);
  options.shadows = true;
  io::write_png(context.out_dir / name, ray::render(mesh, options).image);
}

void run_delaunay3(const DemoContext& context, DemoResult& result) {
  // 300 random points in the unit ball, 120 of them on its sphere.
  Rng rng(3);
  std::vector<Vec3d> points;
  while (points.size() < 300) {
    const Vec3d p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (p.squaredNorm() > 1 || p.squaredNorm() < 1e-6) continue;
    points.push_back(points.size() < 120 ? Vec3d(p.normalized()) : p);
  }
  Stopwatch watch;
  const voronoi::Delaunay3 dt(points);
  result.timing("tetrahedralize 300 points in a ball", watch.seconds());
  dt.validate();
  result.stat("Delaunay3", stats_text(dt.stats()));

  // The tetrahedra behind a cut through the middle (x below the median of their centroids),
  // each shrunk to 60 % about its centroid.
  const auto& tets = dt.tetrahedra();
  std::vector<double> xs;
  for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t) {
    double x = 0;
    for (int k = 0; k < 4; ++k) x += points[tets[4 * t + k]][0] / 4;
    xs.push_back(x);
  }
  std::vector<double> sorted = xs;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double cut = sorted[sorted.size() / 2];
  TriMesh shrunk;
  for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t) {
    if (xs[t] > cut) continue;
    Vec3d c = Vec3d::Zero();
    for (int k = 0; k < 4; ++k) c += points[tets[4 * t + k]] / 4;
    const std::uint32_t base = std::uint32_t(shrunk.vertices.size());
    for (int k = 0; k < 4; ++k) shrunk.vertices.push_back((c + 0.6 * (points[tets[4 * t + k]] - c)).cast<float>());
    // positively oriented (a, b, c, d): the outward faces
    shrunk.triangles.push_back({base + 1, base + 2, base + 3});
    shrunk.triangles.push_back({base + 0, base + 3, base + 2});
    shrunk.triangles.push_back({base + 0, base + 1, base + 3});
    shrunk.triangles.push_back({base + 0, base + 2, base + 1});
  }
  picture(context, shrunk, "delaunay3_ball.png", Vec3f(0.75f, 0.55f, 0.8f));
  io::write_mesh(context.out_dir / "delaunay3_ball.ply", shrunk);
  result.figures.push_back({"delaunay3_ball.png",
                            fmt::format("Delaunay tetrahedralization of {} points in a ball (120 on its sphere): {} "
                                        "tetrahedra; the half behind a cut, each shrunk to 60 %",
                                        points.size(), dt.tetrahedron_count())});
  result.files.push_back({"delaunay3_ball.ply", "the shrunk tetrahedra behind the cut"});

  // Voronoi cells of 120 random sites in a box, exploded.
  rng = Rng(7);
  std::vector<Vec3d> sites;
  for (int i = 0; i < 120; ++i) sites.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  watch = Stopwatch();
  const voronoi::Voronoi3 vd(sites, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)));
  result.timing("Voronoi cells of 120 sites", watch.seconds());
  result.stat("Voronoi3", stats_text(vd.stats()));
  result.stat("Voronoi3 volume / box volume", fmt::format("{:.12f}", vd.volume_total()));
  const TriMesh cells = vd.mesh(0.6);
  picture(context, cells, "voronoi3_cells.png", Vec3f(0.8f, 0.55f, 0.9f));
  io::write_mesh(context.out_dir / "voronoi3_cells.ply", cells);
  result.figures.push_back({"voronoi3_cells.png",
                            fmt::format("Voronoi cells of 120 random sites in the unit cube, exploded (each moved away "
                                        "from the centre by 60 % of its centroid's offset); volumes sum to {:.12f}",
                                        vd.volume_total())});
  result.files.push_back({"voronoi3_cells.ply", "the exploded cells, closed polyhedra"});
  result.text =
      "Delaunay tetrahedralization (seed §5.3.1) by Bowyer-Watson insertion in BRIO order with exact predicates "
      "and a symbolic perturbation, and the Voronoi cells of points in space, each the box clipped by the bisectors "
      "of its Delaunay neighbours. Rendered with the ray module's ray tracer.";
}

const bool registered = register_demo_step(
    {"voronoi", "delaunay3", "3D Delaunay tetrahedralization and Voronoi cells (exploded)", &run_delaunay3});

}  // namespace
}  // namespace geods::cli
