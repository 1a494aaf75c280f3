// Texture synthesis against brute force, determinism across thread counts,
// periodic samples, tiling, hole filling and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/texture/neighborhood.hpp"
#include "geods/texture/synthesis.hpp"

namespace geods::texture {
namespace {

// Blobs of random colours on a noisy background: a texture with structure at several scales.
Image8 blobs(std::size_t w, std::size_t h, std::size_t c, std::uint64_t seed) {
  Rng rng(seed);
  Image8 image(w, h, c);
  for (auto& v : image.data) v = std::uint8_t(rng.below(40));
  for (int b = 0; b < int(w * h / 40); ++b) {
    const double cx = rng.uniform(0, double(w)), cy = rng.uniform(0, double(h)), r = rng.uniform(1, 3.5);
    std::uint8_t colour[4];
    for (auto& v : colour) v = std::uint8_t(120 + rng.below(136));
    for (std::size_t y = 0; y < h; ++y)
      for (std::size_t x = 0; x < w; ++x)
        if (std::hypot(double(x) - cx, double(y) - cy) <= r)
          for (std::size_t k = 0; k < c; ++k) image(x, y, k) = colour[k];
  }
  return image;
}

// Vertical stripes of `period` columns, or a checkerboard of period x period squares.
Image8 periodic(std::size_t w, std::size_t h, std::size_t period, bool checker) {
  Image8 image(w, h, 1);
  for (std::size_t y = 0; y < h; ++y)
    for (std::size_t x = 0; x < w; ++x) {
      const bool on = (x % period) < period / 2;
      const bool on_y = (y % period) < period / 2;
      image(x, y) = (checker ? on != on_y : on) ? 230 : 20;
    }
  return image;
}

TextureRequest request(std::size_t w, std::size_t h, NeighborSearch search, std::size_t n = 5, std::size_t levels = 2) {
  TextureRequest r;
  r.width = w;
  r.height = h;
  r.options.neighborhood = n;
  r.options.levels = levels;
  r.options.search = search;
  return r;
}

struct ThreadLimit {
  explicit ThreadLimit(int n) { set_num_threads(n); }
  ~ThreadLimit() { set_num_threads(0); }
};

TEST(Synthesis, ExactSearchGivesTheBruteForceImage) {
  for (const std::size_t c : {1u, 3u, 4u}) {
    const Image8 sample = blobs(28, 24, c, c);
    for (const bool tile : {false, true}) {
      TextureRequest r = request(40, 33, NeighborSearch::brute);
      r.tile = tile;
      r.options.refinement_passes = 1;
      const auto brute = synthesize_texture(sample, r);
      r.options.search = NeighborSearch::exact;
      const auto exact = synthesize_texture(sample, r);
      EXPECT_EQ(brute.image.data, exact.image.data) << c << " channels, tile " << tile;
      EXPECT_DOUBLE_EQ(brute.stats.mean_neighborhood_distance, exact.stats.mean_neighborhood_distance);
      EXPECT_LT(exact.stats.full_distances, brute.stats.full_distances);
      EXPECT_EQ(exact.image.width, 40u);
      EXPECT_EQ(exact.image.height, 33u);
      EXPECT_EQ(exact.image.channels, c);
    }
  }
}

TEST(Synthesis, EveryOutputPixelIsASamplePixel) {
  const Image8 sample = blobs(32, 32, 3, 9);
  std::set<std::array<std::uint8_t, 3>> colours;
  for (std::size_t i = 0; i < sample.data.size(); i += 3)
    colours.insert({sample.data[i], sample.data[i + 1], sample.data[i + 2]});
  const auto out = synthesize_texture(sample, request(50, 45, NeighborSearch::approx));
  for (std::size_t i = 0; i < out.image.data.size(); i += 3)
    ASSERT_TRUE(colours.count({out.image.data[i], out.image.data[i + 1], out.image.data[i + 2]})) << i / 3;
  EXPECT_EQ(out.stats.levels, 2u);
  EXPECT_EQ(out.stats.pixels, 50u * 45u + 25u * 23u);
  EXPECT_EQ(out.stats.dimension, (12u + 9u) * 3u);  // causal 5x5 and the parent's 3x3
  EXPECT_GT(out.stats.mean_neighborhood_distance, 0);
}

TEST(Synthesis, TheSameSeedGivesTheSameBytesOnAnyThreadCount) {
  const Image8 sample = blobs(40, 40, 3, 21);
  TextureRequest r = request(96, 80, NeighborSearch::approx, 7, 2);
  for (const bool tile : {false, true}) {
    r.tile = tile;
    r.options.refinement_passes = tile ? 1 : 0;
    Image8 one;
    {
      ThreadLimit limit(1);
      one = synthesize_texture(sample, r).image;
    }
    const Image8 all = synthesize_texture(sample, r).image;
    EXPECT_EQ(one.data, all.data) << "tile " << tile;
    r.options.seed = 1;
    EXPECT_NE(synthesize_texture(sample, r).image.data, all.data) << "another seed, another texture";
    r.options.seed = 0;
  }
}

// The smallest shift s >= 1 with image(x + s, y) == image(x, y) for the pixels at rows >= y0.
std::size_t horizontal_period(const Image8& image, std::size_t y0) {
  for (std::size_t s = 1; s < image.width; ++s) {
    bool ok = true;
    for (std::size_t y = y0; y < image.height && ok; ++y)
      for (std::size_t x = 0; x + s < image.width && ok; ++x) ok = image(x, y) == image(x + s, y);
    if (ok) return s;
  }
  return 0;
}

TEST(Synthesis, PeriodicSamplesKeepTheirPeriod) {
  // Past the first rows (which start from the random border), the output repeats with the sample's period.
  for (const std::size_t period : {6u, 8u}) {
    const auto stripes = synthesize_texture(periodic(48, 48, period, false), request(80, 64, NeighborSearch::exact, 7));
    EXPECT_EQ(horizontal_period(stripes.image, 16), period) << "stripes";
    const auto checker = synthesize_texture(periodic(48, 48, period, true), request(80, 64, NeighborSearch::exact, 7));
    EXPECT_EQ(horizontal_period(checker.image, 16), period) << "checkerboard";
    // Columns repeat too (transposed check).
    Image8 t(checker.image.height, checker.image.width, 1);
    for (std::size_t y = 0; y < t.height; ++y)
      for (std::size_t x = 0; x < t.width; ++x) t(x, y) = checker.image(y, x);
    EXPECT_EQ(horizontal_period(t, 16), period) << "checkerboard rows";
  }
}

// Mean, over pixels, of the distance of each pixel's whole 5x5 window (read
// toroidally) to the nearest window of the sample; separately for the pixels
// whose window crosses the image's edge and for the others.
std::pair<double, double> seam_and_inside_distance(const Image8& image, const Image8& sample) {
  const NeighborhoodShape shape = NeighborhoodShape::make(5, 0, false);
  std::vector<std::uint8_t> candidates;
  for (std::size_t y = 2; y + 2 < sample.height; ++y)
    for (std::size_t x = 2; x + 2 < sample.width; ++x)
      for (const Offset o : shape.fine)
        for (std::size_t k = 0; k < sample.channels; ++k) candidates.push_back(sample(x + o.dx, y + o.dy, k));
  const NeighborhoodIndex index(candidates, shape.dimension(sample.channels), 0);
  NeighborhoodIndex::Scratch scratch;
  double seam = 0, inside = 0;
  std::size_t seam_n = 0, inside_n = 0;
  std::vector<std::uint8_t> q;
  const auto w = long(image.width), h = long(image.height);
  for (long y = 0; y < h; ++y)
    for (long x = 0; x < w; ++x) {
      q.clear();
      for (const Offset o : shape.fine)
        for (std::size_t k = 0; k < image.channels; ++k)
          q.push_back(image(std::size_t((x + o.dx + w) % w), std::size_t((y + o.dy + h) % h), k));
      const double d = std::sqrt(double(index.nearest(q.data(), NeighborSearch::brute, 0, scratch).squared_distance));
      const bool crosses = x < 2 || y < 2 || x >= w - 2 || y >= h - 2;
      (crosses ? seam : inside) += d;
      ++(crosses ? seam_n : inside_n);
    }
  return {seam / double(seam_n), inside / double(inside_n)};
}

TEST(Synthesis, ToroidalOutputTilesWithoutSeams) {
  const Image8 sample = blobs(40, 40, 1, 33);
  TextureRequest r = request(64, 64, NeighborSearch::exact, 7, 2);
  r.tile = true;
  r.options.refinement_passes = 1;
  const auto tiled = synthesize_texture(sample, r);
  const auto [seam, inside] = seam_and_inside_distance(tiled.image, sample);
  EXPECT_LE(seam, inside * 1.1) << "across the wrap " << seam << ", inside " << inside;
  // Without tile the wrap is a real seam: the check above can tell.
  r.tile = false;
  const auto plain = synthesize_texture(sample, r);
  const auto [plain_seam, plain_inside] = seam_and_inside_distance(plain.image, sample);
  EXPECT_GT(plain_seam, plain_inside * 1.3) << "across the edge " << plain_seam << ", inside " << plain_inside;
}

TEST(FillHole, LeavesThePixelsOutsideTheMaskAndRestoresAPeriodicPattern) {
  const Image8 image = periodic(64, 48, 8, true);
  Image8 holed = image, mask(64, 48, 1);
  for (std::size_t y = 18; y < 30; ++y)
    for (std::size_t x = 25; x < 41; ++x) {
      mask(x, y) = 255;
      holed(x, y) = 128;  // not a pattern value
    }
  SynthesisOptions o;
  o.neighborhood = 7;
  o.search = NeighborSearch::exact;
  const auto filled = fill_hole(holed, mask, o);
  for (std::size_t i = 0; i < image.data.size(); ++i) {
    if (!mask.data[i]) {
      ASSERT_EQ(filled.image.data[i], holed.data[i]) << "outside the mask, pixel " << i;
    }
  }
  EXPECT_EQ(filled.image.data, image.data) << "the hole of a checkerboard is a checkerboard";
  EXPECT_EQ(filled.stats.pixels > 0, true);
  EXPECT_LT(filled.stats.mean_neighborhood_distance, 1e-9);
}

TEST(FillHole, WithASeparateSampleAndRefinement) {
  const Image8 sample = blobs(40, 40, 3, 3);
  Image8 image = blobs(60, 50, 3, 4), mask(60, 50, 1);
  for (std::size_t y = 10; y < 30; ++y)
    for (std::size_t x = 20; x < 45; ++x) mask(x, y) = 1;
  SynthesisOptions o;
  o.neighborhood = 5;
  o.refinement_passes = 1;
  Image8 one;
  {
    ThreadLimit limit(1);
    one = fill_hole(image, mask, o, &sample).image;
  }
  const auto all = fill_hole(image, mask, o, &sample);
  EXPECT_EQ(one.data, all.image.data);
  std::size_t changed = 0;
  for (std::size_t y = 0; y < 50; ++y)
    for (std::size_t x = 0; x < 60; ++x)
      for (std::size_t k = 0; k < 3; ++k) {
        if (!mask(x, y)) {
          ASSERT_EQ(all.image(x, y, k), image(x, y, k));
        } else {
          changed += all.image(x, y, k) != image(x, y, k);
        }
      }
  EXPECT_GT(changed, 100u);
}

TEST(Synthesis, BadInputIsAClearError) {
  const Image8 sample = blobs(32, 32, 3, 1);
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { synthesize_texture(sample, request(0, 10, NeighborSearch::approx)); }).find("at least 1x1"),
            std::string::npos);
  EXPECT_NE(message([&] { synthesize_texture(sample, request(1 << 16, 1 << 15, NeighborSearch::approx)); }).find("2^30"),
            std::string::npos);
  EXPECT_NE(message([&] { synthesize_texture(Image8(1, 1, 3), request(8, 8, NeighborSearch::approx)); }).find("too small"),
            std::string::npos);
  EXPECT_NE(message([&] { synthesize_texture(blobs(8, 8, 1, 2), request(16, 16, NeighborSearch::approx, 9, 1)); })
                .find("too small"),
            std::string::npos);
  EXPECT_NE(message([&] { synthesize_texture(sample, request(16, 16, NeighborSearch::approx, 4)); }).find("odd"),
            std::string::npos);
  EXPECT_NE(message([&] { synthesize_texture(Image8(8, 8, 5), request(16, 16, NeighborSearch::approx)); })
                .find("1 to 4 channels"),
            std::string::npos);
  EXPECT_NE(message([&] { synthesize_texture(Image8(), request(16, 16, NeighborSearch::approx)); }).find("empty"),
            std::string::npos);
  TextureRequest r = request(16, 16, NeighborSearch::approx);
  r.options.eps = -1;
  EXPECT_NE(message([&] { synthesize_texture(sample, r); }).find("eps"), std::string::npos);
  r.options.eps = 1;
  r.options.levels = 9;
  EXPECT_NE(message([&] { synthesize_texture(sample, r); }).find("levels"), std::string::npos);
  SynthesisOptions o;
  EXPECT_NE(message([&] { fill_hole(sample, Image8(31, 32, 1), o); }).find("differ in size"), std::string::npos);
  const Image8 grey = blobs(32, 32, 1, 5);
  EXPECT_NE(message([&] { fill_hole(sample, Image8(32, 32, 1), o, &grey); }).find("channels"), std::string::npos);
  // A hole that leaves no whole window of known pixels.
  EXPECT_NE(message([&] { fill_hole(sample, Image8(32, 32, 1, 255), o); }).find("away from the hole"),
            std::string::npos);
}

TEST(Synthesis, AutomaticLevelsFollowTheSampleSize) {
  TextureRequest r = request(32, 32, NeighborSearch::approx, 9, 0);
  EXPECT_EQ(synthesize_texture(blobs(40, 40, 1, 1), r).stats.levels, 2u);   // 40, 20 >= 18
  EXPECT_EQ(synthesize_texture(blobs(80, 80, 1, 1), r).stats.levels, 3u);   // 80, 40, 20
  EXPECT_EQ(synthesize_texture(blobs(300, 300, 1, 1), r).stats.levels, 4u);  // at most 4
}

}  // namespace
}  // namespace geods::texture
