#include "geods/texture/neighborhood_index.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::texture {
namespace {

// The covariance is estimated from at most this many candidates, evenly
// spread: the principal directions only need to be good, not exact (the
// searches stay exact whatever the basis: see the integer basis below).
constexpr std::size_t kCovarianceSamples = 2048;
// Candidates per k-d tree leaf: smaller leaves mean fewer full distances and
// a longer descent. With the tree of compile-time dimension and float
// coordinates, 4 is 10 to 13 % faster than 8 on the bench's samples at the
// same error (means over seeds 1 to 5 within the spread over seeds).
constexpr std::size_t kLeafSize = 4;
// The approximate search's schedule (see the header): a query prunes with
// eps / kTightEpsDivisor until it has computed count / kTightShare - kTightBase
// full distances (the tight start: nothing below 4096 candidates), then with
// eps / kStartEpsDivisor for kStartDistances more, then with eps.
constexpr double kTightEpsDivisor = 12;
constexpr std::size_t kTightShare = 256;
constexpr std::size_t kTightBase = 16;
constexpr double kStartEpsDivisor = 3;

}  // namespace

NeighborSearch parse_neighbor_search(std::string_view name) {
  if (name == "brute") return NeighborSearch::brute;
  if (name == "exact") return NeighborSearch::exact;
  if (name == "approx") return NeighborSearch::approx;
  throw Error("texture: unknown search '" + std::string(name) + "' (choose brute, exact or approx)");
}

std::string_view neighbor_search_name(NeighborSearch search) {
  switch (search) {
    case NeighborSearch::brute: return "brute";
    case NeighborSearch::exact: return "exact";
    case NeighborSearch::approx: return "approx";
  }
  return "?";
}

NeighborhoodIndex::NeighborhoodIndex(std::vector<std::uint8_t> vectors, std::size_t dimension,
                                     std::size_t reduced_dimension)
    : vectors_(std::move(vectors)), dim_(dimension) {
  if (dim_ == 0 || dim_ > (std::numeric_limits<std::uint32_t>::max() / (255u * 255u)))
    throw Error("NeighborhoodIndex: dimension must be from 1 to 66051, got " + std::to_string(dim_));
  if (vectors_.size() % dim_ != 0) throw Error("NeighborhoodIndex: the vectors are not rows of the dimension");
  count_ = vectors_.size() / dim_;
  if (count_ == 0) throw Error("NeighborhoodIndex: no candidate neighborhoods");
  if (count_ >= std::numeric_limits<std::uint32_t>::max()) throw Error("NeighborhoodIndex: too many candidates");
  reduced_ = std::min(reduced_dimension, dim_);
  if (reduced_ == 0) return;

  // Principal components of the candidates: the top eigenvectors of their covariance.
  const std::size_t step = std::max<std::size_t>(1, count_ / kCovarianceSamples);
  const std::size_t samples = (count_ + step - 1) / step;
  Eigen::MatrixXd x(samples, dim_);
  for (std::size_t s = 0; s < samples; ++s)
    for (std::size_t a = 0; a < dim_; ++a) x(s, a) = candidate(s * step)[a];
  const Eigen::RowVectorXd mean = x.colwise().mean();
  x.rowwise() -= mean;
  const Eigen::MatrixXd covariance = (x.transpose() * x) / double(samples);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(covariance);
  const Eigen::VectorXd& values = solver.eigenvalues();  // ascending
  const double total = std::max(values.sum(), 0.0);
  double kept = 0;
  for (std::size_t r = 0; r < reduced_; ++r) kept += std::max(values(Eigen::Index(dim_ - 1 - r)), 0.0);
  explained_ = total > 0 ? kept / total : 1;

  // The integer basis (see the header): each direction times q, rounded, with q
  // as large as 16 bits allow and small enough that a row's products with
  // centred 8-bit values (|v - m| <= 255) sum within 32 bits.
  padded_ = (dim_ + 7) / 8 * 8;
  mean_.assign(padded_, 0);
  for (std::size_t a = 0; a < dim_; ++a) mean_[a] = std::int16_t(std::lround(mean(Eigen::Index(a))));
  double largest = 0, row_sum = 0;
  for (std::size_t r = 0; r < reduced_; ++r) {
    const auto direction = solver.eigenvectors().col(Eigen::Index(dim_ - 1 - r));
    largest = std::max(largest, direction.cwiseAbs().maxCoeff());
    row_sum = std::max(row_sum, direction.cwiseAbs().sum());
  }
  const double q = std::min(32000.0 / largest, 2.0e9 / (255.0 * (row_sum + double(dim_))));
  basis_.assign(reduced_ * padded_, 0);
  for (std::size_t r = 0; r < reduced_; ++r)
    for (std::size_t a = 0; a < dim_; ++a)
      basis_[r * padded_ + a] =
          std::int16_t(std::lround(q * solver.eigenvectors()(Eigen::Index(a), Eigen::Index(dim_ - 1 - r))));
  // The largest singular value of the integer basis is at most sqrt(max_r sum_j |G_rj|), G = B B^T
  // (Gershgorin; G in exact integers), so scale_ <= 1 / that makes the map's norm at most 1.
  std::int64_t gershgorin = 1;
  for (std::size_t r = 0; r < reduced_; ++r) {
    std::int64_t sum = 0;
    for (std::size_t j = 0; j < reduced_; ++j) {
      std::int64_t g = 0;
      for (std::size_t a = 0; a < dim_; ++a) g += std::int64_t(basis_[r * padded_ + a]) * basis_[j * padded_ + a];
      sum += g < 0 ? -g : g;
    }
    gershgorin = std::max(gershgorin, sum);
  }
  scale_ = (1.0 - 1e-12) / std::sqrt(double(gershgorin));

  // The float coordinates: |(y, residual)| = |v - m| <= 255 sqrt(dim) = R, so rounding moves a point by at
  // most R 2^-24, and a tree distance by at most R 2^-23 (both ends); margin_ is twice that.
  margin_ = 255.0 * std::sqrt(double(dim_)) * std::ldexp(1.0, -22);
  const std::size_t tree_dim = reduced_ + 1;
  projected_.resize(count_ * tree_dim);
  parallel_for(0, count_, 64, [&](std::size_t begin, std::size_t end) {
    std::vector<std::int16_t> centred;
    for (std::size_t i = begin; i < end; ++i) project(candidate(i), projected_.data() + i * tree_dim, centred);
  });
  // The default reduced dimension gets a tree of compile-time dimension (unrolled distances), others a dynamic one.
  if (tree_dim == kFixedTreeDim) {
    fixed_tree_ = std::make_unique<spatial::KdTree<float, kFixedTreeDim>>(
        spatial::PointView<float>(projected_.data(), count_, tree_dim), kLeafSize);
  } else {
    tree_ = std::make_unique<spatial::KdTree<float>>(spatial::PointView<float>(projected_.data(), count_, tree_dim),
                                                      kLeafSize);
  }
}

NeighborhoodIndexStats NeighborhoodIndex::stats() const {
  NeighborhoodIndexStats s;
  s.candidates = count_;
  s.dimension = dim_;
  s.reduced_dimension = reduced_;
  s.explained_variance = explained_;
  s.bytes = vectors_.size() + (mean_.size() + basis_.size()) * sizeof(std::int16_t) + projected_.size() * sizeof(float);
  if (tree_) s.bytes += tree_->stats().bytes + tree_->size() * tree_->dim() * sizeof(float);
  if (fixed_tree_) s.bytes += fixed_tree_->stats().bytes + fixed_tree_->size() * kFixedTreeDim * sizeof(float);
  return s;
}

void NeighborhoodIndex::project(const std::uint8_t* v, float* out, std::vector<std::int16_t>& centred) const {
  // Exact integers up to the last step: x = v - m in 16 bits, each component a
  // sum of 16-bit products (vectorized as multiply-adds), |x|^2 likewise.
  centred.resize(padded_);
  std::int16_t* x = centred.data();
  std::size_t a = 0;
#if defined(__SSE2__)
  for (; a + 8 <= dim_; a += 8) {
    const __m128i bytes = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(v + a));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(x + a),
                     _mm_sub_epi16(_mm_unpacklo_epi8(bytes, _mm_setzero_si128()),
                                   _mm_loadu_si128(reinterpret_cast<const __m128i*>(mean_.data() + a))));
  }
#endif
  for (; a < dim_; ++a) x[a] = std::int16_t(std::int16_t(v[a]) - mean_[a]);
  std::fill(x + dim_, x + padded_, std::int16_t(0));
  std::int64_t norm = 0;
  constexpr std::size_t kBlock = 8192;  // 8192 * 255^2 < 2^31
  for (std::size_t b = 0; b < padded_; b += kBlock) {
    std::int32_t sum = 0;
    for (std::size_t a = b, e = std::min(padded_, b + kBlock); a < e; ++a) sum += std::int32_t(x[a]) * x[a];
    norm += sum;
  }
  double kept = 0;
  for (std::size_t r = 0; r < reduced_; ++r) {
    const std::int16_t* row = basis_.data() + r * padded_;
#if defined(__SSE2__)
    __m128i acc = _mm_setzero_si128();
    for (std::size_t a = 0; a < padded_; a += 8)
      acc = _mm_add_epi32(acc, _mm_madd_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + a)),
                                              _mm_loadu_si128(reinterpret_cast<const __m128i*>(x + a))));
    acc = _mm_add_epi32(acc, _mm_shuffle_epi32(acc, _MM_SHUFFLE(1, 0, 3, 2)));
    acc = _mm_add_epi32(acc, _mm_shuffle_epi32(acc, _MM_SHUFFLE(2, 3, 0, 1)));
    const std::int32_t dot = _mm_cvtsi128_si32(acc);
#else
    std::int32_t dot = 0;
    for (std::size_t a = 0; a < padded_; ++a) dot += std::int32_t(row[a]) * x[a];
#endif
    const double y = double(dot) * scale_;
    out[r] = float(y);
    kept += y * y;
  }
  out[reduced_] = float(std::sqrt(std::max(double(norm) - kept, 0.0)));
}

std::size_t NeighborhoodIndex::tight_budget() const {
  return count_ / kTightShare > kTightBase ? count_ / kTightShare - kTightBase : 0;
}

std::uint32_t NeighborhoodIndex::squared_distance(const std::uint8_t* query, std::size_t i) const {
  const std::uint8_t* v = candidate(i);
  std::uint32_t d = 0;
  for (std::size_t a = 0; a < dim_; ++a) {
    const int t = int(query[a]) - int(v[a]);
    d += std::uint32_t(t * t);
  }
  return d;
}

NeighborhoodIndex::Match NeighborhoodIndex::brute_force(const std::uint8_t* query, Scratch& scratch) const {
  Match best;
  for (std::size_t i = 0; i < count_; ++i) {
    const std::uint32_t d = squared_distance(query, i);
    if (d < best.squared_distance) best = {std::uint32_t(i), d};  // first of equals: the smaller index
  }
  scratch.full_distances += count_;
  return best;
}

NeighborhoodIndex::Match NeighborhoodIndex::nearest(const std::uint8_t* query, NeighborSearch search, double eps,
                                                    Scratch& scratch) const {
  return nearest(query, search, eps, scratch, Match{});
}

NeighborhoodIndex::Match NeighborhoodIndex::nearest(const std::uint8_t* query, NeighborSearch search, double eps,
                                                    Scratch& scratch, Match start) const {
  if (search == NeighborSearch::brute) return brute_force(query, scratch);
  if (!tree_ && !fixed_tree_) throw Error("NeighborhoodIndex: exact and approx search need reduced_dimension > 0");
  if (search == NeighborSearch::exact) eps = 0;
  if (!(eps >= 0) || std::isinf(eps)) throw Error("NeighborhoodIndex: eps must be finite and >= 0");

  scratch.projected.resize(reduced_ + 1);
  project(query, scratch.projected.data(), scratch.centred);

  // The k-d tree's result policy (KdTree::search_nearest): every candidate the
  // descent reaches gets its full distance; the pruning bound is the best full
  // distance plus half a unit (full distances are integers), widened by the
  // float rounding of the tree coordinates (margin_) and of the tree's own
  // distance sums (a relative 1e-5, far above float's (dim + 2) 2^-24): so
  // rounding can never prune a candidate as near as the best, and the
  // (1 + eps) guarantee holds.
  //
  // The approximate search's schedule: the tree is searched with eps' = eps / 3
  // and prunes a subtree when its bound exceeds worst() / (1 + eps')^2, and
  // worst() is the best bound times ((1 + eps') / (1 + e))^2, which makes that
  // bound / (1 + e)^2, with e = eps / 12 during the tight start, eps' for the
  // next kStartDistances full distances, eps from then on. In the tight start
  // and the next distances worst() >= bound and insert() filters the leaf
  // points by the best bound itself (a point beyond it cannot be nearer); after
  // them the leaves' limit worst() skips points whose bound exceeds the best's
  // ((1 + eps') / (1 + eps))^2 >= 1 / (1 + eps)^2 times: none of them is nearer
  // than the best / (1 + eps), so the (1 + eps) guarantee holds.
  struct Refine {
    const NeighborhoodIndex& index;
    const std::uint8_t* query;
    std::size_t& evaluations;
    std::size_t tight_until;  // evaluations at which the tight start ends
    std::size_t start_until;  // evaluations at which the search relaxes to eps
    float widen;              // ((1 + eps') / (1 + eps / 12))^2, or 1
    float relax;              // ((1 + eps') / (1 + eps))^2, or 1
    Match best;
    float bound = std::numeric_limits<float>::infinity();
    bool full() const { return best.candidate != std::numeric_limits<std::uint32_t>::max(); }
    float worst() const {
      return evaluations < tight_until ? bound * widen : evaluations < start_until ? bound : bound * relax;
    }
    void insert(std::uint32_t i, float tree_distance) {
      if (tree_distance > bound) return;
      ++evaluations;
      const std::uint32_t d = index.squared_distance(query, i);
      if (Match{i, d}.before(best)) set(i, d);
    }
    void set(std::uint32_t i, std::uint32_t d) {
      best = {i, d};
      const double r = std::sqrt(double(d) + 0.5) + index.margin_;
      bound = float(r * r * (1 + 1e-5));
    }
  };
  const std::size_t budget = tight_budget();
  const double tight = eps / kTightEpsDivisor, middle = eps / kStartEpsDivisor;
  const bool tight_start = search == NeighborSearch::approx && budget > 0 && eps > 0;
  const std::size_t tight_until = tight_start ? scratch.full_distances + budget : 0;
  auto squared = [](double x) { return float(x * x); };
  Refine refine{*this,
                query,
                scratch.full_distances,
                tight_until,
                std::max(tight_until, scratch.full_distances) + kStartDistances,
                tight_start ? squared((1 + middle) / (1 + tight)) : 1.0f,
                squared((1 + middle) / (1 + eps)),
                {}};
  if (start.candidate < count_) refine.set(start.candidate, start.squared_distance);
  if (fixed_tree_)
    fixed_tree_->search_nearest(scratch.projected.data(), refine, middle);
  else
    tree_->search_nearest(scratch.projected.data(), refine, middle);
  return refine.best;
}

}  // namespace geods::texture
