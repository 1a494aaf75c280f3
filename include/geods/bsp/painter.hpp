#pragma once
// Rendering without a z-buffer (seed §3.1): the fragments of a BspTree rasterized in
// visibility order through a pinhole camera (the conventions of ray::Camera: pixel
// (x + 0.5, y + 0.5) is sampled, rows top to bottom). Back to front (the painter's
// algorithm) overwrites; front to back writes each pixel once, skipping pixels already
// covered (an occupancy mask of the screen, not the 2D screen BSP of §3.1). Fragments
// on the far side of every frustum corner's plane are skipped by the tree.
#include <cstdint>
#include <vector>

#include "geods/bsp/bsp_tree.hpp"

namespace geods::bsp {

struct PainterView {
  Vec3d eye{0, 0, 3}, target{0, 0, 0}, up{0, 1, 0};
  double vertical_fov_deg = 40;
  int width = 256, height = 256;
};

struct PainterResult {
  std::vector<std::uint32_t> triangle;  // per pixel (row-major from the top): input triangle, kNoIndex for none
  std::size_t pixel_writes = 0;         // writes to the image (front to back: one per covered pixel)
  std::size_t fragments = 0;            // fragments listed by the traversal
};

/// Throws geods::Error for a degenerate view (eye at target, up parallel to the view, size 0).
PainterResult paint(const BspTree& tree, const PainterView& view, bool back_to_front = true);

}  // namespace geods::bsp
