#include "geods/bsp/painter.hpp"

#include <gtest/gtest.h>

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
      EXPECT_LE(r.pixel_writes, std::size_t(view.width * view.height));  // each pixel at most once
    }
  }
  PainterView bad = view;
  bad.target = bad.eye;
  EXPECT_THROW(paint(tree, bad), Error);
}
