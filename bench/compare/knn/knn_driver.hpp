#pragma once
// The knn comparison: the same inputs, timing loop and checks for every library;
// each program only supplies an adapter (see compare_knn_*.cpp).
//
// Workload (anchors/WORKLOADS.md): a k-d tree over 1M float32 3D points with leaf size 10,
// then 100k queries with k = 10, one query at a time. Variants `uniform` and `clustered`
// (knn_<variant>_points.f32 / knn_<variant>_queries.f32). With --threads N > 1 the queries
// are split over N threads with tbb::parallel_for (each query still one at a time), and the
// build uses whatever parallelism the library has (nanoflann 1.4: none).
// Sanity ("ok"): 200 queries (every 500th) compared with brute force in double: the k
// distances match to 1e-5 (relative). "checksum": FNV-1a of every query's neighbour indices
// sorted ascending, so run.py can check that the libraries find the same neighbours.
//
// Adapter interface (struct Lib):
//   static constexpr const char* anchor;
//   struct Index;                                    the built structure
//   static std::unique_ptr<Index> build(const float* points, std::size_t n, std::size_t leaf_size);
//   static void knn(const Index&, const float* q, std::size_t k, std::uint32_t* indices, float* squared_distances);
//       the k nearest, ascending
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common.hpp"

namespace compare::knn {

inline constexpr std::size_t kLeafSize = 10;
inline constexpr std::size_t kK = 10;

template <class Lib>
void run_variant(const Args& args, const std::string& variant) {
  std::vector<float> points = read_raw<float>(args.path("knn_" + variant + "_points.f32"));
  std::vector<float> queries = read_raw<float>(args.path("knn_" + variant + "_queries.f32"));
  const std::size_t n = std::min(points.size() / 3, args.scaled(points.size() / 3));
  const std::size_t m = std::min(queries.size() / 3, args.scaled(queries.size() / 3));
  points.resize(3 * n);
  queries.resize(3 * m);

  std::vector<std::uint32_t> indices(m * kK);
  std::vector<float> distances(m * kK);
  std::unique_ptr<typename Lib::Index> index;
  const double build_s = median_time_s(args.reps, [&] {
    index.reset();
    index = Lib::build(points.data(), n, kLeafSize);
  });
  auto query_all = [&] {
    auto body = [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) Lib::knn(*index, &queries[3 * i], kK, &indices[i * kK], &distances[i * kK]);
    };
    if (args.threads == 1) {
      body(0, m);
    } else {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 256),
                        [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
    }
  };
  const double query_s = median_time_s(args.reps, query_all);

  bool ok = true;
  std::vector<double> brute(n);
  for (std::size_t i = 0; i < m; i += 500) {
    const float* q = &queries[3 * i];
    for (std::size_t j = 0; j < n; ++j) {
      double s = 0;
      for (int a = 0; a < 3; ++a) s += (double(points[3 * j + a]) - q[a]) * (double(points[3 * j + a]) - q[a]);
      brute[j] = s;
    }
    std::partial_sort(brute.begin(), brute.begin() + kK, brute.end());
    for (std::size_t r = 0; r < kK; ++r) {
      const std::uint32_t j = indices[i * kK + r];
      if (j >= n) {
        ok = false;
        break;
      }
      double s = 0;
      for (int a = 0; a < 3; ++a) s += (double(points[3 * j + a]) - q[a]) * (double(points[3 * j + a]) - q[a]);
      if (std::abs(std::sqrt(s) - std::sqrt(brute[r])) > 1e-5 * std::max(1.0, std::sqrt(brute[r]))) ok = false;
    }
  }
  const std::uint64_t checksum = neighbour_checksum<kK>(indices.data(), m);
  Record("knn", Lib::anchor, variant, args.threads)
      .timing(build_s, query_s, m, args.reps)
      .set("points", static_cast<unsigned long long>(n))
      .set("k", static_cast<unsigned long long>(kK))
      .set("leaf_size", static_cast<unsigned long long>(kLeafSize))
      .set("checksum", hex64(checksum))
      .print(ok);
}

template <class Lib>
int run(int argc, char** argv) {
  return run_variants(argc, argv, {"uniform", "clustered"}, run_variant<Lib>);
}

}  // namespace compare::knn
