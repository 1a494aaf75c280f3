#include "geods/texture/neighborhood_index.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::texture {
namespace {

// The covariance is estimated from at most this many candidates, evenly
// spread: the principal directions only need to be good, not exact (the
// searches stay exact whatever the basis, as long as it is orthonormal).
constexpr std::size_t kCovarianceSamples = 2048;
// Candidates per k-d tree leaf: smaller leaves mean fewer full distances and
// a longer descent. 8 is about 5 % faster than 10 and 16 at an error within
// the spread over seeds; 4 is faster still, but its matches are 4 % worse.
constexpr std::size_t kLeafSize = 8;

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
  mean_.assign(mean.data(), mean.data() + dim_);
  basis_.resize(reduced_ * dim_);
  double kept = 0;
  for (std::size_t r = 0; r < reduced_; ++r) {
    const Eigen::Index column = Eigen::Index(dim_ - 1 - r);
    kept += std::max(values(column), 0.0);
    for (std::size_t a = 0; a < dim_; ++a) basis_[a * reduced_ + r] = solver.eigenvectors()(Eigen::Index(a), column);
  }
  explained_ = total > 0 ? kept / total : 1;

  const std::size_t tree_dim = reduced_ + 1;
  projected_.resize(count_ * tree_dim);
  parallel_for(0, count_, 64, [&](std::size_t begin, std::size_t end) {
    std::vector<double> centred;
    for (std::size_t i = begin; i < end; ++i) project(candidate(i), projected_.data() + i * tree_dim, centred);
  });
  tree_ = std::make_unique<spatial::KdTree<double>>(spatial::PointView<double>(projected_.data(), count_, tree_dim),
                                                     kLeafSize);
}

NeighborhoodIndexStats NeighborhoodIndex::stats() const {
  NeighborhoodIndexStats s;
  s.candidates = count_;
  s.dimension = dim_;
  s.reduced_dimension = reduced_;
  s.explained_variance = explained_;
  s.bytes = vectors_.size() + (mean_.size() + basis_.size() + projected_.size()) * sizeof(double);
  if (tree_) s.bytes += tree_->stats().bytes;
  return s;
}

void NeighborhoodIndex::project(const std::uint8_t* v, double* out, std::vector<double>& centred) const {
  // Eigen's vectorized kernels: basis_ holds one column of reduced_ component
  // weights per value, so the product sums whole columns at once.
  centred.resize(dim_);
  Eigen::Map<Eigen::VectorXd> c(centred.data(), Eigen::Index(dim_));
  c = Eigen::Map<const Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 1>>(v, Eigen::Index(dim_)).cast<double>() -
      Eigen::Map<const Eigen::VectorXd>(mean_.data(), Eigen::Index(dim_));
  Eigen::Map<Eigen::VectorXd> components(out, Eigen::Index(reduced_));
  components.noalias() = Eigen::Map<const Eigen::MatrixXd>(basis_.data(), Eigen::Index(reduced_), Eigen::Index(dim_)) * c;
  out[reduced_] = std::sqrt(std::max(c.squaredNorm() - components.squaredNorm(), 0.0));
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
  if (!tree_) throw Error("NeighborhoodIndex: exact and approx search need reduced_dimension > 0");
  if (search == NeighborSearch::exact) eps = 0;
  if (!(eps >= 0) || std::isinf(eps)) throw Error("NeighborhoodIndex: eps must be finite and >= 0");

  scratch.projected.resize(reduced_ + 1);
  project(query, scratch.projected.data(), scratch.centred);

  // The k-d tree's result policy (KdTree::search_nearest): every candidate the
  // descent reaches gets its full distance; the pruning bound is the best full
  // distance plus half a unit: full distances are integers, so rounding in the
  // projection can never prune a candidate as near as the best, and the
  // (1 + eps) guarantee still holds.
  struct Refine {
    const NeighborhoodIndex& index;
    const std::uint8_t* query;
    std::size_t& evaluations;
    Match best;
    double bound = std::numeric_limits<double>::infinity();
    bool full() const { return best.candidate != std::numeric_limits<std::uint32_t>::max(); }
    double worst() const { return bound; }
    void insert(std::uint32_t i, double) {
      ++evaluations;
      const std::uint32_t d = index.squared_distance(query, i);
      if (Match{i, d}.before(best)) set(i, d);
    }
    void set(std::uint32_t i, std::uint32_t d) {
      best = {i, d};
      bound = double(d) + 0.5;
    }
  } refine{*this, query, scratch.full_distances, {}};
  if (start.candidate < count_) refine.set(start.candidate, start.squared_distance);
  tree_->search_nearest(scratch.projected.data(), refine, eps);
  return refine.best;
}

}  // namespace geods::texture
