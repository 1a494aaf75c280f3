#pragma once
// Gaussian image pyramids (seed §5.5, Figure 53): level 0 is the image, each
// further level is the one before blurred by the 5-tap binomial filter
// [1 4 6 4 1] / 16 (edges clamped) and subsampled by 2, so level l has
// ceil(width / 2^l) x ceil(height / 2^l) pixels. Samples stay 8-bit (rounded),
// so that neighbourhood distances are exact integers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geods/core/image.hpp"

namespace geods::texture {

using Image8 = Image<std::uint8_t>;

/// The size of pyramid level `level` of a `size`-pixel side: ceil(size / 2^level).
inline std::size_t level_size(std::size_t size, std::size_t level) {
  return (size + (std::size_t(1) << level) - 1) >> level;
}

/// The next coarser level: blurred and subsampled (pixel (x, y) is the blurred
/// pixel (2x, 2y) of `image`).
Image8 downsample(const Image8& image);

/// `levels` levels, finest first (levels >= 1).
std::vector<Image8> gaussian_pyramid(const Image8& image, std::size_t levels);

/// The mask of the next coarser level for a mask pyramid (nonzero = unknown):
/// a coarse pixel is unknown when any fine pixel under its filter footprint
/// (the 5 x 5 window around (2x, 2y)) is, so that known coarse pixels never
/// mix in unknown ones.
Image8 downsample_mask(const Image8& mask);

}  // namespace geods::texture
