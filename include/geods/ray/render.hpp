#pragma once
// A small ray tracer over any accelerator: one primary ray per pixel, Lambert
// shading (two-sided) with one directional light above and to the left of the
// camera, optional hard shadows by any-hit rays that use the occluder cache.
// Parallel over 16 x 16 tiles, rays in packets of 4 x 4 pixels; the image
// does not depend on the thread count or on the packets.
#include <cstdint>
#include <optional>

#include "geods/core/image.hpp"
#include "geods/core/progress.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/ray/accelerator.hpp"
#include "geods/ray/camera.hpp"

namespace geods::ray {

struct RenderOptions {
  int width = 512, height = 512;
  std::optional<Camera> camera;  // default: Camera::framing(mesh bounds)
  bool shadows = false;
  /// Primary and shadow rays in packets of 4 x 4 pixels (Accelerator's packet
  /// queries; the BVH traverses them together). The image is the same either way.
  bool packets = true;
  AcceleratorKind accel = AcceleratorKind::bvh;
  AcceleratorOptions accel_options;
  ProgressCallback progress;
};

struct RenderResult {
  Image<std::uint8_t> image;  // RGB, rows top to bottom
  double build_s = 0, render_s = 0;
  std::uint64_t rays = 0;          // primary and shadow rays shot
  std::uint64_t hits = 0;          // primary rays that hit the mesh
  std::uint64_t occluder_hits = 0; // shadow rays answered by the occluder cache
  AcceleratorStats accel_stats;    // after rendering (5D classification subdivides while rendering)
  double mrays_per_s() const { return render_s > 0 ? double(rays) / render_s * 1e-6 : 0.0; }
};

/// Builds the accelerator of options.accel over the mesh and renders it.
RenderResult render(const TriMesh& mesh, const RenderOptions& options = {});
/// Renders with an accelerator already built (build_s is then 0). `mesh` must
/// be the mesh the accelerator was built over (its normals shade the image).
RenderResult render(const TriMesh& mesh, const Accelerator& accel, const RenderOptions& options = {});

}  // namespace geods::ray
