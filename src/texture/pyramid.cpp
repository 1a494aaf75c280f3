#include "geods/texture/pyramid.hpp"

#include <algorithm>

#include "geods/core/error.hpp"

namespace geods::texture {
namespace {

constexpr int kTaps[5] = {1, 4, 6, 4, 1};  // binomial, sums to 16

std::size_t clamp_index(std::ptrdiff_t i, std::size_t n) {
  return std::size_t(std::clamp<std::ptrdiff_t>(i, 0, std::ptrdiff_t(n) - 1));
}

}  // namespace

Image8 downsample(const Image8& image) {
  const std::size_t w = image.width, h = image.height, c = image.channels;
  const std::size_t cw = level_size(w, 1), ch = level_size(h, 1);
  // Horizontal pass at the kept columns only, then the vertical pass at the kept rows.
  std::vector<int> rows(h * cw * c);
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < cw; ++x)
      for (std::size_t k = 0; k < c; ++k) {
        int sum = 0;
        for (int t = 0; t < 5; ++t) sum += kTaps[t] * image(clamp_index(std::ptrdiff_t(2 * x) + t - 2, w), y, k);
        rows[(y * cw + x) * c + k] = sum;
      }
  Image8 out(cw, ch, c);
  for (std::size_t y = 0; y < ch; ++y)
    for (std::size_t x = 0; x < cw; ++x)
      for (std::size_t k = 0; k < c; ++k) {
        int sum = 0;
        for (int t = 0; t < 5; ++t) sum += kTaps[t] * rows[(clamp_index(std::ptrdiff_t(2 * y) + t - 2, h) * cw + x) * c + k];
        out(x, y, k) = std::uint8_t((sum + 128) / 256);
      }
  return out;
}

std::vector<Image8> gaussian_pyramid(const Image8& image, std::size_t levels) {
  if (levels == 0) throw Error("gaussian_pyramid: levels must be >= 1");
  std::vector<Image8> pyramid{image};
  while (pyramid.size() < levels) pyramid.push_back(downsample(pyramid.back()));
  return pyramid;
}

Image8 downsample_mask(const Image8& mask) {
  const std::size_t w = mask.width, h = mask.height;
  Image8 out(level_size(w, 1), level_size(h, 1), 1);
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) {
      if (!mask(x, y, 0)) continue;
      // Fine (x, y) lies under the footprint of coarse (cx, cy) when |x - 2 cx| <= 2 and |y - 2 cy| <= 2.
      for (std::size_t cy = (y >= 2 ? (y - 1) / 2 : 0); cy <= std::min((y + 2) / 2, out.height - 1); ++cy)
        for (std::size_t cx = (x >= 2 ? (x - 1) / 2 : 0); cx <= std::min((x + 2) / 2, out.width - 1); ++cx)
          out(cx, cy, 0) = 255;
    }
  return out;
}

}  // namespace geods::texture
