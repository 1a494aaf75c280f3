// The neighbourhood searches against brute force: exact gives the same
// candidate (ties by index), approx stays within (1 + eps).
#include <gtest/gtest.h>

#include <cmath>

#include "geods/core/rng.hpp"
#include "geods/texture/neighborhood.hpp"
#include "geods/texture/neighborhood_index.hpp"

namespace geods::texture {
namespace {

// Clustered vectors with many exact duplicates, so that ties are common.
std::vector<std::uint8_t> clustered(std::size_t n, std::size_t dim, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<std::uint8_t> centres(8 * dim);
  for (auto& v : centres) v = std::uint8_t(rng.below(256));
  std::vector<std::uint8_t> out(n * dim);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = rng.below(8);
    const int spread = rng.below(3) == 0 ? 0 : 12;
    for (std::size_t a = 0; a < dim; ++a) {
      const int v = int(centres[c * dim + a]) + (spread ? int(rng.below(2 * spread + 1)) - spread : 0);
      out[i * dim + a] = std::uint8_t(std::clamp(v, 0, 255));
    }
  }
  return out;
}

std::uint32_t brute_distance(const std::uint8_t* a, const std::uint8_t* b, std::size_t dim) {
  std::uint32_t d = 0;
  for (std::size_t i = 0; i < dim; ++i) d += std::uint32_t((int(a[i]) - int(b[i])) * (int(a[i]) - int(b[i])));
  return d;
}

TEST(NeighborhoodIndex, ExactEqualsBruteForceCandidateForCandidate) {
  for (const std::size_t dim : {3u, 40u, 195u}) {
    const std::size_t n = 700;
    const auto vectors = clustered(n, dim, dim);
    const auto queries = clustered(300, dim, dim + 1000);
    for (const std::size_t reduced : {1u, 8u, 16u}) {
      const NeighborhoodIndex index(vectors, dim, reduced);
      NeighborhoodIndex::Scratch scratch;
      for (std::size_t q = 0; q < 300; ++q) {
        const std::uint8_t* query = queries.data() + q * dim;
        // Oracle: the smallest (distance, index), written out here.
        std::uint32_t best = 0, best_d = brute_distance(query, vectors.data(), dim);
        for (std::size_t i = 1; i < n; ++i) {
          const std::uint32_t d = brute_distance(query, vectors.data() + i * dim, dim);
          if (d < best_d) best = std::uint32_t(i), best_d = d;
        }
        const auto brute = index.nearest(query, NeighborSearch::brute, 0, scratch);
        const auto exact = index.nearest(query, NeighborSearch::exact, 0, scratch);
        ASSERT_EQ(brute.candidate, best);
        ASSERT_EQ(brute.squared_distance, best_d);
        ASSERT_EQ(exact.candidate, best) << "dim " << dim << " reduced " << reduced << " query " << q;
        ASSERT_EQ(exact.squared_distance, best_d);
      }
    }
  }
}

TEST(NeighborhoodIndex, QueriesEqualToACandidateFindTheFirstCopy) {
  const std::size_t dim = 24;
  auto vectors = clustered(400, dim, 3);
  const NeighborhoodIndex index(vectors, dim, 6);
  NeighborhoodIndex::Scratch scratch;
  for (std::size_t i = 0; i < 400; ++i) {
    std::size_t first = i;
    for (std::size_t j = 0; j < i; ++j)
      if (std::equal(vectors.begin() + std::ptrdiff_t(j * dim), vectors.begin() + std::ptrdiff_t((j + 1) * dim),
                     vectors.begin() + std::ptrdiff_t(i * dim))) {
        first = j;
        break;
      }
    const auto m = index.nearest(vectors.data() + i * dim, NeighborSearch::exact, 0, scratch);
    EXPECT_EQ(m.squared_distance, 0u);
    EXPECT_EQ(m.candidate, first);
  }
}

TEST(NeighborhoodIndex, ApproxIsWithinOnePlusEpsOfTheNearest) {
  const std::size_t dim = 65;
  const auto vectors = clustered(2000, dim, 11);
  const auto queries = clustered(400, dim, 12);
  const NeighborhoodIndex index(vectors, dim, 12);
  NeighborhoodIndex::Scratch exact_scratch, approx_scratch;
  for (const double eps : {0.1, 0.5, 2.0}) {
    for (std::size_t q = 0; q < 400; ++q) {
      const std::uint8_t* query = queries.data() + q * dim;
      const auto exact = index.nearest(query, NeighborSearch::brute, 0, exact_scratch);
      const auto approx = index.nearest(query, NeighborSearch::approx, eps, approx_scratch);
      ASSERT_EQ(approx.squared_distance, index.squared_distance(query, approx.candidate));
      ASSERT_LE(std::sqrt(double(approx.squared_distance)), (1 + eps) * std::sqrt(double(exact.squared_distance)) + 1e-9);
    }
  }
  // The approximation saves work: fewer full distances than the exact search.
  NeighborhoodIndex::Scratch exact_tree, approx_tree;
  for (std::size_t q = 0; q < 400; ++q) {
    index.nearest(queries.data() + q * dim, NeighborSearch::exact, 0, exact_tree);
    index.nearest(queries.data() + q * dim, NeighborSearch::approx, 2.0, approx_tree);
  }
  EXPECT_LT(approx_tree.full_distances, exact_tree.full_distances);
  EXPECT_LT(exact_tree.full_distances, 400u * 2000u);
}

TEST(NeighborhoodIndex, TheScheduleOfTheApproximateSearch) {
  // An approximate query prunes with eps / 12 for its first tight_budget() full
  // distances (over 4096 candidates; none below), with eps / 3 for
  // kStartDistances more, then with eps: one that finishes within its tight
  // budget is within (1 + eps / 12) of brute force's nearest, one that
  // finishes within kStartDistances more within (1 + eps / 3), every one within
  // (1 + eps). On neighbourhood-like vectors (65 values, queries near
  // candidates) and on uniform 3-vectors, where a (1 + eps) answer may be far
  // worse than the nearest; on a large set and a small one.
  for (const std::size_t n : {8192u, 2000u}) {
    for (const std::size_t dim : {65u, 3u}) {
      std::vector<std::uint8_t> vectors = clustered(n, dim, 31), queries(300 * dim);
      Rng rng(32);
      if (dim == 3)
        for (auto& v : vectors) v = std::uint8_t(rng.below(256));
      for (std::size_t q = 0; q < 300; ++q) {
        const std::size_t c = rng.below(n);
        for (std::size_t a = 0; a < dim; ++a)
          queries[q * dim + a] = dim == 3 ? std::uint8_t(rng.below(256))
                                          : std::uint8_t(std::clamp(int(vectors[c * dim + a]) + int(rng.below(41)) - 20, 0, 255));
      }
      const NeighborhoodIndex index(vectors, dim, 8);
      EXPECT_EQ(index.tight_budget(), n > 4096 ? n / 256 - 16 : 0);
      NeighborhoodIndex::Scratch scratch;
      std::size_t tight = 0, start = 0, beyond = 0;
      for (const double eps : {4.0, 8.0, 24.0, 40.0}) {
        for (std::size_t q = 0; q < 300; ++q) {
          const std::uint8_t* query = queries.data() + q * dim;
          const double nearest =
              std::sqrt(double(index.nearest(query, NeighborSearch::brute, 0, scratch).squared_distance));
          const std::size_t before = scratch.full_distances;
          const auto approx = index.nearest(query, NeighborSearch::approx, eps, scratch);
          const double found = std::sqrt(double(approx.squared_distance));
          const std::size_t work = scratch.full_distances - before;
          ASSERT_EQ(approx.squared_distance, index.squared_distance(query, approx.candidate));
          ASSERT_LE(found, (1 + eps) * nearest + 1e-9) << "dim " << dim << " query " << q;
          if (work < index.tight_budget()) {
            ++tight;
            ASSERT_LE(found, (1 + eps / 12) * nearest + 1e-9) << "dim " << dim << " query " << q << " eps " << eps;
          } else if (work < index.tight_budget() + NeighborhoodIndex::kStartDistances) {
            ++start;
            ASSERT_LE(found, (1 + eps / 3) * nearest + 1e-9) << "dim " << dim << " query " << q << " eps " << eps;
          } else {
            ++beyond;
          }
        }
      }
      if (n > 4096) {
        EXPECT_GT(tight, 100u) << "dim " << dim;
      }
      EXPECT_GT(start + tight, 100u) << "n " << n << " dim " << dim;
      if (dim == 65) {
        EXPECT_GT(beyond, 0u) << "n " << n;  // neighbourhoods use up the schedule on some queries
      }
    }
  }
  EXPECT_EQ(NeighborhoodIndex(clustered(4096, 65, 33), 65, 8).tight_budget(), 0u);
}

TEST(NeighborhoodIndex, AStartingMatchKeepsTheGuarantees) {
  // From any start (a random candidate, or brute force's answer itself), exact
  // still ends at brute force's candidate and approx within (1 + eps) of it.
  const std::size_t dim = 40;
  const auto vectors = clustered(1500, dim, 21);
  const auto queries = clustered(300, dim, 22);
  const NeighborhoodIndex index(vectors, dim, 8);
  NeighborhoodIndex::Scratch scratch;
  Rng rng(23);
  for (std::size_t q = 0; q < 300; ++q) {
    const std::uint8_t* query = queries.data() + q * dim;
    const auto brute = index.nearest(query, NeighborSearch::brute, 0, scratch);
    const auto i = std::uint32_t(rng.below(1500));
    for (const NeighborhoodIndex::Match start : {NeighborhoodIndex::Match{i, index.squared_distance(query, i)}, brute}) {
      const auto exact = index.nearest(query, NeighborSearch::exact, 0, scratch, start);
      ASSERT_EQ(exact.candidate, brute.candidate) << "query " << q;
      for (const double eps : {0.5, 8.0}) {
        const auto approx = index.nearest(query, NeighborSearch::approx, eps, scratch, start);
        ASSERT_EQ(approx.squared_distance, index.squared_distance(query, approx.candidate));
        ASSERT_LE(std::sqrt(double(approx.squared_distance)),
                  (1 + eps) * std::sqrt(double(brute.squared_distance)) + 1e-9);
      }
    }
  }
}

TEST(NeighborhoodIndex, StatsAndBadInput) {
  const NeighborhoodIndex index(clustered(100, 10, 1), 10, 40);
  const auto s = index.stats();
  EXPECT_EQ(s.candidates, 100u);
  EXPECT_EQ(s.dimension, 10u);
  EXPECT_EQ(s.reduced_dimension, 10u);  // clamped to the dimension
  EXPECT_NEAR(s.explained_variance, 1.0, 1e-9);
  EXPECT_GT(s.bytes, 1000u);
  EXPECT_THROW(NeighborhoodIndex({}, 10, 4), Error);
  EXPECT_THROW(NeighborhoodIndex(std::vector<std::uint8_t>(15), 10, 4), Error);
  EXPECT_THROW(NeighborhoodIndex(std::vector<std::uint8_t>(15), 0, 4), Error);
  NeighborhoodIndex::Scratch scratch;
  const NeighborhoodIndex brute_only(clustered(10, 4, 2), 4, 0);
  std::uint8_t q[4] = {1, 2, 3, 4};
  EXPECT_THROW(brute_only.nearest(q, NeighborSearch::exact, 0, scratch), Error);
  EXPECT_THROW(index.nearest(clustered(1, 10, 3).data(), NeighborSearch::approx, -1, scratch), Error);
  EXPECT_EQ(parse_neighbor_search("approx"), NeighborSearch::approx);
  EXPECT_EQ(neighbor_search_name(parse_neighbor_search("exact")), "exact");
  EXPECT_THROW(parse_neighbor_search("kdtree"), Error);
}

TEST(NeighborhoodShape, CausalWindowHoldsThePixelsBeforeTheCentre) {
  const NeighborhoodShape s = NeighborhoodShape::make(9, 5, true);
  EXPECT_EQ(s.fine.size(), 40u);  // 4 rows of 9, and 4 to the left
  EXPECT_EQ(s.parent.size(), 25u);
  EXPECT_EQ(s.dimension(3), 195u);
  for (const Offset o : s.fine) EXPECT_TRUE(o.dy < 0 || (o.dy == 0 && o.dx < 0));
  const NeighborhoodShape full = NeighborhoodShape::make(5, 0, false);
  EXPECT_EQ(full.fine.size(), 24u);
  EXPECT_TRUE(full.parent.empty());
  EXPECT_THROW(NeighborhoodShape::make(4, 0, true), Error);
  EXPECT_THROW(NeighborhoodShape::make(1, 0, true), Error);
  EXPECT_THROW(NeighborhoodShape::make(5, 2, true), Error);
}

}  // namespace
}  // namespace geods::texture
