// geods::texture on the texture comparison: Wei-Levoy synthesis with one neighbourhood search
// (TEXTURE_SEARCH: approx, exact or brute), default options otherwise. Samples: data/brick.png
// and data/gravel.png reduced by the Gaussian pyramid to 128 x 128 and 64 x 64 (levels 2 and 3
// of the 512 x 512 images), synthesized to 256 x 256 and 512 x 512 with seed 1. Reported: the
// time (query_s), the mean neighbourhood distance per value (the match error), and an FNV hash
// of the image (exact and brute must agree).
#include <cstdint>
#include <string>

#include "common.hpp"
#include "geods/io/image_io.hpp"
#include "geods/texture/pyramid.hpp"
#include "geods/texture/synthesis.hpp"

namespace {

std::uint64_t fnv1a(const std::vector<std::uint8_t>& bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (const std::uint8_t b : bytes) h = (h ^ b) * 1099511628211ull;
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  namespace texture = geods::texture;
  const char* variants[] = {"brick_64_to_256", "brick_64_to_512", "brick_128_to_256", "brick_128_to_512",
                            "gravel_64_to_256", "gravel_128_to_256"};
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  for (const std::string variant : variants) {
    if (!args.wants(variant)) continue;
    const std::size_t a = variant.find('_'), b = variant.find("_to_");
    const std::string name = variant.substr(0, a);
    const std::size_t sample_side = std::stoul(variant.substr(a + 1, b - a - 1));
    const std::size_t out_side = args.scaled(std::stoul(variant.substr(b + 4)));

    const texture::Image8 full = geods::io::read_image(std::string(TEXTURE_DATA_DIR) + "/" + name + ".png");
    const std::size_t level = sample_side == 128 ? 2 : 3;
    const texture::Image8 sample = texture::gaussian_pyramid(full, level + 1)[level];
    texture::TextureRequest request;
    request.width = request.height = out_side;
    request.options.search = texture::parse_neighbor_search(TEXTURE_SEARCH);
    request.options.seed = 1;

    texture::SynthesisResult result;
    const double s = compare::median_time_s(args.reps, [&] { result = texture::synthesize_texture(sample, request); });
    const bool ok = sample.width == sample_side && result.image.width == out_side &&
                    result.stats.mean_neighborhood_distance > 0;
    compare::Record("texture", std::string("geods-") + TEXTURE_SEARCH, variant, args.threads)
        .timing(0, s, out_side * out_side, args.reps)
        .set("mean_neighborhood_distance", result.stats.mean_neighborhood_distance)
        .set("full_distances", static_cast<unsigned long long>(result.stats.full_distances))
        .set("image_hash", std::to_string(fnv1a(result.image.data)))
        .print(ok);
  }
  return 0;
}
