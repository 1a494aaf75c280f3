#pragma once
// The nearest-neighbour search of texture synthesis (seed §5.5: line 2 of the
// loop "is exactly a nearest-neighbor search"): the candidate neighbourhoods
// of a sample, and for a query neighbourhood the candidate nearest to it in
// Euclidean distance, ties broken by the smaller candidate index.
//
// Distances are between 8-bit vectors, so squared distances are exact
// integers and every method agrees bit for bit on what "nearest" means.
//
// - brute: every candidate (the reference).
// - exact: a k-d tree (spatial::KdTree) over the candidates projected on
//   their first principal components, plus one coordinate: the norm of the
//   residual (the part of the centred vector the components leave out). The
//   projection is orthonormal and | |Rq| - |Rc| | <= |R(q - c)|, so the
//   distance in the tree is a lower bound of the full one: the descent computes
//   the full distance of each leaf candidate it reaches and prunes by the best
//   full distance so far. The answer is brute force's, candidate for candidate.
// - approx: the same descent with the k-d tree's (1 + eps) pruning: a subtree
//   is skipped when its projected lower bound exceeds best / (1 + eps), so the
//   distance found is within (1 + eps) of the nearest, in the full space.
//   Its eps grows with the query's work (a schedule): the descent prunes with
//   eps / 12 until the query has computed tight_budget() full distances (the
//   "tight start"), a share of a brute-force scan that grows with the
//   candidates (1/256 of them, less 16: none up to 4096 candidates), then
//   with eps / 3 for kStartDistances more, and with eps from then on. A query
//   that finishes within its budget is within (1 + eps / 12) of the nearest,
//   one that finishes within kStartDistances more within (1 + eps / 3), every
//   query within (1 + eps). The first full distances find a near match, and
//   the rest of the descent, which on noise-like samples visits many leaves
//   for little gain, is pruned harder. Where brute force is dear, part of the
//   saving buys nearer matches, which matter because synthesis compounds
//   them: a match a few per cent worse makes the next pixels' neighbourhoods
//   worse too (docs/texture.md).
//   Few principal components make the tree shallow and the bound loose (more
//   full distances); many make the tree slow in high dimension. This is the
//   role of Wei and Levoy's PCA-reduced tree-structured vector quantization,
//   with a guarantee.
//
// The projection is computed in exact integer arithmetic: the principal
// directions are rounded to 16-bit integers (B), the vectors centred on the
// rounded mean m, and the tree coordinates are B (v - m) / s, with s an upper
// bound of B's largest singular value (Gershgorin on B B^T), so the map has
// norm <= 1, plus the residual sqrt(|v - m|^2 - |B (v - m) / s|^2). Both
// bounds above hold for any such map, so the rounded basis costs nothing in
// correctness, and a query's projection is a few 16-bit multiply-adds per
// value. The tree holds the coordinates rounded to float (half the memory of
// doubles, faster leaves); the search widens its bound by the rounding, which
// is at most |v - m| 2^-24 per point. With the default 8 components the tree
// has a compile-time dimension of 9.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string_view>
#include <vector>

#include "geods/spatial/kd_tree.hpp"

namespace geods::texture {

enum class NeighborSearch { brute, exact, approx };

/// Parses "brute", "exact" or "approx"; throws geods::Error naming the choices.
NeighborSearch parse_neighbor_search(std::string_view name);
std::string_view neighbor_search_name(NeighborSearch search);

struct NeighborhoodIndexStats {
  std::size_t candidates = 0;
  std::size_t dimension = 0;          // values per neighbourhood
  std::size_t reduced_dimension = 0;  // principal components in the k-d tree (0: brute force only)
  double explained_variance = 0;      // fraction of the candidates' variance the components keep
  std::size_t bytes = 0;
};

class NeighborhoodIndex {
 public:
  struct Match {
    std::uint32_t candidate = std::numeric_limits<std::uint32_t>::max();
    std::uint32_t squared_distance = std::numeric_limits<std::uint32_t>::max();
    /// The order of "nearest": smaller distance, then smaller candidate index.
    bool before(const Match& o) const {
      return squared_distance < o.squared_distance || (squared_distance == o.squared_distance && candidate < o.candidate);
    }
  };

  /// `vectors` holds the candidates row by row, `dimension` values each
  /// (dimension * 255^2 < 2^32). reduced_dimension: principal components the
  /// k-d tree uses (clamped to the dimension); 0 builds no tree (brute force
  /// only). Throws geods::Error for no candidates or a bad dimension.
  NeighborhoodIndex(std::vector<std::uint8_t> vectors, std::size_t dimension, std::size_t reduced_dimension);

  std::size_t size() const { return count_; }
  std::size_t dimension() const { return dim_; }
  std::size_t reduced_dimension() const { return reduced_; }
  const std::uint8_t* candidate(std::size_t i) const { return vectors_.data() + i * dim_; }
  NeighborhoodIndexStats stats() const;

  /// Full distances an approximate query computes with eps / 12 before it relaxes to eps / 3 (see above).
  std::size_t tight_budget() const;
  /// Full distances an approximate query computes with eps / 3, after its tight budget, before it relaxes to eps.
  static constexpr std::size_t kStartDistances = 8;

  /// The exact squared distance of a query to candidate i.
  std::uint32_t squared_distance(const std::uint8_t* query, std::size_t i) const;

  /// Per-thread buffers of nearest(), reused across queries.
  struct Scratch {
    std::vector<float> projected;
    std::vector<std::int16_t> centred;
    std::size_t full_distances = 0;  // full distances computed, summed over queries
  };

  /// The candidate nearest to `query` (dimension() values). eps >= 0 is used by
  /// approx only. exact/approx need a tree (reduced_dimension > 0).
  /// `start`, if it names a candidate, is a known match (with its exact
  /// squared distance) the tree search starts from: a good one prunes from
  /// the first node on. The guarantees are the same: exact finds brute
  /// force's candidate, approx one within (1 + eps) of the nearest.
  Match nearest(const std::uint8_t* query, NeighborSearch search, double eps, Scratch& scratch, Match start) const;
  Match nearest(const std::uint8_t* query, NeighborSearch search, double eps, Scratch& scratch) const;

 private:
  Match brute_force(const std::uint8_t* query, Scratch& scratch) const;
  // The coordinates of v (dimension() values) on the principal directions: reduced_dimension() values.
  // Candidates and queries go through this one computation, so equal vectors project bit-identically.
  void project(const std::uint8_t* v, float* out, std::vector<std::int16_t>& centred) const;

  std::vector<std::uint8_t> vectors_;
  std::size_t count_ = 0, dim_ = 0, reduced_ = 0;
  double explained_ = 0;
  std::size_t padded_ = 0;          // dim_ rounded up to a multiple of 8 (the integer rows' stride)
  std::vector<std::int16_t> mean_;  // padded_: the candidates' mean, rounded (0 in the padding)
  std::vector<std::int16_t> basis_; // reduced_ rows of padded_: the principal directions, rounded to integers
  double scale_ = 0;                // tree coordinate = (basis row . (v - mean)) * scale_
  // count_ rows of reduced_ + 1 (the components, the residual norm), rounded to float: the searches
  // widen their bound by the rounding (margin_), see nearest().
  std::vector<float> projected_;
  double margin_ = 0;
  static constexpr std::size_t kFixedTreeDim = 9;  // 8 components (the synthesis' default) and the residual
  std::unique_ptr<spatial::KdTree<float>> tree_;
  std::unique_ptr<spatial::KdTree<float, int(kFixedTreeDim)>> fixed_tree_;
};

}  // namespace geods::texture
