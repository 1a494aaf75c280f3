// Gaussian pyramids and mask pyramids against their definitions, written out directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "geods/core/rng.hpp"
#include "geods/texture/pyramid.hpp"

namespace geods::texture {
namespace {

Image8 random_image(std::size_t w, std::size_t h, std::size_t c, std::uint64_t seed) {
  Rng rng(seed);
  Image8 image(w, h, c);
  for (auto& v : image.data) v = std::uint8_t(rng.below(256));
  return image;
}

TEST(Pyramid, LevelSizesRoundUp) {
  EXPECT_EQ(level_size(64, 0), 64u);
  EXPECT_EQ(level_size(64, 2), 16u);
  EXPECT_EQ(level_size(65, 1), 33u);
  EXPECT_EQ(level_size(1, 3), 1u);
  const auto pyramid = gaussian_pyramid(random_image(37, 20, 3, 1), 4);
  ASSERT_EQ(pyramid.size(), 4u);
  for (std::size_t l = 0; l < 4; ++l) {
    EXPECT_EQ(pyramid[l].width, level_size(37, l));
    EXPECT_EQ(pyramid[l].height, level_size(20, l));
    EXPECT_EQ(pyramid[l].channels, 3u);
  }
  EXPECT_THROW(gaussian_pyramid(pyramid[0], 0), Error);
}

TEST(Pyramid, DownsampleIsTheBinomialFilterAtEvenPixels) {
  // Oracle: the 5x5 outer product of [1 4 6 4 1] in double, clamped edges, rounded half up.
  const double taps[5] = {1, 4, 6, 4, 1};
  for (const auto& [w, h] : {std::pair<std::size_t, std::size_t>{17, 9}, {8, 8}, {1, 5}, {2, 1}}) {
    const Image8 image = random_image(w, h, 2, w * 100 + h);
    const Image8 coarse = downsample(image);
    for (std::size_t y = 0; y < coarse.height; ++y)
      for (std::size_t x = 0; x < coarse.width; ++x)
        for (std::size_t k = 0; k < 2; ++k) {
          double sum = 0;
          for (int j = 0; j < 5; ++j)
            for (int i = 0; i < 5; ++i) {
              const auto sx = std::clamp<long>(long(2 * x) + i - 2, 0, long(w) - 1);
              const auto sy = std::clamp<long>(long(2 * y) + j - 2, 0, long(h) - 1);
              sum += taps[i] * taps[j] * image(std::size_t(sx), std::size_t(sy), k);
            }
          EXPECT_EQ(coarse(x, y, k), std::uint8_t(std::floor(sum / 256 + 0.5))) << w << "x" << h << " " << x << "," << y;
        }
  }
}

TEST(Pyramid, ConstantImagesStayConstant) {
  const Image8 image(30, 14, 1, 77);
  for (const Image8& level : gaussian_pyramid(image, 4))
    EXPECT_TRUE(std::all_of(level.data.begin(), level.data.end(), [](std::uint8_t v) { return v == 77; }));
}

TEST(Pyramid, MaskMarksEveryCoarsePixelWhoseFootprintTouchesTheHole) {
  Rng rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t w = 1 + rng.below(20), h = 1 + rng.below(20);
    Image8 mask(w, h, 1);
    for (auto& v : mask.data) v = rng.below(10) == 0 ? 255 : 0;
    const Image8 coarse = downsample_mask(mask);
    ASSERT_EQ(coarse.width, level_size(w, 1));
    for (std::size_t y = 0; y < coarse.height; ++y)
      for (std::size_t x = 0; x < coarse.width; ++x) {
        bool touched = false;
        for (long j = -2; j <= 2; ++j)
          for (long i = -2; i <= 2; ++i) {
            const auto sx = std::clamp<long>(long(2 * x) + i, 0, long(w) - 1);
            const auto sy = std::clamp<long>(long(2 * y) + j, 0, long(h) - 1);
            touched = touched || mask(std::size_t(sx), std::size_t(sy), 0);
          }
        EXPECT_EQ(coarse(x, y, 0) != 0, touched) << w << "x" << h << " at " << x << "," << y;
      }
  }
}

}  // namespace
}  // namespace geods::texture
