#include "geods/texture/synthesis.hpp"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <iterator>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/texture/neighborhood.hpp"

namespace geods::texture {
namespace {

constexpr std::size_t kMaxLevels = 4;
constexpr std::uint32_t kNoSource = std::numeric_limits<std::uint32_t>::max();
// The causal neighbours whose patches the coherent start continues.
// (All 12 of the 5 x 5 causal window were tried: no better matches on brick or gravel, 5 % slower.)
constexpr Offset kCoherenceOffsets[] = {{-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
constexpr std::size_t kMaxOutputPixels = std::size_t(1) << 30;
// Principal components in the k-d tree when the caller leaves it to us: fewer
// make the lower bound looser (more full distances), more make the tree slower
// (a tree of a few thousand candidates splits only about 9 axes). 8 was the
// fastest at the same error on 64^2 to 512^2 samples (docs/texture.md).
constexpr std::size_t kDefaultReducedDimension = 8;

std::string size_text(std::size_t w, std::size_t h) { return std::to_string(w) + "x" + std::to_string(h); }

// One pyramid level of the output (or of the image whose hole is filled): the
// pixels, the noise they start from, and which ones are synthesized. A
// non-toroidal canvas has `pad` border pixels of noise on every side; a
// toroidal one wraps instead. Coordinates are those of the interior.
struct Canvas {
  std::size_t width = 0, height = 0, channels = 0, pad = 0;
  bool wrap = false;
  std::vector<std::uint8_t> values, noise;
  std::vector<std::uint8_t> unknown;  // interior pixels, 1 = synthesized here
  // Interior pixels: the sample pixel (y * width + x of the sample level) whose
  // value each holds, kNoSource for noise and for known pixels of another image.
  std::vector<std::uint32_t> source;

  std::size_t row() const { return width + 2 * pad; }
  std::size_t interior(std::size_t x, std::size_t y) const { return y * width + x; }
  // Offset of the pixel at interior coordinates (x, y), which may lie up to pad outside.
  std::size_t at(std::ptrdiff_t x, std::ptrdiff_t y) const {
    if (wrap) {
      const auto w = std::ptrdiff_t(width), h = std::ptrdiff_t(height);
      x = ((x % w) + w) % w;
      y = ((y % h) + h) % h;
      return (std::size_t(y) * width + std::size_t(x)) * channels;
    }
    return ((std::size_t(y + std::ptrdiff_t(pad)) * row()) + std::size_t(x + std::ptrdiff_t(pad))) * channels;
  }
};

// The candidates of one level: the sample pixels whose windows lie in the
// sample (and, with a sample mask, touch no unknown pixel), their vectors in
// the search index, and the value each one gives.
struct Candidates {
  std::vector<std::uint8_t> values;  // channels per candidate
  std::vector<std::uint32_t> pixel;  // per candidate: its sample pixel, y * width + x
  std::vector<std::uint32_t> at;     // per sample pixel: its candidate, or kNoSource
  std::size_t width = 0, height = 0;  // of the sample level
  std::optional<NeighborhoodIndex> index;
};

struct Level {
  const Image8& sample;
  const Image8* sample_parent;  // one level coarser, null at the coarsest
  const Image8* sample_mask;    // unknown sample pixels (nonzero), or null
  const Image8* sample_parent_mask;
};

bool inside(const Image8& image, std::ptrdiff_t x, std::ptrdiff_t y) {
  return x >= 0 && y >= 0 && x < std::ptrdiff_t(image.width) && y < std::ptrdiff_t(image.height);
}

Candidates gather_candidates(const Level& level, const NeighborhoodShape& shape, std::size_t reduced_dimension) {
  const Image8& s = level.sample;
  const std::size_t c = s.channels, dim = shape.dimension(c);
  auto known = [](const Image8* mask, std::ptrdiff_t x, std::ptrdiff_t y) {
    return !mask || !(*mask)(std::size_t(x), std::size_t(y), 0);
  };
  Candidates out;
  out.at.assign(s.width * s.height, kNoSource);
  out.width = s.width;
  out.height = s.height;
  std::vector<std::uint8_t> vectors;
  for (std::size_t y = 0; y < s.height; ++y)
    for (std::size_t x = 0; x < s.width; ++x) {
      const auto px = std::ptrdiff_t(x), py = std::ptrdiff_t(y);
      bool ok = known(level.sample_mask, px, py);
      for (const Offset o : shape.fine)
        ok = ok && inside(s, px + o.dx, py + o.dy) && known(level.sample_mask, px + o.dx, py + o.dy);
      for (const Offset o : shape.parent) {
        const std::ptrdiff_t qx = px / 2 + o.dx, qy = py / 2 + o.dy;
        ok = ok && inside(*level.sample_parent, qx, qy) && known(level.sample_parent_mask, qx, qy);
      }
      if (!ok) continue;
      for (const Offset o : shape.fine)
        for (std::size_t k = 0; k < c; ++k) vectors.push_back(s(std::size_t(px + o.dx), std::size_t(py + o.dy), k));
      for (const Offset o : shape.parent)
        for (std::size_t k = 0; k < c; ++k)
          vectors.push_back((*level.sample_parent)(std::size_t(px / 2 + o.dx), std::size_t(py / 2 + o.dy), k));
      for (std::size_t k = 0; k < c; ++k) out.values.push_back(s(x, y, k));
      out.at[y * s.width + x] = std::uint32_t(out.pixel.size());
      out.pixel.push_back(std::uint32_t(y * s.width + x));
    }
  if (vectors.empty()) return out;
  out.index.emplace(std::move(vectors), dim, reduced_dimension);
  return out;
}

// Everything a level's passes share.
struct LevelSynthesis {
  const NeighborhoodShape& shape;
  const Candidates& candidates;
  Canvas& canvas;
  const Canvas* parent;  // the coarser level's finished canvas, or null
  const SynthesisOptions& options;
  std::vector<float>* distances;  // per interior pixel, at the finest level only
  // Offsets of the window pixels from the centre in a padded canvas's values
  // (a toroidal canvas wraps instead, through Canvas::at).
  std::vector<std::ptrdiff_t> fine_delta, parent_delta;

  struct Worker {
    std::vector<std::uint8_t> query;
    NeighborhoodIndex::Scratch scratch;
  };
  tbb::enumerable_thread_specific<Worker> workers;

  std::size_t full_distances() {
    std::size_t n = 0;
    for (const Worker& w : workers) n += w.scratch.full_distances;
    return n;
  }

  // Gathers p's window into `query`: fine pixels from `source` (the canvas's
  // values, or the previous pass's), the pixels of a later t from the noise.
  void gather(std::size_t x, std::size_t y, const std::vector<std::uint8_t>& source, std::optional<std::size_t> t,
              std::vector<std::uint8_t>& query) const {
    const std::size_t c = canvas.channels;
    const std::size_t h1 = std::size_t(shape.fine_half) + 1;
    if (!canvas.wrap) {  // the common case, without a branch per value
      query.resize(shape.dimension(c));
      std::uint8_t* out = query.data();
      const std::uint8_t* centre = source.data() + canvas.at(std::ptrdiff_t(x), std::ptrdiff_t(y));
      const std::uint8_t* up =
          parent ? parent->values.data() + parent->at(std::ptrdiff_t(x / 2), std::ptrdiff_t(y / 2)) : nullptr;
      if (c == 1) {  // grey: one byte per offset, not a memmove call each
        for (const std::ptrdiff_t d : fine_delta) *out++ = centre[d];
        for (const std::ptrdiff_t d : parent_delta) *out++ = up[d];
        return;
      }
      for (const std::ptrdiff_t d : fine_delta) out = std::copy_n(centre + d, c, out);
      for (const std::ptrdiff_t d : parent_delta) out = std::copy_n(up + d, c, out);
      return;
    }
    query.clear();
    for (const Offset o : shape.fine) {
      const std::size_t at = canvas.at(std::ptrdiff_t(x) + o.dx, std::ptrdiff_t(y) + o.dy);
      const std::uint8_t* value = source.data() + at;
      if (t && canvas.wrap) {  // a wrapped canvas stores the interior only: at / c is the pixel's index
        const std::size_t i = at / c;
        if (canvas.unknown[i] && i % canvas.width + h1 * (i / canvas.width) >= *t) value = canvas.noise.data() + at;
      }
      query.insert(query.end(), value, value + c);
    }
    for (const Offset o : shape.parent) {
      const std::uint8_t* value =
          parent->values.data() + parent->at(std::ptrdiff_t(x / 2) + o.dx, std::ptrdiff_t(y / 2) + o.dy);
      query.insert(query.end(), value, value + c);
    }
  }

  // The coherent candidate (Ashikhmin 2001): each already synthesized
  // neighbour q = p + o copied sample pixel s(q), so s(q) - o continues that
  // patch at p. The nearest of these few is a start for the tree search,
  // which then prunes from its first node. Only in the causal pass, where the
  // neighbours are final (a later t, across the wrap, is not read).
  NeighborhoodIndex::Match coherent_start(std::size_t x, std::size_t y, std::size_t t,
                                          const std::uint8_t* query) const {
    const NeighborhoodIndex& index = *candidates.index;
    const std::size_t h1 = std::size_t(shape.fine_half) + 1;
    NeighborhoodIndex::Match best;
    std::uint32_t seen[std::size(kCoherenceOffsets)];  // neighbours in one patch give one candidate: its distance once
    std::size_t seen_count = 0;
    for (const Offset o : kCoherenceOffsets) {
      std::ptrdiff_t qx = std::ptrdiff_t(x) + o.dx, qy = std::ptrdiff_t(y) + o.dy;
      const auto w = std::ptrdiff_t(canvas.width), h = std::ptrdiff_t(canvas.height);
      if (canvas.wrap) {
        qx = (qx + w) % w, qy = (qy + h) % h;
      } else if (qx < 0 || qy < 0 || qx >= w || qy >= h) {
        continue;
      }
      const std::size_t q = canvas.interior(std::size_t(qx), std::size_t(qy));
      if (canvas.unknown[q] && std::size_t(qx) + h1 * std::size_t(qy) >= t) continue;
      const std::uint32_t from = canvas.source[q];
      if (from == kNoSource) continue;
      const std::ptrdiff_t sx = std::ptrdiff_t(from % candidates.width) - o.dx,
                           sy = std::ptrdiff_t(from / candidates.width) - o.dy;
      if (sx < 0 || sy < 0 || sx >= std::ptrdiff_t(candidates.width) || sy >= std::ptrdiff_t(candidates.height))
        continue;
      const std::uint32_t i = candidates.at[std::size_t(sy) * candidates.width + std::size_t(sx)];
      if (i == kNoSource || std::find(seen, seen + seen_count, i) != seen + seen_count) continue;
      seen[seen_count++] = i;
      const NeighborhoodIndex::Match m{i, index.squared_distance(query, i)};
      if (m.before(best)) best = m;
    }
    return best;
  }

  // w: the calling thread's buffers (workers.local(), looked up once per chunk of pixels).
  void synthesize(Worker& w, std::size_t x, std::size_t y, const std::vector<std::uint8_t>& source,
                  std::optional<std::size_t> t) {
    gather(x, y, source, t, w.query);
    const NeighborhoodIndex& index = *candidates.index;
    const NeighborhoodIndex::Match start = t && options.search != NeighborSearch::brute
                                               ? coherent_start(x, y, *t, w.query.data())
                                               : NeighborhoodIndex::Match{};
    const auto match = index.nearest(w.query.data(), options.search, options.eps, w.scratch, start);
    canvas.source[canvas.interior(x, y)] = candidates.pixel[match.candidate];
    const std::size_t c = canvas.channels;
    std::copy_n(candidates.values.data() + std::size_t(match.candidate) * c, c, canvas.values.data() + canvas.at(std::ptrdiff_t(x), std::ptrdiff_t(y)));
    if (distances)
      (*distances)[canvas.interior(x, y)] = float(std::sqrt(double(match.squared_distance) / double(index.dimension())));
  }
};

// Window offsets as offsets in a padded canvas's values (see LevelSynthesis).
std::vector<std::ptrdiff_t> deltas(const Canvas& c, const std::vector<Offset>& offsets) {
  std::vector<std::ptrdiff_t> out;
  for (const Offset o : offsets) out.push_back((std::ptrdiff_t(c.row()) * o.dy + o.dx) * std::ptrdiff_t(c.channels));
  return out;
}

// The scan-line pass, one anti-diagonal t = x + (h + 1) y at a time (see synthesis.hpp).
void causal_pass(LevelSynthesis& s, Progress& progress, std::size_t& done) {
  Canvas& canvas = s.canvas;
  const std::size_t w = canvas.width, h = canvas.height, h1 = std::size_t(s.shape.fine_half) + 1;
  const std::size_t steps = (w - 1) + h1 * (h - 1) + 1;
  for (std::size_t t = 0; t < steps; ++t) {
    const std::size_t y_lo = t >= w ? (t - (w - 1) + h1 - 1) / h1 : 0, y_hi = std::min(h - 1, t / h1);
    if (y_lo > y_hi) continue;
    parallel_for(y_lo, y_hi + 1, 4, [&](std::size_t b, std::size_t e) {
      LevelSynthesis::Worker& worker = s.workers.local();
      for (std::size_t y = b; y < e; ++y) {
        const std::size_t x = t - h1 * y;
        if (canvas.unknown[canvas.interior(x, y)]) s.synthesize(worker, x, y, canvas.values, t);
      }
    });
    done += y_hi + 1 - y_lo;
    progress.update(double(done));
  }
}

// A refinement pass: every synthesized pixel again, with the whole window read from the previous pass.
void refinement_pass(LevelSynthesis& s, Progress& progress, std::size_t& done) {
  Canvas& canvas = s.canvas;
  const std::vector<std::uint8_t> previous = canvas.values;
  constexpr std::size_t kRowsPerUpdate = 8;
  for (std::size_t y0 = 0; y0 < canvas.height; y0 += kRowsPerUpdate) {
    const std::size_t y1 = std::min(canvas.height, y0 + kRowsPerUpdate);
    parallel_for(y0 * canvas.width, y1 * canvas.width, 16, [&](std::size_t b, std::size_t e) {
      LevelSynthesis::Worker& worker = s.workers.local();
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t x = i % canvas.width, y = i / canvas.width;
        if (canvas.unknown[i]) s.synthesize(worker, x, y, previous, std::nullopt);
      }
    });
    done += (y1 - y0) * canvas.width;
    progress.update(double(done));
  }
}

void check_options(const SynthesisOptions& o) {
  if (!(o.eps >= 0) || std::isinf(o.eps)) throw Error("texture: eps must be finite and >= 0");
  if (o.levels > kMaxLevels) throw Error("texture: levels must be from 1 to 4 (0: automatic), got " + std::to_string(o.levels));
}

std::size_t parent_size(const SynthesisOptions& o) {
  return o.parent_neighborhood ? o.parent_neighborhood : ((o.neighborhood / 2) | 1);
}

// The pyramid levels: as asked, or as many (up to 4) as keep the coarsest
// sample level at least twice the window on each side.
std::size_t level_count(const Image8& sample, const SynthesisOptions& o) {
  if (o.levels) return o.levels;
  std::size_t levels = 1;
  while (levels < kMaxLevels && std::min(level_size(sample.width, levels), level_size(sample.height, levels)) >=
                                    2 * o.neighborhood)
    ++levels;
  return levels;
}

void check_image(const Image8& image, const char* what) {
  if (image.channels < 1 || image.channels > 4)
    throw Error(std::string("texture: the ") + what + " must have 1 to 4 channels, got " + std::to_string(image.channels));
  if (image.width == 0 || image.height == 0) throw Error(std::string("texture: the ") + what + " is empty");
}

// The noise a level starts from. The border of a non-toroidal canvas is the
// sample read toroidally from a random offset, so that it holds the sample's
// local structure (a border of independent random pixels locks regular
// textures, such as stripes, into the wrong period from the first row on);
// unknown pixels of a masked sample give way to random candidates' values.
// A toroidal canvas starts from independent random candidate values: its
// first rows read them across the wrap, and a structured start there would
// be copied on and clash with the rows it finally wraps to.
void fill_noise(Canvas& canvas, const Level& level, const Candidates& candidates, Rng rng) {
  const Image8& s = level.sample;
  const std::size_t c = canvas.channels, n = candidates.values.size() / c;
  if (canvas.wrap) {
    for (std::size_t i = 0; i < canvas.noise.size(); i += c)
      std::copy_n(candidates.values.data() + rng.below(n) * c, c, canvas.noise.data() + i);
    return;
  }
  const std::size_t ox = rng.below(s.width), oy = rng.below(s.height);
  const std::size_t rows = canvas.height + 2 * canvas.pad;
  for (std::size_t y = 0; y < rows; ++y)
    for (std::size_t x = 0; x < canvas.row(); ++x) {
      const std::size_t sx = (ox + x) % s.width, sy = (oy + y) % s.height;
      const std::uint8_t* value = &s(sx, sy, 0);
      if (level.sample_mask && (*level.sample_mask)(sx, sy, 0)) value = candidates.values.data() + rng.below(n) * c;
      std::copy_n(value, c, canvas.noise.data() + (y * canvas.row() + x) * c);
    }
}

// Before a level's first pass: its unknown pixels and its border start as its noise.
void start_from_noise(Canvas& c) {
  const std::size_t rows = c.height + 2 * c.pad;
  for (std::size_t y = 0; y < rows; ++y)
    for (std::size_t x = 0; x < c.row(); ++x) {
      const bool border = y < c.pad || y >= c.height + c.pad || x < c.pad || x >= c.width + c.pad;
      if (border || c.unknown[c.interior(x - c.pad, y - c.pad)]) {
        const std::size_t at = (y * c.row() + x) * c.channels;
        std::copy_n(c.noise.data() + at, c.channels, c.values.data() + at);
      }
    }
}

// The whole synthesis over given canvases (one per level, finest first, with
// their unknown pixels and, for a hole, their known values already in place).
SynthesisStats run(const std::vector<Image8>& sample, const std::vector<Image8>* sample_mask,
                   std::vector<Canvas>& canvases, const SynthesisOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t levels = canvases.size();
  const NeighborhoodShape causal_fine = NeighborhoodShape::make(options.neighborhood, parent_size(options), true);
  const NeighborhoodShape causal_top = NeighborhoodShape::make(options.neighborhood, 0, true);
  const NeighborhoodShape full_fine = NeighborhoodShape::make(options.neighborhood, parent_size(options), false);
  const NeighborhoodShape full_top = NeighborhoodShape::make(options.neighborhood, 0, false);
  const std::size_t reduced =
      options.search == NeighborSearch::brute ? 0 : (options.reduced_dimension ? options.reduced_dimension : kDefaultReducedDimension);

  std::size_t total = 0, synthesized = 0;  // pixels visited / synthesized, over levels and passes
  for (const Canvas& c : canvases) {
    const std::size_t passes = 1 + options.refinement_passes;
    total += c.width * c.height * passes;
    synthesized += std::size_t(std::count(c.unknown.begin(), c.unknown.end(), 1)) * passes;
  }
  Progress progress(options.progress, "texture", double(total));
  std::size_t done = 0;

  SynthesisStats stats;
  stats.width = canvases[0].width;
  stats.height = canvases[0].height;
  stats.channels = canvases[0].channels;
  stats.levels = levels;
  std::vector<float> distances(canvases[0].width * canvases[0].height, 0.0f);
  for (std::size_t l = levels; l-- > 0;) {
    const bool top = l + 1 == levels;
    const Level level{sample[l], top ? nullptr : &sample[l + 1], sample_mask ? &(*sample_mask)[l] : nullptr,
                      sample_mask && !top ? &(*sample_mask)[l + 1] : nullptr};
    Canvas& canvas = canvases[l];
    const Canvas* parent = top ? nullptr : &canvases[l + 1];
    // The candidates of each window shape, built once per level (every refinement pass shares the full window's).
    auto candidates_for = [&](const NeighborhoodShape& shape) {
      Candidates candidates = gather_candidates(level, shape, reduced);
      if (!candidates.index)
        throw Error("texture: the sample (" + size_text(sample[0].width, sample[0].height) + ", " +
                    size_text(sample[l].width, sample[l].height) + " at pyramid level " + std::to_string(l) +
                    ") is too small for a " + std::to_string(options.neighborhood) + "x" +
                    std::to_string(options.neighborhood) + " neighborhood" +
                    (sample_mask ? " away from the hole" : "") + "; use fewer levels or a smaller neighborhood");
      return candidates;
    };
    const Candidates causal = candidates_for(top ? causal_top : causal_fine);
    const std::optional<Candidates> full =
        options.refinement_passes ? std::optional(candidates_for(top ? full_top : full_fine)) : std::nullopt;
    fill_noise(canvas, level, causal, Rng(options.seed * 31 + l));
    start_from_noise(canvas);
    for (std::size_t pass = 0; pass <= options.refinement_passes; ++pass) {
      const bool last = pass == options.refinement_passes;
      const NeighborhoodShape& shape = pass == 0 ? (top ? causal_top : causal_fine) : (top ? full_top : full_fine);
      const Candidates& candidates = pass == 0 ? causal : *full;
      LevelSynthesis s{shape,   candidates, canvas, parent, options, l == 0 && last ? &distances : nullptr,
                       deltas(canvas, shape.fine), parent ? deltas(*parent, shape.parent) : std::vector<std::ptrdiff_t>{},
                       {}};
      if (pass == 0)
        causal_pass(s, progress, done);
      else
        refinement_pass(s, progress, done);
      stats.full_distances += s.full_distances();
      if (l == 0 && last) {
        const NeighborhoodIndexStats is = candidates.index->stats();
        stats.candidates = is.candidates;
        stats.dimension = is.dimension;
        stats.reduced_dimension = is.reduced_dimension;
      }
    }
  }
  progress.finish();
  stats.pixels = synthesized;
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < distances.size(); ++i)
    if (canvases[0].unknown[i]) sum += distances[i], ++count;
  stats.mean_neighborhood_distance = count ? sum / double(count) : 0;
  stats.compute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

Canvas make_canvas(std::size_t width, std::size_t height, std::size_t channels, std::size_t pad, bool wrap) {
  Canvas c;
  c.width = width;
  c.height = height;
  c.channels = channels;
  c.wrap = wrap;
  c.pad = wrap ? 0 : pad;
  const std::size_t n = (width + 2 * c.pad) * (height + 2 * c.pad) * channels;
  c.values.assign(n, 0);
  c.noise.assign(n, 0);
  c.unknown.assign(width * height, 1);
  c.source.assign(width * height, kNoSource);
  return c;
}

Image8 interior_image(const Canvas& c) {
  Image8 out(c.width, c.height, c.channels);
  for (std::size_t y = 0; y < c.height; ++y)
    for (std::size_t x = 0; x < c.width; ++x)
      std::copy_n(c.values.data() + c.at(std::ptrdiff_t(x), std::ptrdiff_t(y)), c.channels, &out(x, y, 0));
  return out;
}

std::size_t canvas_pad(const SynthesisOptions& o) { return std::max(o.neighborhood, parent_size(o)) / 2; }

}  // namespace

SynthesisResult synthesize_texture(const Image8& sample, const TextureRequest& request) {
  const SynthesisOptions& options = request.options;
  check_options(options);
  check_image(sample, "sample");
  if (request.width == 0 || request.height == 0)
    throw Error("texture: the output size must be at least 1x1, got " + size_text(request.width, request.height));
  if (request.width > kMaxOutputPixels / request.height)
    throw Error("texture: the output " + size_text(request.width, request.height) + " is over 2^30 pixels");
  NeighborhoodShape::make(options.neighborhood, parent_size(options), true);  // checks the sizes
  const std::size_t levels = level_count(sample, options);
  const std::vector<Image8> pyramid = gaussian_pyramid(sample, levels);
  std::vector<Canvas> canvases;
  for (std::size_t l = 0; l < levels; ++l)
    canvases.push_back(make_canvas(level_size(request.width, l), level_size(request.height, l), sample.channels,
                                   canvas_pad(options), request.tile));
  SynthesisResult result;
  result.stats = run(pyramid, nullptr, canvases, options);
  result.image = interior_image(canvases[0]);
  return result;
}

SynthesisResult fill_hole(const Image8& image, const Image8& mask, const SynthesisOptions& options,
                          const Image8* sample) {
  check_options(options);
  check_image(image, "image");
  if (mask.width != image.width || mask.height != image.height)
    throw Error("fill_hole: the mask (" + size_text(mask.width, mask.height) + ") and the image (" +
                size_text(image.width, image.height) + ") differ in size");
  if (mask.channels == 0) throw Error("fill_hole: the mask has no channels");
  if (sample) {
    check_image(*sample, "sample");
    if (sample->channels != image.channels)
      throw Error("fill_hole: the sample has " + std::to_string(sample->channels) + " channels, the image " +
                  std::to_string(image.channels));
  }
  NeighborhoodShape::make(options.neighborhood, parent_size(options), true);
  const Image8& source = sample ? *sample : image;
  const std::size_t levels = level_count(source, options);
  const std::vector<Image8> image_pyramid = gaussian_pyramid(image, levels);
  std::vector<Image8> masks{Image8(mask.width, mask.height, 1)};
  for (std::size_t i = 0; i < mask.width * mask.height; ++i) masks[0].data[i] = mask.data[i * mask.channels] ? 255 : 0;
  while (masks.size() < levels) masks.push_back(downsample_mask(masks.back()));

  std::vector<Canvas> canvases;
  for (std::size_t l = 0; l < levels; ++l) {
    const Image8& level = image_pyramid[l];
    Canvas c = make_canvas(level.width, level.height, level.channels, canvas_pad(options), false);
    for (std::size_t y = 0; y < level.height; ++y)
      for (std::size_t x = 0; x < level.width; ++x) {
        c.unknown[c.interior(x, y)] = masks[l](x, y, 0) ? 1 : 0;
        if (!sample && !c.unknown[c.interior(x, y)]) c.source[c.interior(x, y)] = std::uint32_t(y * level.width + x);
        std::copy_n(&level(x, y, 0), level.channels, c.values.data() + c.at(std::ptrdiff_t(x), std::ptrdiff_t(y)));
      }
    canvases.push_back(std::move(c));
  }
  SynthesisResult result;
  if (sample)
    result.stats = run(gaussian_pyramid(*sample, levels), nullptr, canvases, options);
  else
    result.stats = run(image_pyramid, &masks, canvases, options);
  result.image = interior_image(canvases[0]);
  return result;
}

}  // namespace geods::texture
