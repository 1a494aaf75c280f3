#pragma once
// The dynamic comparison: the same inputs, schedule and checks for every program; each program
// only supplies an adapter (compare_dynamic_*.cpp).
//
// Schedule (on the knn uniform points of anchors/WORKLOADS.md, single thread):
//   1. insert all n points (1M) in batches of 1000, in file order, so point i gets id i;
//      after every 100k inserts, 10k k = 10 queries (the first 10k of knn_uniform_queries.f32);
//   2. delete a random half (SplitMix64 seed 42 permutation, the first n/2), in batches of 1000;
//   3. the same 10k queries once more ("final" queries): checked and checksummed.
// Timed separately: insert_s (all insert batches), delete_s (all delete batches), query_s (all
// query rounds, 11 x 10k); count = queries. worst_batch_s (and _ms) = slowest insert batch
// (with the prepare() that follows it, i.e. a static rebuild).
// Adapters that can insert one point at a time cheaply also run a latency pass: a fresh
// structure, the first 2^18 points inserted one by one, each timed: max_insert_s (and _us), mean_insert_us.
// Check ("ok"): every 500th final query against brute force over the live points in double
// (distances to 1e-5 relative, every returned id live); "checksum": FNV-1a of every final
// query's neighbour ids sorted ascending (equal across programs: same neighbours).
//
// Adapter (struct Lib):
//   static constexpr const char* anchor;
//   static constexpr bool single_insert;                       run the latency pass
//   struct State; explicit State(const float* all_points, std::size_t n);
//   void insert(std::size_t first, std::size_t count);        points [first, first + count)
//   void remove(const std::uint32_t* ids, std::size_t count);
//   void prepare();        before a query round; a static rebuild happens here (timed as insert/delete)
//   void knn(const float* q, std::size_t k, std::uint32_t* ids, float* squared_distances) const;
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "common.hpp"

namespace compare::dynamic {

inline constexpr std::size_t kK = 10;
inline constexpr std::size_t kBatch = 1000;
inline constexpr std::size_t kQueryEvery = 100000;
inline constexpr std::size_t kQueries = 10000;
inline constexpr std::size_t kLatencyPoints = std::size_t(1) << 18;

inline double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <class Lib>
void run_uniform(const Args& args) {
  std::vector<float> points = read_raw<float>(args.path("knn_uniform_points.f32"));
  std::vector<float> queries = read_raw<float>(args.path("knn_uniform_queries.f32"));
  const std::size_t n = std::min(points.size() / 3, args.scaled(points.size() / 3));
  const std::size_t m = std::min(queries.size() / 3, args.scaled(kQueries));
  const std::size_t every = std::max<std::size_t>(kBatch, args.scaled(kQueryEvery));
  points.resize(3 * n);
  queries.resize(3 * m);

  // The deletions: the first half of a seeded permutation, identical in every program.
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  SplitMix64 rng(42);
  for (std::size_t i = n; i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
  const std::size_t n_delete = n / 2;
  std::vector<char> live(n, 1);
  for (std::size_t i = 0; i < n_delete; ++i) live[order[i]] = 0;

  std::vector<std::uint32_t> ids(m * kK);
  std::vector<float> dist(m * kK);
  double insert_s = 0, delete_s = 0, query_s = 0, worst_batch_s = 0;
  std::size_t query_count = 0;

  std::unique_ptr<typename Lib::State> state = std::make_unique<typename Lib::State>(points.data(), n);
  auto round = [&] {
    const double t0 = now_s();
    for (std::size_t i = 0; i < m; ++i) state->knn(&queries[3 * i], kK, &ids[i * kK], &dist[i * kK]);
    query_s += now_s() - t0;
    query_count += m;
  };
  for (std::size_t first = 0; first < n; first += kBatch) {
    const std::size_t count = std::min(kBatch, n - first);
    const double t0 = now_s();
    state->insert(first, count);
    double dt = now_s() - t0;
    if ((first + count) % every == 0 || first + count == n) {
      const double t1 = now_s();
      state->prepare();  // a static rebuild makes the inserts visible here: part of the insert cost
      dt += now_s() - t1;  // and of this batch's latency
      insert_s += dt;
      worst_batch_s = std::max(worst_batch_s, dt);
      round();
    } else {
      insert_s += dt;
      worst_batch_s = std::max(worst_batch_s, dt);
    }
  }
  for (std::size_t first = 0; first < n_delete; first += kBatch) {
    const std::size_t count = std::min(kBatch, n_delete - first);
    const double t0 = now_s();
    state->remove(&order[first], count);
    delete_s += now_s() - t0;
  }
  {
    const double t0 = now_s();
    state->prepare();
    delete_s += now_s() - t0;
  }
  round();  // the final queries, left in ids / dist

  bool ok = true;
  std::vector<double> brute;
  for (std::size_t i = 0; i < m; i += 500) {
    const float* q = &queries[3 * i];
    brute.clear();
    for (std::size_t j = 0; j < n; ++j) {
      if (!live[j]) continue;
      double s = 0;
      for (int a = 0; a < 3; ++a) s += (double(points[3 * j + a]) - q[a]) * (double(points[3 * j + a]) - q[a]);
      brute.push_back(s);
    }
    const std::size_t kk = std::min(kK, brute.size());
    std::partial_sort(brute.begin(), brute.begin() + kk, brute.end());
    for (std::size_t r = 0; r < kk; ++r) {
      const std::uint32_t j = ids[i * kK + r];
      if (j >= n || !live[j]) {
        ok = false;
        break;
      }
      double s = 0;
      for (int a = 0; a < 3; ++a) s += (double(points[3 * j + a]) - q[a]) * (double(points[3 * j + a]) - q[a]);
      if (std::abs(std::sqrt(s) - std::sqrt(brute[r])) > 1e-5 * std::max(1.0, std::sqrt(brute[r]))) ok = false;
    }
  }
  const std::uint64_t checksum = neighbour_checksum<kK>(ids.data(), m);
  state.reset();

  Record rec("dynamic", Lib::anchor, "uniform", args.threads);
  rec.set("insert_s", insert_s)
      .set("delete_s", delete_s)
      .set("query_s", query_s)
      .set("count", static_cast<unsigned long long>(query_count))
      .set("median_of", 1)
      .set("points", static_cast<unsigned long long>(n))
      .set("deleted", static_cast<unsigned long long>(n_delete))
      .set("insert_mps", n / insert_s * 1e-6)
      .set("delete_mps", n_delete / delete_s * 1e-6)
      .set("query_mqs", query_count / query_s * 1e-6)
      .set("worst_batch_s", worst_batch_s)
      .set("worst_batch_ms", worst_batch_s * 1e3);
  if constexpr (Lib::single_insert) {
    const std::size_t p = std::min(n, args.scaled(kLatencyPoints));
    auto fresh = std::make_unique<typename Lib::State>(points.data(), n);
    double worst = 0, total = 0;
    for (std::size_t i = 0; i < p; ++i) {
      const double t0 = now_s();
      fresh->insert(i, 1);
      const double dt = now_s() - t0;
      worst = std::max(worst, dt);
      total += dt;
    }
    rec.set("latency_points", static_cast<unsigned long long>(p))
        .set("max_insert_s", worst)
        .set("max_insert_us", worst * 1e6)
        .set("mean_insert_us", total / p * 1e6);
  }
  rec.set("checksum", hex64(checksum)).print(ok);
}

template <class Lib>
int run(int argc, char** argv) {
  return run_variants(argc, argv, {"uniform"}, [](const Args& args, const char*) { run_uniform<Lib>(args); });
}

}  // namespace compare::dynamic
