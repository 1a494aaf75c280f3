#include "geods/shape/shape_distribution.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::shape {

namespace {

constexpr std::string_view kFunctionNames[] = {"d1", "d2", "a3", "d3", "d4"};
constexpr std::string_view kNormalizationNames[] = {"mean", "median", "none"};
constexpr std::string_view kMetricNames[] = {"l1", "l2", "chi2", "emd"};

template <typename E, std::size_t N>
E parse_name(std::string_view name, const std::string_view (&names)[N], const char* what) {
  for (std::size_t i = 0; i < N; ++i)
    if (names[i] == name) return E(i);
  std::string expected;
  for (std::size_t i = 0; i < N; ++i) expected += (i ? (i + 1 == N ? " or " : ", ") : "") + std::string(names[i]);
  throw Error(fmt::format("unknown {} '{}' (expected {})", what, name, expected));
}

// One evaluation of f on fresh surface points.
double evaluate(const SurfaceSampler& s, ShapeFunction f, Rng& rng) {
  switch (f) {
    case ShapeFunction::d1:
      return (s.sample(rng) - s.centroid()).norm();
    case ShapeFunction::d2: {
      const Vec3d p = s.sample(rng);
      return (s.sample(rng) - p).norm();
    }
    case ShapeFunction::a3: {
      const Vec3d p = s.sample(rng);
      const Vec3d u = s.sample(rng) - p, v = s.sample(rng) - p;
      return std::atan2(u.cross(v).norm(), u.dot(v));
    }
    case ShapeFunction::d3: {
      const Vec3d p = s.sample(rng);
      const Vec3d u = s.sample(rng) - p, v = s.sample(rng) - p;
      return std::sqrt(0.5 * u.cross(v).norm());
    }
    case ShapeFunction::d4: {
      const Vec3d p = s.sample(rng);
      const Vec3d u = s.sample(rng) - p, v = s.sample(rng) - p, w = s.sample(rng) - p;
      return std::cbrt(std::abs(u.cross(v).dot(w)) / 6.0);
    }
  }
  throw Error("shape: bad shape function");
}

void check_options(ShapeFunction f, const DistributionOptions& o) {
  if (std::size_t(f) > std::size_t(ShapeFunction::d4)) throw Error("shape: bad shape function");
  if (o.samples == 0) throw Error("shape: samples must be >= 1");
  if (o.samples > (std::size_t(1) << 32)) throw Error(fmt::format("shape: {} samples, at most 2^32", o.samples));
  if (o.bins == 0) throw Error("shape: bins must be >= 1");
  if (o.bins > (std::size_t(1) << 20)) throw Error(fmt::format("shape: {} bins, at most 2^20", o.bins));
  if (std::size_t(o.normalization) > std::size_t(Normalization::none)) throw Error("shape: bad normalization");
  if (!(std::isfinite(o.max_value) && o.max_value >= 0))
    throw Error(fmt::format("shape: max_value must be finite and >= 0, got {}", o.max_value));
  if (o.normalization == Normalization::none && o.max_value == 0 && f != ShapeFunction::a3)
    throw Error("shape: normalization none needs max_value, the end of the histogram's range");
}

}  // namespace

std::string_view shape_function_name(ShapeFunction f) { return kFunctionNames[std::size_t(f) % 5]; }
ShapeFunction parse_shape_function(std::string_view name) {
  return parse_name<ShapeFunction>(name, kFunctionNames, "shape function");
}
std::string_view normalization_name(Normalization n) { return kNormalizationNames[std::size_t(n) % 3]; }
Normalization parse_normalization(std::string_view name) {
  return parse_name<Normalization>(name, kNormalizationNames, "normalization");
}
std::string_view metric_name(Metric m) { return kMetricNames[std::size_t(m) % 4]; }
Metric parse_metric(std::string_view name) { return parse_name<Metric>(name, kMetricNames, "metric"); }

// ---------------------------------------------------------------- sampling

SurfaceSampler::SurfaceSampler(const TriMesh& mesh) {
  const std::size_t n = mesh.triangles.size(), nv = mesh.vertices.size();
  if (n == 0) throw Error("shape: the mesh has no triangles");
  if (n >= std::numeric_limits<std::uint32_t>::max()) throw Error("shape: too many triangles");
  for (std::size_t i = 0; i < nv; ++i)
    if (!mesh.vertices[i].allFinite()) throw Error(fmt::format("shape: vertex {} has a non-finite coordinate", i));
  corners_.resize(n);
  std::vector<double> weight(n);
  std::vector<char> bad(n, 0);
  // Per triangle in parallel (independent); the sums below run in order, so the result is deterministic.
  parallel_for(0, n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) {
      const auto& tri = mesh.triangles[t];
      if (tri[0] >= nv || tri[1] >= nv || tri[2] >= nv) {
        bad[t] = 1;
        continue;
      }
      const Vec3f& a = mesh.vertices[tri[0]];
      corners_[t] = {a, mesh.vertices[tri[1]] - a, mesh.vertices[tri[2]] - a};
      // Edges are stored in float: corners more than the float range apart would give infinite points.
      if (!corners_[t].ab.allFinite() || !corners_[t].ac.allFinite()) {
        bad[t] = 2;
        continue;
      }
      const Vec3d ab = (mesh.vertices[tri[1]].cast<double>() - a.cast<double>());
      const Vec3d ac = (mesh.vertices[tri[2]].cast<double>() - a.cast<double>());
      weight[t] = 0.5 * ab.cross(ac).norm();
    }
  });
  if (const auto it = std::find(bad.begin(), bad.end(), 2); it != bad.end() && std::find(bad.begin(), it, 1) == it)
    throw Error(fmt::format("shape: triangle {} spans more than the float range (coordinates near +-3.4e38); "
                            "scale the input",
                            it - bad.begin()));
  if (const auto it = std::find(bad.begin(), bad.end(), 1); it != bad.end()) {
    const std::size_t t = std::size_t(it - bad.begin());
    const auto& tri = mesh.triangles[t];
    const std::uint32_t corner = tri[0] >= nv ? tri[0] : tri[1] >= nv ? tri[1] : tri[2];
    throw Error(fmt::format("shape: triangle {} has corner {} out of range ({} vertices)", t, corner, nv));
  }
  Vec3d weighted = Vec3d::Zero();
  for (std::size_t t = 0; t < n; ++t) {
    const auto& c = corners_[t];
    area_ += weight[t];
    weighted += weight[t] * (c.a.cast<double>() + (c.ab.cast<double>() + c.ac.cast<double>()) / 3.0);
  }
  if (!(area_ > 0) || !std::isfinite(area_)) throw Error("shape: the mesh's surface has zero area");
  centroid_ = weighted / area_;

  // Vose's alias method: scaled weights n * w / W split into an underfull and an overfull list.
  prob_.assign(n, 0.0);
  alias_.assign(n, 0);
  const auto largest = std::uint32_t(std::max_element(weight.begin(), weight.end()) - weight.begin());
  std::vector<double> p(n);
  std::vector<std::uint32_t> small, large;
  for (std::size_t t = 0; t < n; ++t) {
    p[t] = weight[t] * double(n) / area_;
    (p[t] < 1.0 ? small : large).push_back(std::uint32_t(t));
  }
  while (!small.empty() && !large.empty()) {
    const std::uint32_t s = small.back(), l = large.back();
    small.pop_back();
    prob_[s] = p[s];
    alias_[s] = l;
    p[l] = (p[l] + p[s]) - 1.0;
    if (p[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // Left over by rounding: full columns, except a triangle of no area (never picked).
  for (std::uint32_t t : large) prob_[t] = 1.0, alias_[t] = t;
  for (std::uint32_t t : small) {
    prob_[t] = weight[t] > 0 ? 1.0 : 0.0;
    alias_[t] = weight[t] > 0 ? t : largest;
  }
}

Vec3d SurfaceSampler::sample(Rng& rng) const {
  const double u = rng.uniform() * double(prob_.size());
  std::size_t t = std::min(std::size_t(u), prob_.size() - 1);
  if (u - double(t) >= prob_[t]) t = alias_[t];
  const double s = std::sqrt(rng.uniform()), r2 = rng.uniform();
  const Corner& c = corners_[t];
  return c.a.cast<double>() + s * (1.0 - r2) * c.ab.cast<double>() + s * r2 * c.ac.cast<double>();
}

std::uint64_t chunk_seed(std::uint64_t seed, std::uint64_t chunk) {
  std::uint64_t z = seed ^ (0x9e3779b97f4a7c15ULL * (chunk + 1));
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

namespace {

std::vector<double> sample_values(const SurfaceSampler& sampler, ShapeFunction f, std::size_t samples,
                                  std::uint64_t seed) {
  std::vector<double> values(samples);
  const std::size_t chunks = (samples + kChunk - 1) / kChunk;
  parallel_for(0, chunks, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) {
      Rng rng(chunk_seed(seed, c));
      const std::size_t end = std::min(samples, (c + 1) * kChunk);
      for (std::size_t i = c * kChunk; i < end; ++i) values[i] = evaluate(sampler, f, rng);
    }
  });
  return values;
}

std::vector<float> distribution(const SurfaceSampler& sampler, ShapeFunction f, const DistributionOptions& o) {
  const std::vector<double> values = sample_values(sampler, f, o.samples, o.seed);
  return histogram(values, normalization_scale(values, f, o.normalization), histogram_max(f, o), o.bins);
}

}  // namespace

std::vector<double> shape_function_values(const TriMesh& mesh, ShapeFunction f, std::size_t samples,
                                          std::uint64_t seed) {
  check_options(f, DistributionOptions{samples, 1, seed, Normalization::mean, 0});
  return sample_values(SurfaceSampler(mesh), f, samples, seed);
}

double normalization_scale(std::span<const double> values, ShapeFunction f, Normalization n) {
  if (f == ShapeFunction::a3 || n == Normalization::none) return 1.0;
  if (values.empty()) throw Error("shape: no values to normalize");
  double scale;
  if (n == Normalization::mean) {
    scale = std::accumulate(values.begin(), values.end(), 0.0) / double(values.size());
  } else {
    std::vector<double> copy(values.begin(), values.end());
    auto mid = copy.begin() + std::ptrdiff_t(copy.size() / 2);
    std::nth_element(copy.begin(), mid, copy.end());
    scale = *mid;
  }
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error(fmt::format("shape: the {} of the {} values is {} (a surface without extent in the function's "
                            "dimensions); it cannot be normalized",
                            normalization_name(n), shape_function_name(f), scale));
  return scale;
}

double histogram_max(ShapeFunction f, const DistributionOptions& o) {
  if (o.max_value > 0) return o.max_value;
  if (f == ShapeFunction::a3) return std::numbers::pi;
  return o.normalization == Normalization::median ? 4.0 : 3.0;
}

std::vector<float> histogram(std::span<const double> values, double scale, double max_value, std::size_t bins) {
  if (bins == 0 || !(scale > 0) || !(max_value > 0)) throw Error("shape: histogram needs bins, scale and range > 0");
  std::vector<std::uint64_t> counts(bins, 0);
  const double factor = double(bins) / (scale * max_value);
  for (double v : values) {
    const double x = v * factor;
    const std::size_t bin = x >= double(bins) ? bins - 1 : x > 0 ? std::size_t(x) : 0;
    ++counts[bin];
  }
  std::vector<float> out(bins);
  const double total = double(values.size());
  for (std::size_t i = 0; i < bins; ++i) out[i] = float(double(counts[i]) / total);
  return out;
}

std::vector<float> shape_distribution(const TriMesh& mesh, ShapeFunction f, const DistributionOptions& options) {
  check_options(f, options);
  return distribution(SurfaceSampler(mesh), f, options);
}

// ---------------------------------------------------------------- similarity

double histogram_distance(std::span<const float> a, std::span<const float> b, Metric metric, std::size_t block) {
  if (a.size() != b.size())
    throw Error(fmt::format("shape::histogram_distance: histograms of {} and {} bins", a.size(), b.size()));
  if (block == 0) block = a.size();
  if (!a.empty() && a.size() % block != 0)
    throw Error(fmt::format("shape::histogram_distance: blocks of {} do not divide {} bins", block, a.size()));
  double sum = 0;
  switch (metric) {
    case Metric::l1:
      for (std::size_t i = 0; i < a.size(); ++i) sum += std::abs(double(a[i]) - double(b[i]));
      return sum;
    case Metric::l2:
      for (std::size_t i = 0; i < a.size(); ++i) sum += (double(a[i]) - double(b[i])) * (double(a[i]) - double(b[i]));
      return std::sqrt(sum);
    case Metric::chi2:
      for (std::size_t i = 0; i < a.size(); ++i) {
        const double s = double(a[i]) + double(b[i]), d = double(a[i]) - double(b[i]);
        if (s > 0) sum += d * d / s;
      }
      return sum;
    case Metric::emd: {
      double cumulative = 0;
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (i % block == 0) cumulative = 0;
        cumulative += double(a[i]) - double(b[i]);
        sum += std::abs(cumulative);
      }
      return sum;
    }
  }
  throw Error("shape::histogram_distance: bad metric");
}

// ---------------------------------------------------------------- descriptors

DescriptorOptions parse_descriptor(std::string_view spec) {
  DescriptorOptions o;
  o.functions.clear();
  o.weights.clear();
  if (spec == "combined") {
    o.functions = {ShapeFunction::d2, ShapeFunction::a3, ShapeFunction::d3};
    o.weights = {1.0, 1.0, 1.0};
    return o;
  }
  std::size_t start = 0;
  while (start <= spec.size()) {
    const std::size_t end = std::min(spec.find('+', start), spec.size());
    const std::string_view part = spec.substr(start, end - start);
    const std::size_t colon = part.find(':');
    o.functions.push_back(parse_shape_function(part.substr(0, colon)));
    double weight = 1.0;
    if (colon != std::string_view::npos) {
      const std::string_view w = part.substr(colon + 1);
      const auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), weight);
      if (ec != std::errc() || ptr != w.data() + w.size() || !std::isfinite(weight) || weight < 0)
        throw Error(fmt::format("shape: bad weight '{}' in descriptor '{}'", w, spec));
    }
    o.weights.push_back(weight);
    start = end + 1;
  }
  return o;
}

std::string descriptor_name(const DescriptorOptions& o) {
  if (o.functions.size() == 1 && o.weights.size() == 1 && o.weights[0] == 1.0)
    return std::string(shape_function_name(o.functions[0]));
  if (o.functions == std::vector<ShapeFunction>{ShapeFunction::d2, ShapeFunction::a3, ShapeFunction::d3} &&
      o.weights == std::vector<double>{1.0, 1.0, 1.0})
    return "combined";
  std::string out;
  for (std::size_t i = 0; i < o.functions.size(); ++i)
    out += fmt::format("{}{}:{}", i ? "+" : "", shape_function_name(o.functions[i]),
                       i < o.weights.size() ? o.weights[i] : 1.0);
  return out;
}

void check_descriptor(const DescriptorOptions& o) {
  if (o.functions.empty()) throw Error("shape: a descriptor needs at least one shape function");
  if (o.weights.size() != o.functions.size())
    throw Error(fmt::format("shape: {} weights for {} shape functions", o.weights.size(), o.functions.size()));
  for (double w : o.weights)
    if (!std::isfinite(w) || w < 0) throw Error(fmt::format("shape: bad descriptor weight {}", w));
  for (ShapeFunction f : o.functions) check_options(f, o.distribution);
}

std::vector<float> describe(const TriMesh& mesh, const DescriptorOptions& options) {
  check_descriptor(options);
  const SurfaceSampler sampler(mesh);
  std::vector<float> out;
  out.reserve(options.functions.size() * options.distribution.bins);
  for (std::size_t i = 0; i < options.functions.size(); ++i) {
    DistributionOptions o = options.distribution;
    o.seed = options.distribution.seed + i;
    for (float v : distribution(sampler, options.functions[i], o)) out.push_back(float(v * options.weights[i]));
  }
  return out;
}

}  // namespace geods::shape
