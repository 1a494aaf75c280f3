// The renderer: the same picture with every accelerator and any thread count,
// the framing camera fits the mesh, shadows darken, bad options raise.
#include <gtest/gtest.h>

#include <cmath>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/ray/render.hpp"

namespace geods::ray {
namespace {

bool is_background(const Image<std::uint8_t>& image, std::size_t x, std::size_t y) {
  // The background is a bluish-grey gradient: blue above red; the surface is warm: red above blue.
  return image(x, y, 2) > image(x, y, 0);
}

TEST(Render, EveryAcceleratorAndThreadCountGivesTheSamePicture) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  RenderOptions options;
  options.width = 96;
  options.height = 64;
  options.shadows = true;
  options.accel = AcceleratorKind::grid;
  const RenderResult reference = render(mesh, options);
  ASSERT_EQ(reference.image.width, 96u);
  ASSERT_EQ(reference.image.height, 64u);
  ASSERT_EQ(reference.image.channels, 3u);
  EXPECT_GT(reference.hits, 96u * 64u / 10);
  EXPECT_GT(reference.rays, 96u * 64u);  // primary plus shadow rays
  EXPECT_GT(reference.mrays_per_s(), 0.0);
  for (AcceleratorKind kind : all_accelerator_kinds()) {
    options.accel = kind;
    const RenderResult result = render(mesh, options);
    EXPECT_EQ(result.image.data, reference.image.data) << to_string(kind);
    EXPECT_EQ(result.rays, reference.rays) << to_string(kind);
    EXPECT_EQ(result.accel_stats.kind, to_string(kind));
  }
  set_num_threads(1);
  options.accel = AcceleratorKind::rays5d;
  const RenderResult serial = render(mesh, options);
  set_num_threads(0);
  EXPECT_EQ(serial.image.data, reference.image.data);
}

TEST(Render, FramingShowsTheWholeMesh) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  RenderOptions options;
  options.width = options.height = 80;
  const RenderResult result = render(mesh, options);
  std::size_t surface = 0;
  for (std::size_t y = 0; y < 80; ++y)
    for (std::size_t x = 0; x < 80; ++x) {
      const bool border = x == 0 || y == 0 || x == 79 || y == 79;
      if (border) {
        EXPECT_TRUE(is_background(result.image, x, y)) << x << ", " << y;
      }
      surface += !is_background(result.image, x, y);
    }
  EXPECT_EQ(surface, result.hits);
  EXPECT_GT(surface, 80u * 80u / 8);
  // Every corner of the bounds projects inside the field of view.
  const Camera camera = Camera::framing(mesh.bounds());
  const Vec3f forward = (camera.target - camera.eye).normalized();
  const AABB3f box = mesh.bounds();
  for (int c = 0; c < 8; ++c) {
    const Vec3f corner(c & 1 ? box.hi[0] : box.lo[0], c & 2 ? box.hi[1] : box.lo[1], c & 4 ? box.hi[2] : box.lo[2]);
    const float angle = std::acos((corner - camera.eye).normalized().dot(forward)) * 180.0f / 3.14159265f;
    EXPECT_LT(angle, camera.vertical_fov_deg / 2);
  }
}

TEST(Render, PrimaryRaysSpanTheFieldOfView) {
  const Camera camera{Vec3f(1, 2, 3), Vec3f(1, 2, -1), Vec3f::UnitY(), 60};
  const Ray3f centre = camera.primary_ray(50, 25, 100, 50);
  EXPECT_EQ(centre.origin, camera.eye);
  EXPECT_NEAR((centre.direction - Vec3f(0, 0, -1)).norm(), 0.0f, 1e-6f);
  // The top edge's middle is half the vertical field of view above the axis; the
  // right edge's middle is further out by the aspect ratio (2) in tan units.
  const Ray3f top = camera.primary_ray(50, 0, 100, 50);
  EXPECT_NEAR(std::atan2(top.direction[1], -top.direction[2]), 30.0f * 3.14159265f / 180, 1e-5f);
  const Ray3f right = camera.primary_ray(100, 25, 100, 50);
  EXPECT_NEAR(right.direction[0] / -right.direction[2], 2 * std::tan(30.0f * 3.14159265f / 180), 1e-5f);
  EXPECT_NEAR(right.direction.norm(), 1.0f, 1e-6f);
}

TEST(Render, ShadowsDarkenAndUseTheOccluderCache) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  RenderOptions options;
  options.width = options.height = 160;  // neighbouring shadow rays often meet the same triangle
  const RenderResult lit = render(mesh, options);
  options.shadows = true;
  const RenderResult shadowed = render(mesh, options);
  EXPECT_EQ(lit.hits, shadowed.hits);
  long darker = 0, brighter = 0;
  for (std::size_t i = 0; i < lit.image.size(); ++i) {
    darker += shadowed.image.data[i] < lit.image.data[i];
    brighter += shadowed.image.data[i] > lit.image.data[i];
  }
  EXPECT_GT(darker, 0);
  EXPECT_EQ(brighter, 0);
  // The BVH's shadow packets do not use the occluder cache; ray by ray they do.
  options.packets = false;
  const RenderResult cached = render(mesh, options);
  EXPECT_EQ(cached.image.data, shadowed.image.data);
  EXPECT_GT(cached.occluder_hits, 0u);
  options.accel = AcceleratorKind::grid;
  options.packets = true;
  EXPECT_GT(render(mesh, options).occluder_hits, 0u);
}

TEST(Render, PacketsGiveTheSamePictureAsSingleRays) {
  // Sizes that are not multiples of the 4 x 4 pixel packets; 4 and 8 wide
  // BVHs (packet traversal) and the octree (ray by ray behind the interface).
  const TriMesh mesh = test::data_mesh("bunny.ply");
  RenderOptions options;
  options.width = 75;
  options.height = 41;
  options.shadows = true;
  for (int arity : {4, 8}) {
    options.accel = AcceleratorKind::bvh;
    options.accel_options.bvh.arity = arity;
    options.packets = false;
    const RenderResult single = render(mesh, options);
    options.packets = true;
    const RenderResult packets = render(mesh, options);
    EXPECT_EQ(packets.image.data, single.image.data) << "arity " << arity;
    EXPECT_EQ(packets.rays, single.rays);
    EXPECT_EQ(packets.hits, single.hits);
    EXPECT_GT(single.hits, 75u * 41u / 10);
    EXPECT_GT(single.rays, 75u * 41u);  // shadow rays were shot too
    options.accel = AcceleratorKind::octree;
    EXPECT_EQ(render(mesh, options).image.data, single.image.data);
  }
}

TEST(Render, BadOptionsRaise) {
  const TriMesh mesh = test::data_mesh("bunny.ply");
  RenderOptions options;
  options.width = 0;
  EXPECT_THROW(render(mesh, options), Error);
  options.width = 16;
  options.height = 16;
  options.camera = Camera{Vec3f::Zero(), Vec3f::Zero()};
  EXPECT_THROW(render(mesh, options), Error);
  options.camera = Camera{Vec3f(0, 5, 0), Vec3f::Zero(), Vec3f::UnitY()};
  EXPECT_THROW(render(mesh, options), Error);  // up parallel to the view direction
  options.camera = Camera{Vec3f(0, 0, 5), Vec3f::Zero(), Vec3f::UnitY(), 180};
  EXPECT_THROW(render(mesh, options), Error);
  // A camera inside the mesh's bounds looking out works.
  options.camera = Camera{mesh.bounds().center(), mesh.bounds().center() + Vec3f::UnitZ()};
  EXPECT_NO_THROW(render(mesh, options));
  TriMesh other = mesh;
  other.triangles.pop_back();
  const auto accel = make_accelerator(other, AcceleratorKind::grid);
  EXPECT_THROW(render(mesh, *accel, RenderOptions{}), Error);
}

}  // namespace
}  // namespace geods::ray
