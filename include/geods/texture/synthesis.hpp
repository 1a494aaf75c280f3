#pragma once
// Texture synthesis by neighbourhood search (seed §5.5; Wei & Levoy 2000):
// the output is built level by level of a Gaussian pyramid, coarsest first;
// within a level each pixel takes the value of the sample pixel whose
// neighbourhood (neighborhood.hpp: causal n x n at the level, full m x m one
// level coarser) is nearest to its own (neighborhood_index.hpp).
//
// Order and determinism: pixels are synthesized in scan-line order, which for
// the causal window is the same as visiting them by t = x + (h + 1) y
// (h = n / 2): every pixel of p's window has a smaller t. Pixels of equal t do
// not see each other, so each such anti-diagonal is synthesized in parallel
// and the image is the same bytes on any thread count. A window pixel not yet
// synthesized (a later t; only with a toroidal output, across the wrap) reads
// the level's initial noise.
//
// Borders: a non-toroidal output is padded with h pixels of noise on every
// side, the seed's "random border", which is dropped at the end. The noise is
// the sample read toroidally from a random offset (random pixels, but with the
// sample's local structure, so that regular textures start in phase). A
// toroidal output (tile) wraps its windows instead, so that the result tiles,
// and starts from independent random sample pixels. Sample windows must lie
// inside the sample (candidates near its
// edges are left out), so the sample must be larger than the windows at every
// level.
//
// Refinement passes (optional) revisit every synthesized pixel with the whole
// n x n window (all pixels final, read from the previous pass), which removes
// the seams a causal pass leaves where it starts from noise (the top rows, and
// across the wrap of a toroidal output). They too are parallel and
// deterministic.
#include <cstddef>
#include <cstdint>
#include <string>

#include "geods/core/image.hpp"
#include "geods/core/progress.hpp"
#include "geods/texture/neighborhood_index.hpp"
#include "geods/texture/pyramid.hpp"

namespace geods::texture {

struct SynthesisOptions {
  std::size_t neighborhood = 9;         // odd fine window side, >= 3
  std::size_t parent_neighborhood = 0;  // odd window side one level coarser; 0: n/2 rounded up to odd (5 for 9)
  std::size_t levels = 0;               // pyramid levels; 0: as many as the sample allows, at most 4
  NeighborSearch search = NeighborSearch::approx;
  double eps = 24;                      // approx: distances within (1 + eps) of the nearest (docs/texture.md: why 24)
  std::size_t reduced_dimension = 0;    // principal components in the k-d tree; 0: 8
  std::size_t refinement_passes = 0;
  std::uint64_t seed = 0;
  ProgressCallback progress;
};

struct TextureRequest {
  std::size_t width = 0, height = 0;  // output size in pixels
  bool tile = false;                  // toroidal output: the result tiles without seams
  SynthesisOptions options;
};

struct SynthesisStats {
  std::size_t width = 0, height = 0, channels = 0;
  std::size_t levels = 0;
  std::size_t pixels = 0;       // pixels synthesized, summed over levels and passes
  std::size_t candidates = 0;   // sample neighbourhoods searched at the finest level
  std::size_t dimension = 0;    // values per neighbourhood at the finest level
  std::size_t reduced_dimension = 0;
  std::size_t full_distances = 0;  // full-dimension distances computed, over all levels
  /// Mean over the finest level's synthesized pixels of the distance between
  /// the pixel's neighbourhood and its match, per value (||N(p) - N(p_i)|| /
  /// sqrt(dimension), in 8-bit units): 0 is a perfect match.
  double mean_neighborhood_distance = 0;
  double compute_s = 0;
};

struct SynthesisResult {
  Image8 image;
  SynthesisStats stats;
};

/// A width x height texture like `sample` (1 to 4 channels of 8 bits). Throws
/// geods::Error for an empty output, an output over 2^30 pixels, a sample
/// too small for the windows at some level, or bad options.
SynthesisResult synthesize_texture(const Image8& sample, const TextureRequest& request);

/// Fills the hole of `image`: the pixels whose `mask` value (first channel)
/// is nonzero are synthesized, every other pixel is kept as it is. The sample
/// is `sample` if given (same channels), otherwise the image's known part:
/// its windows that do not touch the hole.
SynthesisResult fill_hole(const Image8& image, const Image8& mask, const SynthesisOptions& options,
                          const Image8* sample = nullptr);

}  // namespace geods::texture
