// Demo step of the terrain module: the Jacksboro DEM seen from a low viewpoint
// with the view-dependent 4-8 mesh (its wireframe over the shaded rendering and
// from above, where the level of detail is plain), and triangles against error
// for the 4-8 mesh and the greedy TIN (seed §2.3, Figures 4 and 5).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "demo.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/svg.hpp"
#include "geods/ray/render.hpp"
#include "geods/terrain/stats_fields.hpp"
#include "geods/terrain/terrain.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

// Pixel coordinates and depth of p seen by `camera` in a w x h image (depth <= 0: behind).
struct Projection {
  Vec3d eye, f, r, u;
  double tv, th;
  int w, h;
  Projection(const ray::Camera& c, int width, int height) : w(width), h(height) {
    eye = c.eye.cast<double>();
    f = (c.target - c.eye).cast<double>().normalized();
    r = f.cross(c.up.cast<double>()).normalized();
    u = r.cross(f);
    tv = std::tan(double(c.vertical_fov_deg) * M_PI / 360);
    th = tv * w / h;
  }
  Vec3d operator()(const Vec3f& p) const {
    const Vec3d d = p.cast<double>() - eye;
    const double z = d.dot(f);
    return {w * 0.5 * (1 + d.dot(r) / (z * th)), h * 0.5 * (1 - d.dot(u) / (z * tv)), z};
  }
};

// The nearest depth per pixel of the mesh's triangles (in front of the eye).
std::vector<double> depth_buffer(const terrain::TerrainMesh& m, const Projection& P) {
  std::vector<double> z(std::size_t(P.w) * std::size_t(P.h), std::numeric_limits<double>::infinity());
  for (const auto& t : m.triangles) {
    const Vec3d a = P(m.vertices[t[0]]), b = P(m.vertices[t[1]]), c = P(m.vertices[t[2]]);
    if (a.z() <= 1e-6 || b.z() <= 1e-6 || c.z() <= 1e-6) continue;
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (std::abs(det) < 1e-12) continue;
    const int x0 = std::max(0, int(std::floor(std::min({a.x(), b.x(), c.x()})))),
              x1 = std::min(P.w - 1, int(std::ceil(std::max({a.x(), b.x(), c.x()})))),
              y0 = std::max(0, int(std::floor(std::min({a.y(), b.y(), c.y()})))),
              y1 = std::min(P.h - 1, int(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double l1 = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) / det;
        const double l2 = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / det;
        const double l3 = 1 - l1 - l2;
        if (l1 < 0 || l2 < 0 || l3 < 0) continue;
        // Depth is affine in 1/z on screen.
        const double inv = l1 / a.z() + l2 / b.z() + l3 / c.z();
        double& d = z[std::size_t(y) * std::size_t(P.w) + std::size_t(x)];
        d = std::min(d, 1 / inv);
      }
  }
  return z;
}

void draw_line(Image<std::uint8_t>& im, double x0, double y0, double x1, double y1, const std::uint8_t rgb[3],
               double alpha, const std::function<bool(double, int, int)>& visible = {}) {
  const int steps = std::max(1, int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))));
  for (int k = 0; k <= steps; ++k) {
    const double t = double(k) / steps;
    const int x = int(x0 + t * (x1 - x0)), y = int(y0 + t * (y1 - y0));
    if (x < 0 || y < 0 || x >= int(im.width) || y >= int(im.height)) continue;
    if (visible && !visible(t, x, y)) continue;
    for (int c = 0; c < 3; ++c) {
      std::uint8_t& v = im(std::size_t(x), std::size_t(y), std::size_t(c));
      v = std::uint8_t(std::lround((1 - alpha) * v + alpha * rgb[c]));
    }
  }
}

void run_terrain(const DemoContext& context, DemoResult& result) {
  terrain::HeightField field = terrain::read_height_field(context.data_dir / "jacksboro_dem.npy");
  field.spacing = {30, 30};  // the DEM's 30 m samples (z in metres)
  Stopwatch build_watch;
  const terrain::Terrain t(field, {.z_scale = 1.5});
  result.timing("build the 4-8 hierarchy (403 x 344 samples)", build_watch.seconds());

  // A low viewpoint at the south edge, looking north over the field towards the horizon.
  const int w = 960, h = 540;
  terrain::TerrainView view;
  view.camera.eye = Vec3f(5200, -900, 2300);
  view.camera.target = Vec3f(6500, 6000, 900);
  view.camera.up = Vec3f(0, 0, 1);
  view.camera.vertical_fov_deg = 45;
  view.width = w, view.height = h;
  terrain::Refinement by_view;
  by_view.view = view;
  by_view.pixel_error = 2;
  Stopwatch refine_watch;
  const terrain::TerrainMesh m = t.refine(by_view);
  result.timing("view-dependent refinement (tau = 2 px)", refine_watch.seconds());

  TriMesh mesh;
  mesh.vertices = m.vertices;
  mesh.triangles = m.triangles;
  ray::RenderOptions options;
  options.width = w, options.height = h;
  options.camera = view.camera;
  Image<std::uint8_t> picture = ray::render(mesh, options).image;
  const Projection P(view.camera, w, h);
  const std::vector<double> depth = depth_buffer(m, P);
  const std::uint8_t wire[3] = {20, 40, 110};
  for (const auto& tri : m.triangles)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t i = tri[std::size_t(e)], j = tri[std::size_t((e + 1) % 3)];
      if (i > j) continue;  // each edge once (interior edges are in two triangles)
      const Vec3d a = P(m.vertices[i]), b = P(m.vertices[j]);
      if (a.z() <= 1 || b.z() <= 1) continue;
      draw_line(picture, a.x(), a.y(), b.x(), b.y(), wire, 0.55, [&](double s, int x, int y) {
        const double z = 1 / ((1 - s) / a.z() + s / b.z());
        return z <= depth[std::size_t(y) * std::size_t(w) + std::size_t(x)] * 1.002 + 1;
      });
    }
  io::write_png(context.out_dir / "terrain_view.png", picture);
  result.figures.push_back(
      {"terrain_view.png",
       fmt::format("The Jacksboro DEM (heights × 1.5) from a low viewpoint: the view-dependent 4-8 mesh (τ = 2 pixels) "
                   "shaded, its edges drawn over it: fine near the eye, coarse towards the horizon; {} triangles, one "
                   "strip of {} vertices",
                   m.triangles.size(), m.strip.size())});

  // From above: the same mesh, with the eye and the view direction.
  const int zoom = 2;
  Image<std::uint8_t> top(t.width() * zoom, t.height() * zoom, 3, 255);
  const std::uint8_t grey[3] = {60, 60, 60}, red[3] = {200, 30, 30};
  for (const auto& tri : m.triangles)
    for (int e = 0; e < 3; ++e) {
      const auto a = m.samples[tri[std::size_t(e)]], b = m.samples[tri[std::size_t((e + 1) % 3)]];
      draw_line(top, a[0] * zoom, (t.height() - 1 - a[1]) * zoom, b[0] * zoom, (t.height() - 1 - b[1]) * zoom, grey, 0.8);
    }
  const double ex = view.camera.eye.x() / 30 * zoom, ey = (t.height() - 1 - view.camera.eye.y() / 30) * zoom;
  const double tx = view.camera.target.x() / 30 * zoom, ty = (t.height() - 1 - view.camera.target.y() / 30) * zoom;
  draw_line(top, ex, std::min(ey, double(top.height - 1)), tx, ty, red, 1.0);
  io::write_png(context.out_dir / "terrain_top.png", top);
  result.figures.push_back({"terrain_top.png",
                            "The same mesh from above (north up); the red line is the view direction from the eye at the "
                            "south edge: triangles shrink towards the eye, and what lies outside the view frustum stays "
                            "coarse."});

  // Triangles against error: the 4-8 mesh and the greedy TIN (Figure 4 against Figure 5).
  std::vector<Vec2d> grid_curve, tin_curve;
  for (const double e : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0}) {
    terrain::Refinement r;
    r.max_error = e;
    const terrain::TerrainMesh g = t.refine(r), tin = t.tin(e);
    result.stat(fmt::format("max error {} m: triangles 4-8 / TIN", e),
                fmt::format("{} / {} (measured {:.2f} / {:.2f})", g.triangles.size(), tin.triangles.size(),
                            t.measure_error(g), t.measure_error(tin)));
    grid_curve.emplace_back(std::log10(e), std::log10(double(g.triangles.size())));
    tin_curve.emplace_back(std::log10(e), std::log10(double(tin.triangles.size())));
  }
  AABB2d box;
  for (const auto& p : grid_curve) box.extend(p);
  for (const auto& p : tin_curve) box.extend(p);
  io::SvgWriter svg(box, 520, 40);
  svg.title("triangles against max vertical error (log-log)");
  io::SvgStyle blue, orange;
  blue.stroke = "#1f4e9c", blue.stroke_width = 2, blue.fill = "none";
  orange.stroke = "#d0701c", orange.stroke_width = 2, orange.fill = "none";
  svg.polyline(grid_curve, blue);
  svg.polyline(tin_curve, orange);
  svg.label(grid_curve.front(), "4-8 mesh", blue);
  svg.label(tin_curve.back(), "greedy TIN", orange);
  for (const auto& p : grid_curve) svg.label(Vec2d(p.x(), box.lo.y()), fmt::format("{:g} m", std::pow(10, p.x())));
  svg.save(context.out_dir / "terrain_error.svg");
  result.figures.push_back({"terrain_error.svg",
                            "Triangles against the maximum vertical error (log-log, 1 to 50 m), measured against every "
                            "sample: the 4-8 mesh (blue) and the greedy Delaunay TIN (orange), which needs fewer "
                            "triangles for the same error but no longer has the 4-8 mesh's regular structure."});
  result.stat("terrain", stats_text(t.stats()));
  result.text =
      "Terrain level of detail (seed §2.3): the 4-8 hierarchy of Lindstrom & Pascucci with nested errors and nested "
      "bounding spheres, so that refinement by a screen-space error with frustum culling is crack-free by "
      "construction; the vertex records in a matrix in memory, in the interleaved red/blue quadtree layout in "
      "files; one triangle strip per view.";
}

const bool registered = register_demo_step(
    {"terrain", "lod", "A DEM from a low viewpoint: view-dependent 4-8 mesh, and triangles against error", &run_terrain});

}  // namespace
}  // namespace geods::cli
