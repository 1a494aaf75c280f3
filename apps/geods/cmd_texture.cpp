// geods texture: texture synthesis by neighbourhood search (Wei-Levoy), and hole filling.
#include <fmt/format.h>

#include <filesystem>
#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/io/image_io.hpp"
#include "geods/texture/stats_fields.hpp"
#include "geods/texture/synthesis.hpp"
#include "stats_json.hpp"

namespace geods::cli {
namespace {

class TextureCommand : public Command {
 public:
  std::string name() const override { return "texture"; }
  std::string summary() const override {
    return "synthesize a texture like a sample image (Wei-Levoy neighborhood search), or fill a masked hole";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "sample", sample_, "Sample image: 8-bit PNG, JPEG or BMP, grey, grey+alpha, RGB or RGBA");
    add_output(app, "-o,--output", output_, "Output image", io::OutputKind::image)->required();
    app.add_option("--size", size_, "Output width,height (not with --image: the image's size)")->delimiter(',')->expected(2);
    app.add_option("--neighborhood", options_.neighborhood, "Odd side of the window at each level (default 9)");
    app.add_option("--parent-neighborhood", options_.parent_neighborhood,
                   "Odd side of the window one level coarser (default: neighborhood/2 rounded up to odd)");
    app.add_option("--levels", options_.levels, "Gaussian pyramid levels, 1 to 4 (default: from the sample size)");
    app.add_option("--search", search_, "Nearest-neighborhood search: approx (default), exact or brute");
    app.add_option("--eps", options_.eps, "approx: matches within (1 + eps) of the nearest (default 24)");
    app.add_option("--reduced-dimension", options_.reduced_dimension,
                   "Principal components in the k-d tree (default 8)");
    app.add_option("--refinement-passes,--refine", options_.refinement_passes,
                   "Passes over the output with the whole window, after the causal pass (default 0)");
    app.add_option("--seed", options_.seed, "Seed of the initial noise");
    app.add_flag("--tile", tile_, "Toroidal output: the result tiles without seams");
    app.add_option("--image", image_, "Fill a hole in this image (needs --mask) from SAMPLE, or from its own known part if SAMPLE is the image");
    app.add_option("--mask", mask_, "Hole mask, the image's size: nonzero (first channel) = pixel to synthesize")
        ->needs("--image");
  }

  void run(const RunContext& context, Report& report) override {
    if (!image_.empty() && mask_.empty()) throw Error("texture: --image needs --mask");
    if (!image_.empty() && !size_.empty()) throw Error("texture: --size does not go with --image (the image's size is used)");
    if (image_.empty() && size_.empty()) throw Error("texture: --size W,H is required (or --image and --mask)");
    options_.search = texture::parse_neighbor_search(search_);
    options_.progress = context.progress;
    const Image8 sample = read_8_bit(sample_);

    texture::SynthesisResult result;
    if (image_.empty()) {
      texture::TextureRequest request;
      request.width = size_[0];
      request.height = size_[1];
      request.tile = tile_;
      request.options = options_;
      result = texture::synthesize_texture(sample, request);
    } else {
      if (tile_) throw Error("texture: --tile does not go with --image");
      const Image8 image = read_8_bit(image_), mask = read_8_bit(mask_);
      // SAMPLE = the image itself: its windows that do not touch the hole are the candidates.
      const bool own = std::filesystem::equivalent(sample_, image_);
      result = texture::fill_hole(image, mask, options_, own ? nullptr : &sample);
    }
    io::write_png(output_, result.image);

    Json& j = report.json;
    j["sample"] = sample_;
    if (!image_.empty()) j["image"] = image_, j["mask"] = mask_;
    j["search"] = search_;
    j["neighborhood"] = options_.neighborhood;
    if (options_.search == texture::NeighborSearch::approx) j["eps"] = options_.eps;
    j["tile"] = tile_;
    j["seed"] = options_.seed;
    put_stats(j, result.stats);
    j["output"] = output_;
    const auto& s = result.stats;
    report.lines.push_back(fmt::format("texture: {} ({} channels) -> {}x{}, {} levels, {} search{}", sample_,
                                       s.channels, s.width, s.height, s.levels, search_,
                                       image_.empty() ? "" : ", filling the hole of " + image_));
    report.lines.push_back(fmt::format("  {} pixels synthesized in {:.3f} s; {} candidates of {} values ({} in the tree)",
                                       s.pixels, s.compute_s, s.candidates, s.dimension, s.reduced_dimension));
    report.lines.push_back(fmt::format("  mean neighborhood distance {:.3f} per value; wrote {}",
                                       s.mean_neighborhood_distance, output_));
  }

 private:
  using Image8 = texture::Image8;
  static Image8 read_8_bit(const std::string& path) {
    if (io::image_bit_depth(path) != 8)
      throw Error(path + ": a 16-bit image; texture synthesis works on 8-bit samples (convert it first)");
    return io::read_image(path);
  }

  std::string sample_, output_, image_, mask_, search_ = "approx";
  std::vector<std::size_t> size_;
  texture::SynthesisOptions options_;
  bool tile_ = false;
};

const bool registered_texture = register_command<TextureCommand>();

}  // namespace
}  // namespace geods::cli
