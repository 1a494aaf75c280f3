// k-d tree build and k-NN query rates on 1M uniform 3D points (the knn workload
// of anchors/WORKLOADS.md, with points generated here).
#include <benchmark/benchmark.h>

#include <vector>

#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace {

using namespace geods;
using namespace geods::spatial;

const std::vector<float>& uniform_points(std::size_t n, std::uint64_t seed) {
  static std::vector<float> points, queries;
  std::vector<float>& v = seed == 1 ? points : queries;
  if (v.size() != 3 * n) {
    Rng rng(seed);
    v.resize(3 * n);
    for (float& x : v) x = float(rng.uniform());
  }
  return v;
}

constexpr std::size_t kPoints = 1000000, kQueries = 100000;

// Arg: threads (1, or 0 for all cores).
void BM_KdTreeBuild(benchmark::State& state) {
  const auto& p = uniform_points(kPoints, 1);
  set_num_threads(int(state.range(0)));
  for (auto _ : state) {
    const KdTree<float, 3> tree(PointView<float>(p.data(), kPoints, 3), 10);
    benchmark::DoNotOptimize(tree.nodes().data());
  }
  set_num_threads(0);
  state.SetItemsProcessed(std::int64_t(state.iterations() * kPoints));
}
BENCHMARK(BM_KdTreeBuild)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

// Args: k, eps * 10. One query at a time on one thread.
void BM_KdTreeKnn(benchmark::State& state) {
  const auto& p = uniform_points(kPoints, 1);
  const auto& q = uniform_points(kQueries, 2);
  const KdTree<float, 3> tree(PointView<float>(p.data(), kPoints, 3), 10);
  const KnnRequest request{std::size_t(state.range(0)), double(state.range(1)) / 10};
  std::vector<Neighbor<float>> out(request.k);
  std::size_t i = 0;
  for (auto _ : state) {
    tree.query_into(std::span<const float>(&q[3 * i], 3), request, out.data());
    benchmark::DoNotOptimize(out.data());
    if (++i == kQueries) i = 0;
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}
BENCHMARK(BM_KdTreeKnn)->Args({1, 0})->Args({10, 0})->Args({10, 5})->Args({100, 0});

// All cores: the batch of 100k queries.
void BM_KdTreeKnnBatch(benchmark::State& state) {
  const auto& p = uniform_points(kPoints, 1);
  const auto& q = uniform_points(kQueries, 2);
  const KdTree<float, 3> tree(PointView<float>(p.data(), kPoints, 3), 10);
  for (auto _ : state) {
    const auto result = tree.query_batch(PointView<float>(q.data(), kQueries, 3), KnnRequest{10});
    benchmark::DoNotOptimize(result.data());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations() * kQueries));
}
BENCHMARK(BM_KdTreeKnnBatch)->Unit(benchmark::kMillisecond)->UseRealTime();

// Range counting in 2D: boxes of about 1 % of the points.
void BM_KdTreeCountBox2d(benchmark::State& state) {
  const std::size_t n = kPoints;
  std::vector<double> p(2 * n);
  Rng rng(3);
  for (double& x : p) x = rng.uniform();
  const KdTree<double, 2> tree(PointView<double>(p.data(), n, 2), 10);
  std::size_t total = 0;
  for (auto _ : state) {
    const double x = rng.uniform(0, 0.9), y = rng.uniform(0, 0.9);
    const double lo[2] = {x, y}, hi[2] = {x + 0.1, y + 0.1};
    total += tree.count_box(lo, hi);
  }
  benchmark::DoNotOptimize(total);
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}
BENCHMARK(BM_KdTreeCountBox2d);

}  // namespace
