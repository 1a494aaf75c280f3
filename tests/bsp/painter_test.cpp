#include "geods/bsp/painter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "bsp/meshes.hpp"
#include "geods/core/error.hpp"
#include "geods/ray/accelerator.hpp"
#include "geods/ray/camera.hpp"

using namespace geods;
using namespace geods::bsp;
using namespace bsp_test;

// The painter's image (no z-buffer) equals the ray-traced one (the ray module's BVH
// accelerator) up to pixels on silhouette and triangle edges.
TEST(Painter, MatchesRayTracedImage) {
  Triangles scene = torus(1.0, 0.4, 24, 12);
  const Triangles b = transformed(sphere(0.5, 8, 12), 0.0, {0.3, 0.2, 0.6});
  const auto base = std::uint32_t(scene.vertices.size());
  scene.vertices.insert(scene.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) scene.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  const BspTree tree(scene.vertices, scene.triangles);

  PainterView view;
  view.eye = {2.2, 1.8, 3.0};
  view.width = view.height = 160;
  ray::Camera cam;
  cam.eye = view.eye.cast<float>();
  cam.target = view.target.cast<float>();
  cam.up = view.up.cast<float>();
  cam.vertical_fov_deg = float(view.vertical_fov_deg);
  const auto accel = ray::make_accelerator(to_tri_mesh(scene), ray::AcceleratorKind::bvh);
  std::vector<std::uint32_t> traced(std::size_t(view.width * view.height));
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x)
      traced[std::size_t(y * view.width + x)] = accel->intersect(cam.primary_ray(x + 0.5f, y + 0.5f, view.width, view.height)).prim;

  for (bool b2f : {true, false}) {
    const PainterResult r = paint(tree, view, b2f);
    std::size_t mismatches = 0, covered = 0, interior_mismatches = 0;
    for (int y = 1; y + 1 < view.height; ++y)
      for (int x = 1; x + 1 < view.width; ++x) {
        const std::size_t i = std::size_t(y * view.width + x);
        covered += traced[i] != kNoIndex;
        if (r.triangle[i] == traced[i]) continue;
        ++mismatches;
        // An edge pixel: some 8-neighbour sees another triangle (or nothing) in the traced image.
        bool edge = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) edge |= traced[std::size_t((y + dy) * view.width + x + dx)] != traced[i];
        interior_mismatches += !edge;
      }
    EXPECT_GT(covered, 3000u);
    EXPECT_EQ(interior_mismatches, 0u) << (b2f ? "back to front" : "front to back");
    EXPECT_LT(mismatches, covered / 20);
    if (!b2f) {
      // Each pixel written once: as many writes as pixels showing a triangle.
      const auto shown = std::size_t(std::count_if(r.triangle.begin(), r.triangle.end(), [](auto t) { return t != kNoIndex; }));
      EXPECT_EQ(r.pixel_writes, shown);
      EXPECT_GT(r.screen_nodes, 1u);
    }
  }
  PainterView bad = view;
  bad.target = bad.eye;
  EXPECT_THROW(paint(tree, bad), Error);
}

namespace {

using P2 = ScreenBsp::Point;

// Oracle: a point inside a convex polygon by its edges' signs (written out here).
bool contains(const std::vector<P2>& p, double x, double y) {
  double area = 0;
  for (std::size_t k = 0; k < p.size(); ++k) area += p[k][0] * p[(k + 1) % p.size()][1] - p[k][1] * p[(k + 1) % p.size()][0];
  if (area == 0) return false;
  const double s = area > 0 ? 1 : -1;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const P2& a = p[k];
    const P2& b = p[(k + 1) % p.size()];
    if (!(s * ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) >= 0)) return false;
  }
  return true;
}

}  // namespace

// The screen BSP's occupied region is the union of the inserted polygons (checked at every
// pixel centre and at random points against brute force), its area matches a sampled
// estimate of the union's, and no pixel is reported twice: random triangles, rectangles on
// pixel centres (edges through sample points), shared edges, polygons off the screen, and
// degenerate ones.
TEST(ScreenBsp, OccupiedIsUnionAndPixelsOnce) {
  const int W = 64, H = 48;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> ux(-10, W + 10), uy(-10, H + 10);
  std::vector<std::vector<P2>> polys;
  for (int i = 0; i < 40; ++i) polys.push_back({{ux(rng), uy(rng)}, {ux(rng), uy(rng)}, {ux(rng), uy(rng)}});
  for (int i = 0; i < 10; ++i) {  // rectangles with edges through pixel centres, split along a diagonal
    const double x0 = std::floor(ux(rng)) + 0.5, y0 = std::floor(uy(rng)) + 0.5;
    const double x1 = x0 + 1 + double(rng() % 12), y1 = y0 + 1 + double(rng() % 12);
    polys.push_back({{x0, y0}, {x1, y0}, {x1, y1}});
    polys.push_back({{x0, y0}, {x1, y1}, {x0, y1}});
  }
  polys.push_back({{1, 1}, {5, 5}, {9, 9}});           // zero area
  polys.push_back({{-50, -50}, {-40, -50}, {-40, -40}});  // off the screen
  polys.push_back({{10.5, 10.5}, {10.5, 10.5}, {20.5, 10.5}, {20.5, 30.5}});  // a repeated vertex
  std::shuffle(polys.begin(), polys.end(), rng);

  ScreenBsp screen(W, H);
  std::vector<int> writes(std::size_t(W * H), 0);
  std::vector<std::uint32_t> pixels;
  std::size_t total = 0;
  for (const auto& p : polys) {
    pixels.clear();
    const std::size_t n = screen.insert(p, pixels);
    EXPECT_EQ(n, pixels.size());
    for (auto pix : pixels) ++writes[pix];
    total += pixels.size();
  }
  std::size_t covered = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool any = false;
      for (const auto& p : polys) any |= contains(p, x + 0.5, y + 0.5);
      covered += any;
      EXPECT_EQ(writes[std::size_t(y * W + x)], int(any)) << x << " " << y;
      EXPECT_EQ(screen.occupied(x + 0.5, y + 0.5), any) << x << " " << y;
    }
  EXPECT_EQ(total, covered);
  EXPECT_GT(covered, std::size_t(W * H / 4));
  EXPECT_LT(covered, std::size_t(W * H));
  // Random points (not on any line): occupied exactly where some polygon is; the area.
  std::uniform_real_distribution<double> px(0, W), py(0, H);
  int inside = 0;
  const int samples = 40000;
  for (int i = 0; i < samples; ++i) {
    const double x = px(rng), y = py(rng);
    bool any = false;
    for (const auto& p : polys) any |= contains(p, x, y);
    inside += any;
    ASSERT_EQ(screen.occupied(x, y), any) << x << " " << y;
  }
  const double estimate = double(inside) / samples * W * H;
  const double sigma = std::sqrt(double(inside) * (1 - double(inside) / samples)) / samples * W * H;
  EXPECT_NEAR(screen.occupied_area(), estimate, 4 * sigma + 1e-9);
  EXPECT_GT(screen.depth(), 2u);

  // A polygon far larger than the screen covers it; then nothing is left to write.
  ScreenBsp big(8, 6);
  const std::vector<P2> huge{{-1e100, -1e100}, {1e100, -1e100}, {0, 1e100}};
  pixels.clear();
  EXPECT_EQ(big.insert(huge, pixels), 48u);
  EXPECT_EQ(big.insert(huge, pixels), 0u);
  EXPECT_NEAR(big.occupied_area(), 48.0, 1e-9);

  std::vector<P2> bad{{0, 0}, {std::nan(""), 1}, {1, 1}};
  EXPECT_THROW(screen.insert(bad, pixels), Error);
  EXPECT_THROW(ScreenBsp(0, 5), Error);
}
