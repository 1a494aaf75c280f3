// Demo steps of the field module's applications: the discrete Voronoi diagram
// of projected distance functions (seed §6.1.2), a CSG carve with distance
// fields (§6.2.2) and a morph between two data/ meshes (§6.2.1).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "demo.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/modeling.hpp"
#include "geods/field/morph.hpp"
#include "geods/field/projection.hpp"
#include "geods/field/sdf_grid.hpp"
#include "geods/field/stats_fields.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/ray/render.hpp"
#include "stats_text.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

// A colour per site id (golden-ratio hues), darkened with distance and on iso-distance lines.
Image<std::uint8_t> voronoi_picture(const field::Projection& p, double step) {
  const std::size_t w = p.distance.dims[0], h = p.distance.dims[1];
  const double far = *std::max_element(p.distance.data.begin(), p.distance.data.end());
  Image<std::uint8_t> im(w, h, 3);
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) {
      const std::size_t i = p.distance.index(x, h - 1 - y, 0);  // y up
      const double hue = std::fmod(double(p.ids[i]) * 0.618033988749895, 1.0) * 6;
      double rgb[3];
      for (int c = 0; c < 3; ++c) {
        const double k = std::fmod(hue + 4 - 2 * c + 6, 6);  // a soft HSV wheel
        rgb[c] = 1 - 0.55 * std::clamp(std::min(k, 4 - k), 0.0, 1.0);
      }
      const double d = p.distance.data[i];
      double shade = 1 - 0.45 * d / std::max(far, 1e-12);
      const auto band = [&](std::size_t j) { return std::floor(p.distance.data[j] / step); };
      const bool line = (x + 1 < w && band(p.distance.index(x + 1, h - 1 - y, 0)) != band(i));
      const bool edge = (x + 1 < w && p.ids[p.distance.index(x + 1, h - 1 - y, 0)] != p.ids[i]) ||
                        (y + 1 < h && p.ids[p.distance.index(x, h - 2 - y, 0)] != p.ids[i]);
      if (line) shade *= 0.8;
      if (edge) shade = 0.15;
      if (d < 0.75) shade = 0.05;  // the sites themselves
      for (int c = 0; c < 3; ++c) im(x, y, std::size_t(c)) = std::uint8_t(std::clamp(255 * rgb[c] * shade, 0.0, 255.0));
    }
  return im;
}

void run_projection(const DemoContext& context, DemoResult& result) {
  // 60 points, 5 segments (roads) and two filled polygons (lakes) on a 640 x 420 image.
  Rng rng(16);
  field::ProjectionSites sites;
  for (int i = 0; i < 60; ++i) sites.points.emplace_back(rng.uniform(10, 630), rng.uniform(10, 410), 0);
  for (int i = 0; i < 5; ++i)
    sites.segments.push_back({Vec3d(rng.uniform(20, 620), rng.uniform(20, 400), 0),
                              Vec3d(rng.uniform(20, 620), rng.uniform(20, 400), 0)});
  sites.polygons.push_back({{420, 60}, {520, 80}, {560, 150}, {480, 130}, {430, 170}});
  sites.polygons.push_back({{80, 300}, {160, 280}, {190, 360}, {120, 390}});
  Grid3Geometry grid;
  grid.dims = {640, 420, 1};
  Stopwatch watch;
  const field::Projection p = field::project_distance(sites, grid);
  result.timing("projection of 67 distance functions onto 640 x 420 pixels", watch.seconds());
  io::write_png(context.out_dir / "field_projection_voronoi.png", voronoi_picture(p, 12));
  result.figures.push_back(
      {"field_projection_voronoi.png",
       "the id buffer as a discrete Voronoi diagram of 60 points (cones), 5 segments (tents) and 2 filled polygons "
       "(slabs), each region in its site's colour, darker farther from it, a line every 12 pixels of distance"});
  // A volume: hyperboloids slice by slice.
  field::ProjectionSites points3;
  for (int i = 0; i < 200; ++i) points3.points.emplace_back(rng.uniform(0, 63), rng.uniform(0, 63), rng.uniform(0, 63));
  Grid3Geometry cube;
  cube.dims = {64, 64, 64};
  Stopwatch watch3;
  const field::Projection p3 = field::project_distance(points3, cube);
  result.timing("projection of 200 points onto 64^3 samples (hyperboloids per slice)", watch3.seconds());
  result.stat("2D", stats_text(p.stats));
  result.stat("3D", stats_text(p3.stats));
  result.text =
      "Projection of distance functions (seed §6.1.2, Hoff et al.): every site's distance function — a cone for a "
      "point, a tent for a segment, a slab with tents and cones around it for a filled polygon, a hyperboloid on the "
      "slices of a volume — is rasterized into a depth buffer with the depth test \"less\", in software, parallel over "
      "rows; the depth buffer is then the distance field and the id buffer a discrete Voronoi diagram. Each fragment "
      "evaluates the distance function exactly at the pixel centre, so the field is exact there (no cone "
      "tessellation error); rows cull sites whose distance to the row exceeds the row's farthest depth.";
}

// Renders `mesh` into out_dir/name from a fixed camera.
void picture(const DemoContext& context, const TriMesh& mesh, const std::string& name, const ray::Camera& camera,
             int size = 384) {
  ray::RenderOptions options;
  options.width = options.height = size;
  options.camera = camera;
  io::write_png(context.out_dir / name, ray::render(mesh, options).image);
}

void run_csg(const DemoContext& context, DemoResult& result) {
  const TriMesh bunny = io::read_mesh(context.data_dir / "bunny.ply");
  const AABB3f box = bunny.bounds();
  const Grid3Geometry grid = field::sdf_grid_geometry(box, 128, 0, 4);
  Stopwatch sdf_watch;
  const Grid3<float> d = field::sdf_grid(bunny, grid).distance;
  result.timing("bunny's signed distance on 128 samples", sdf_watch.seconds());
  // Tools: a ball biting the back, a row of holes drilled through the body, a smooth ball on the head.
  const auto ball = [&](const Vec3f& c, float r) {
    Grid3<float> f;
    static_cast<Grid3Geometry&>(f) = grid;
    f.data.resize(d.size());
    for (std::size_t k = 0; k < grid.dims[2]; ++k)
      for (std::size_t j = 0; j < grid.dims[1]; ++j)
        for (std::size_t i = 0; i < grid.dims[0]; ++i) f(i, j, k) = (grid.position(i, j, k) - c).norm() - r;
    return f;
  };
  const auto drill = [&](float y, float r) {  // a cylinder along z
    Grid3<float> f;
    static_cast<Grid3Geometry&>(f) = grid;
    f.data.resize(d.size());
    for (std::size_t k = 0; k < grid.dims[2]; ++k)
      for (std::size_t j = 0; j < grid.dims[1]; ++j)
        for (std::size_t i = 0; i < grid.dims[0]; ++i) {
          const Vec3f p = grid.position(i, j, k);
          f(i, j, k) = std::hypot(p.x() - 0.5f, p.y() - y) - r;
        }
    return f;
  };
  const Vec3f size = box.hi - box.lo;
  Stopwatch csg_watch;
  Grid3<float> carved = field::csg(d, ball(box.lo + Vec3f(0.7f, 0.4f, 0.95f).cwiseProduct(size), 0.2f * size.y()),
                                   field::CsgOp::difference);
  carved = field::csg(carved, drill(box.lo.y() + 0.3f * size.y(), 0.07f * size.y()), field::CsgOp::difference);
  carved = field::blend(carved, ball(box.lo + Vec3f(0.3f, 0.82f, 0.55f).cwiseProduct(size), 0.1f * size.y()),
                        0.06 * size.y());
  const Grid3<float> shell = field::csg(carved, field::offset(carved, -0.04 * size.y()), field::CsgOp::difference);
  const double csg_s = csg_watch.seconds();
  Stopwatch iso_watch;
  const TriMesh carved_mesh = field::field_surface(carved);
  const TriMesh offset_mesh = field::field_surface(field::offset(d, 0.05 * size.y()));
  result.timing("CSG operations (4) and an offset on the grid", csg_s);
  result.timing("marching cubes of two fields", iso_watch.seconds());
  const ray::Camera camera = ray::Camera::framing(box, Vec3f(0.55f, 0.35f, 0.75f));
  picture(context, carved_mesh, "field_csg_carved.png", camera);
  picture(context, offset_mesh, "field_csg_offset.png", camera);
  io::write_mesh(context.out_dir / "field_csg_carved.ply", carved_mesh);
  result.figures.push_back({"field_csg_carved.png",
                            "the bunny minus a ball (max(D, -D_ball)), minus a drilled cylinder, smoothly united with a "
                            "ball on its head (blend radius 6 % of its height); the zero set by marching cubes"});
  result.figures.push_back({"field_csg_offset.png", "the bunny's offset surface D = 5 % of its height"});
  result.files.push_back({"field_csg_carved.ply", "the carved bunny (PLY)"});
  result.stat("carved: vertices / triangles / closed",
              fmt::format("{} / {} / {}", carved_mesh.num_vertices(), carved_mesh.num_triangles(),
                          carved_mesh.validate().closed_manifold() ? "yes" : "no"));
  result.stat("hollow shell (carved minus its inward offset): samples inside",
              fmt::format("{}", std::count_if(shell.data.begin(), shell.data.end(), [](float v) { return v < 0; })));
  result.text =
      "Volumetric modeling with distance fields (seed §6.2.2): Boolean operations are the operators of the seed's "
      "table applied sample by sample — min for a union, max for an intersection, max(D_O, −D_T) for a difference — "
      "blends are the smooth min with a blend radius, offsets subtract a constant; the surfaces come from marching "
      "cubes (iso module).";
}

void run_morph(const DemoContext& context, DemoResult& result) {
  const TriMesh bunny = io::read_mesh(context.data_dir / "bunny.ply");
  TriMesh teapot = io::read_mesh(context.data_dir / "teapot.obj");
  // The teapot scaled and moved onto the bunny's box (its height to the bunny's).
  const AABB3f b = bunny.bounds(), t = teapot.bounds();
  const float scale = (b.hi.y() - b.lo.y()) / (t.hi.y() - t.lo.y()) * 0.9f;
  for (Vec3f& v : teapot.vertices) v = (v - t.center()) * scale + b.center();
  teapot.normals.clear();
  field::MorphOptions options;
  options.res = 80;
  Stopwatch build_watch;
  const field::Morph plain = field::Morph::build(bunny, teapot, options);
  result.timing("morph: the two signed distance fields (80 samples)", build_watch.seconds());
  // Correspondences: the bunny's ears go to the spout and the handle, its tail to the lid's top.
  const auto corner = [](const AABB3f& box, float x, float y, float z) -> Vec3d {
    return (box.lo + Vec3f(x, y, z).cwiseProduct(box.hi - box.lo)).cast<double>();
  };
  const AABB3f tb = teapot.bounds();
  options.from = {corner(b, 0.3f, 1.0f, 0.5f), corner(b, 0.9f, 0.3f, 0.5f), corner(b, 0.05f, 0.2f, 0.5f),
                  corner(b, 0.5f, 0.0f, 0.5f)};
  options.to = {corner(tb, 0.5f, 1.0f, 0.5f), corner(tb, 1.0f, 0.6f, 0.5f), corner(tb, 0.0f, 0.5f, 0.5f),
                corner(tb, 0.5f, 0.0f, 0.5f)};
  Stopwatch warp_watch;
  const field::Morph warped = field::Morph::build(bunny, teapot, options);
  result.timing("warped morph: fields and warps", warp_watch.seconds());
  AABB3f all = b;
  all.extend(tb);
  const ray::Camera camera = ray::Camera::framing(all, Vec3f(0.35f, 0.3f, 0.9f));
  const int frames = 5, size = 256;
  for (const auto& [m, stem] : {std::pair{&plain, "field_morph"}, std::pair{&warped, "field_morph_warped"}}) {
    Image<std::uint8_t> strip(std::size_t(size * frames), std::size_t(size), 3);
    Stopwatch watch;
    std::vector<std::size_t> triangles;
    for (int k = 0; k < frames; ++k) {
      const TriMesh s = m->surface(double(k) / (frames - 1));
      triangles.push_back(s.num_triangles());
      ray::RenderOptions ro;
      ro.width = ro.height = size;
      ro.camera = camera;
      const Image<std::uint8_t> frame = ray::render(s, ro).image;
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
          for (int c = 0; c < 3; ++c)
            strip(std::size_t(k * size + x), std::size_t(y), std::size_t(c)) = frame(std::size_t(x), std::size_t(y), std::size_t(c));
      if (k == frames / 2) io::write_mesh(context.out_dir / (std::string(stem) + "_half.ply"), s);
    }
    result.timing(fmt::format("{}: {} surfaces (fields, marching cubes, rendering)", stem, frames), watch.seconds());
    io::write_png(context.out_dir / (std::string(stem) + ".png"), strip);
    result.stat(fmt::format("{}: triangles per step", stem), fmt::format("{}", fmt::join(triangles, ", ")));
    result.files.push_back({std::string(stem) + "_half.ply", "the surface halfway (PLY)"});
  }
  result.figures.push_back({"field_morph.png",
                            "bunny to teapot by interpolating the signed distance fields, (1 − t) D_bunny + t D_teapot "
                            "(equation 16), t = 0, ¼, ½, ¾, 1"});
  result.figures.push_back(
      {"field_morph_warped.png",
       fmt::format("the same with 4 correspondences (ears to spout and lid, tail to handle, feet to base): both shapes "
                   "warped towards the in-between pose by a least-squares rigid part (rotation {:.1f}°) and a "
                   "thin-plate radial basis function elastic part (equation 17), then interpolated",
                   warped.stats().rotation_angle * 180 / M_PI)});
  result.stat("warped morph", stats_text(warped.stats()));
  result.text =
      "Morphing with distance fields (seed §6.2.1, Cohen-Or et al.): the in-between shapes are the zero sets of "
      "interpolated signed distance fields, which change genus freely (the teapot's handle opens a hole the bunny "
      "does not have). With user correspondences the shapes are first warped so that the corresponding points meet.";
}

const bool registered_projection = register_demo_step(
    {"field", "projection", "Projected distance functions: a discrete Voronoi diagram (§6.1.2)", &run_projection});
const bool registered_csg =
    register_demo_step({"field", "csg", "CSG with distance fields: a carved bunny (§6.2.2)", &run_csg});
const bool registered_morph =
    register_demo_step({"field", "morph", "Morphing a bunny into a teapot (§6.2.1)", &run_morph});

}  // namespace
}  // namespace geods::cli
