// Demo steps of the texture module: each texture of data/ (reduced to a
// 128 x 128 sample) next to a synthesis at twice its size, a tileable texture
// shown tiled, and a hole filled from its surroundings.
#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "demo.hpp"
#include "geods/io/image_io.hpp"
#include "geods/texture/pyramid.hpp"
#include "geods/texture/synthesis.hpp"

namespace geods::cli {
namespace {

using texture::Image8;

constexpr std::size_t kSampleLevel = 2;  // 512 x 512 data textures -> 128 x 128 samples

/// `images` left to right on a white strip, `gap` pixels apart, tops aligned.
Image8 side_by_side(const std::vector<const Image8*>& images, std::size_t gap = 8) {
  std::size_t width = 0, height = 0;
  for (const Image8* im : images) width += im->width + (width ? gap : 0), height = std::max(height, im->height);
  const std::size_t channels = images.front()->channels;
  Image8 out(width, height, channels, 255);
  std::size_t x0 = 0;
  for (const Image8* im : images) {
    for (std::size_t y = 0; y < im->height; ++y)
      std::copy_n(&(*im)(0, y), im->width * channels, &out(x0, y));
    x0 += im->width + gap;
  }
  return out;
}

/// The image repeated nx by ny times.
Image8 tiled(const Image8& im, std::size_t nx, std::size_t ny) {
  Image8 out(im.width * nx, im.height * ny, im.channels);
  for (std::size_t y = 0; y < out.height; ++y)
    for (std::size_t x = 0; x < out.width; ++x)
      for (std::size_t c = 0; c < im.channels; ++c) out(x, y, c) = im(x % im.width, y % im.height, c);
  return out;
}

Image8 sample_of(const DemoContext& context, const std::string& name) {
  const Image8 full = io::read_image(context.data_dir / (name + ".png"));
  return texture::gaussian_pyramid(full, kSampleLevel + 1)[kSampleLevel];
}

void run_synthesis(const DemoContext& context, DemoResult& result) {
  for (const std::string name : {"brick", "grass", "gravel"}) {
    const Image8 sample = sample_of(context, name);
    texture::TextureRequest request;
    request.width = 2 * sample.width;
    request.height = 2 * sample.height;
    request.options.seed = 1;
    request.options.progress = context.progress;
    const texture::SynthesisResult r = texture::synthesize_texture(sample, request);
    const std::string file = "texture_" + name + ".png";
    io::write_png(context.out_dir / file, side_by_side({&sample, &r.image}));
    const auto& s = r.stats;
    result.figures.push_back(
        {file, fmt::format("{}: the {}x{} sample (left) and a {}x{} synthesis, {} search, {:.2f} s; mean "
                           "neighborhood distance {:.2f} per value",
                           name, sample.width, sample.height, s.width, s.height,
                           texture::neighbor_search_name(request.options.search), s.compute_s,
                           s.mean_neighborhood_distance)});
    result.timing(name + " " + std::to_string(s.width) + "x" + std::to_string(s.height), s.compute_s);
  }
  result.text =
      "Wei-Levoy texture synthesis (seed §5.5): each output pixel, in scan-line order from a random border, takes "
      "the value of the sample pixel whose neighbourhood is nearest to its own: the causal 9 x 9 window at its "
      "level of a Gaussian pyramid and a 5 x 5 window one level coarser. The nearest-neighbour search is the "
      "project's k-d tree over 8 principal components of the neighbourhoods and the norm of the rest, with the "
      "(1 + eps) approximate search (eps = 24, pruning harder as a query's work grows), full distances at the leaves, and a start from the coherent "
      "candidate (the patch the neighbours copy, continued). Samples: the 512 x 512 textures of data/ reduced to "
      "128 x 128 by the pyramid.";
}

void run_tile_and_hole(const DemoContext& context, DemoResult& result) {
  // A tileable texture: a toroidal output, shown 2 x 2.
  const Image8 gravel = sample_of(context, "gravel");
  texture::TextureRequest request;
  request.width = request.height = 128;
  request.tile = true;
  request.options.seed = 2;
  request.options.refinement_passes = 1;  // removes the seam the causal pass leaves across the wrap
  const texture::SynthesisResult tile = texture::synthesize_texture(gravel, request);
  io::write_png(context.out_dir / "texture_tile.png", tiled(tile.image, 2, 2));
  result.figures.push_back({"texture_tile.png",
                            fmt::format("a 128x128 toroidal synthesis from gravel (tile mode, one refinement pass), "
                                        "repeated 2 x 2: no seams; {:.2f} s",
                                        tile.stats.compute_s)});
  result.timing("tileable 128x128", tile.stats.compute_s);

  // A hole: a disc cut out of a brick photograph, filled from the rest of it.
  const Image8 brick = texture::gaussian_pyramid(io::read_image(context.data_dir / "brick.png"), 2)[1];
  Image8 mask(brick.width, brick.height, 1, 0), damaged = brick;
  const double cx = 0.5 * double(brick.width), cy = 0.5 * double(brick.height), r = 0.18 * double(brick.width);
  std::size_t hole = 0;
  for (std::size_t y = 0; y < brick.height; ++y)
    for (std::size_t x = 0; x < brick.width; ++x)
      if ((double(x) - cx) * (double(x) - cx) + (double(y) - cy) * (double(y) - cy) < r * r)
        mask(x, y) = 255, damaged(x, y) = 0, ++hole;
  texture::SynthesisOptions options;
  options.seed = 3;
  const texture::SynthesisResult filled = texture::fill_hole(damaged, mask, options);
  io::write_png(context.out_dir / "texture_hole.png", side_by_side({&damaged, &filled.image}));
  result.figures.push_back({"texture_hole.png",
                            fmt::format("hole filling: a disc of {} pixels cut out of brick ({}x{}, left), filled "
                                        "from the rest of the image (right); the pixels outside are kept; {:.2f} s",
                                        hole, brick.width, brick.height, filled.stats.compute_s)});
  result.timing("hole filling", filled.stats.compute_s);
  result.stat("hole: mean neighborhood distance", fmt::format("{:.2f}", filled.stats.mean_neighborhood_distance));
  result.stat("tile: mean neighborhood distance", fmt::format("{:.2f}", tile.stats.mean_neighborhood_distance));
  result.text =
      "Tile mode wraps every window around the output, so that the texture repeats without seams. Hole filling "
      "(constrained synthesis) synthesizes only the masked pixels, in scan-line order, from the image's own windows "
      "that do not touch the hole; the pixels it has not reached yet start as noise.";
}

const bool registered_synthesis = register_demo_step(
    {"texture", "synthesis", "Texture synthesis by neighbourhood search (Wei-Levoy)", &run_synthesis});
const bool registered_tile =
    register_demo_step({"texture", "tile_and_hole", "Tileable textures and hole filling", &run_tile_and_hole});

}  // namespace
}  // namespace geods::cli
