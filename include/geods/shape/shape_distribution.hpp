#pragma once
// Shape distributions (seed §5.6; Osada, Funkhouser, Chazelle, Dobkin, "Shape
// distributions", ACM TOG 21(4), 2002): a shape function of random points on a
// mesh's surface, evaluated many times, binned into a histogram that serves as
// the shape's feature vector.
//
// Sampling: points are uniform on the surface (area-weighted): a triangle is
// picked with probability proportional to its area (Walker's alias table, O(1)
// per pick), then a point in it with Osada's formula
//   P = (1 - sqrt(r1)) A + sqrt(r1) (1 - r2) B + sqrt(r1) r2 C.
// The samples are drawn in chunks of kChunk evaluations, chunk c from its own
// Rng seeded by (seed, c), so the histogram depends only on the mesh and the
// options, never on the thread count.
//
// Shape functions: d1 |P - C| with C the surface's centroid (area-weighted,
// exact), d2 |P1 - P2|, a3 the angle at P1 between P1P2 and P1P3 (0..pi),
// d3 sqrt of the area of triangle P1P2P3, d4 cube root of the volume of
// tetrahedron P1P2P3P4.
//
// Normalization (scale): the lengths of d1, d2, d3 and d4 are divided by the
// mean (default) or the median of the sampled values before binning, so a
// uniformly scaled copy gets the same histogram; the histogram covers
// [0, max_value) of the normalized values (default 3 for the mean, 4 for the
// median; a larger value lands in the last bin). a3 is scale-invariant and
// covers [0, pi). Normalization::none bins the raw values over [0, max_value)
// (max_value then required), as in the seed's Figure 55. Translation and
// rotation do not change the function values; tessellation does not change the
// distribution of surface points. The histogram sums to 1.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "geods/core/rng.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/core/vec.hpp"

namespace geods::shape {

enum class ShapeFunction : std::uint32_t { d1, d2, a3, d3, d4 };
enum class Normalization : std::uint32_t { mean, median, none };

std::string_view shape_function_name(ShapeFunction f);
/// "d1", "d2", "a3", "d3" or "d4"; geods::Error otherwise.
ShapeFunction parse_shape_function(std::string_view name);
std::string_view normalization_name(Normalization n);
/// "mean", "median" or "none"; geods::Error otherwise.
Normalization parse_normalization(std::string_view name);

struct DistributionOptions {
  std::size_t samples = 1 << 16;  // evaluations of the shape function (>= 1)
  std::size_t bins = 64;          // histogram bins (>= 1)
  std::uint64_t seed = 0;
  Normalization normalization = Normalization::mean;
  double max_value = 0;  // upper end of the histogram; 0: 3 (mean), 4 (median), pi (a3); required for none
};

/// Evaluations per random stream: chunk c of the samples uses Rng(chunk_seed(seed, c)).
inline constexpr std::size_t kChunk = 4096;

/// Area-weighted uniform random points on a mesh's surface. Construction checks
/// the mesh: geods::Error for no triangles, an index out of range, a non-finite
/// coordinate or a total area of zero. Zero-area triangles are never picked. O(n).
class SurfaceSampler {
 public:
  explicit SurfaceSampler(const TriMesh& mesh);
  /// A uniform random point on the surface; O(1).
  Vec3d sample(Rng& rng) const;
  double area() const { return area_; }
  /// Area-weighted centroid of the surface (exact, not sampled).
  const Vec3d& centroid() const { return centroid_; }
  std::size_t triangles() const { return corners_.size(); }

 private:
  struct Corner {  // per triangle: corner A and edges B - A, C - A (float: half the memory traffic of double)
    Vec3f a, ab, ac;
  };
  std::vector<Corner> corners_;
  std::vector<double> prob_;        // alias table: keep triangle i with probability prob_[i]
  std::vector<std::uint32_t> alias_;
  double area_ = 0;
  Vec3d centroid_ = Vec3d::Zero();
};

/// The seed of the random stream of chunk `chunk` (splitmix of both).
std::uint64_t chunk_seed(std::uint64_t seed, std::uint64_t chunk);

/// `samples` raw values of shape function f on the mesh (unnormalized), in the
/// order of the chunks; parallel over chunks, deterministic. Throws as SurfaceSampler.
std::vector<double> shape_function_values(const TriMesh& mesh, ShapeFunction f, std::size_t samples,
                                          std::uint64_t seed = 0);

/// The scale a distribution is normalized by: the mean or the median of the
/// values (1 for none and for a3). geods::Error if it is not positive and finite
/// (all sampled points coincide, say a mesh whose triangles have no volume for d4).
double normalization_scale(std::span<const double> values, ShapeFunction f, Normalization n);

/// The histogram's upper end under `options` (its max_value or the default).
double histogram_max(ShapeFunction f, const DistributionOptions& options);

/// The shape distribution of f on the mesh: options.bins values summing to 1
/// (see the header comment for sampling and normalization). Throws geods::Error
/// for bad options, or a mesh SurfaceSampler refuses. O(triangles + samples).
std::vector<float> shape_distribution(const TriMesh& mesh, ShapeFunction f, const DistributionOptions& options = {});

/// Bins `values` / scale over [0, max_value) into `bins` bins summing to 1
/// (values at or beyond the end go to the last bin).
std::vector<float> histogram(std::span<const double> values, double scale, double max_value, std::size_t bins);

// ---------------------------------------------------------------- similarity

enum class Metric : std::uint32_t { l1, l2, chi2, emd };
std::string_view metric_name(Metric m);
/// "l1", "l2", "chi2" or "emd"; geods::Error otherwise.
Metric parse_metric(std::string_view name);

/// Distance between two histograms of the same length: l1 sum |a - b|, l2
/// sqrt(sum (a - b)^2), chi2 sum (a - b)^2 / (a + b) over bins where a + b > 0,
/// emd the earth mover's distance of 1D distributions: the L1 distance of the
/// cumulative histograms (in bins). For a combined descriptor give `block`, the
/// bins per distribution: the cumulative sums restart at every block. Throws
/// geods::Error for different lengths or a block that does not divide them.
double histogram_distance(std::span<const float> a, std::span<const float> b, Metric metric, std::size_t block = 0);

// ---------------------------------------------------------------- descriptors

/// A feature vector: the shape distributions of `functions`, each multiplied by
/// its weight, concatenated (functions.size() * distribution.bins values).
struct DescriptorOptions {
  std::vector<ShapeFunction> functions{ShapeFunction::d2};
  std::vector<double> weights{1.0};  // one per function (>= 0, finite)
  DistributionOptions distribution;
};

/// "d1", "d2", "a3", "d3", "d4" (one function, weight 1), "combined" (d2, a3,
/// d3, weights 1, the ensemble PCL's ESF also uses) or functions joined by '+'
/// with optional weights ("d2+a3:0.5"). geods::Error otherwise.
DescriptorOptions parse_descriptor(std::string_view spec);
/// The spec parse_descriptor reads back ("d2", "combined", "d2:1+a3:0.5").
std::string descriptor_name(const DescriptorOptions& options);
/// Throws geods::Error for no functions, a weight count that differs, a
/// negative or non-finite weight, 0 samples or bins, a bad max_value.
void check_descriptor(const DescriptorOptions& options);

/// The descriptor of a mesh: each function's distribution from the same
/// surface sampler (with seed + function index), weighted and concatenated.
std::vector<float> describe(const TriMesh& mesh, const DescriptorOptions& options);

}  // namespace geods::shape
