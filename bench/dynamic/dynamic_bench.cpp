// Dyn(k-d) micro benchmarks: insert / delete / query throughput of both
// variants against rebuilding a static k-d tree from scratch, and the worst
// single-insert and single-delete latency of each variant (counters
// max_insert_us, mean_insert_us, max_delete_us, mean_delete_us, in thread CPU
// time, so that being preempted by other processes does not count), with the
// largest work count (DynamizedStats::work, element visits) one delete paid.
//   geods_dynamic_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <numeric>
#include <vector>

#include "geods/core/rng.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace {

using namespace geods;
using Tree = dynamic::DynamicKdTree<float, 3>;

double thread_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::vector<Tree::Point> uniform_points(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Tree::Point> points(n);
  for (auto& p : points) p = {float(rng.uniform()), float(rng.uniform()), float(rng.uniform())};
  return points;
}

dynamic::Variant variant_of(const benchmark::State& state) {
  return state.range(1) ? dynamic::Variant::worst_case : dynamic::Variant::amortized;
}

// n inserts one at a time into an empty tree; the slowest single insert is the worst-case latency.
void BM_Insert(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const auto points = uniform_points(n, 1);
  double worst = 0, total = 0;
  for (auto _ : state) {
    Tree tree(dynamic::DynamizeOptions{variant_of(state)});
    for (const auto& p : points) {
      const double start = thread_seconds();
      benchmark::DoNotOptimize(tree.insert(p));
      const double seconds = thread_seconds() - start;
      worst = std::max(worst, seconds);
      total += seconds;
    }
  }
  state.SetItemsProcessed(std::int64_t(state.iterations() * n));
  state.counters["max_insert_us"] = worst * 1e6;
  state.counters["mean_insert_us"] = total / double(state.iterations() * n) * 1e6;
}
BENCHMARK(BM_Insert)->ArgsProduct({{1 << 16, 1 << 18}, {0, 1}})->ArgNames({"n", "worst_case"})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

// What an insert costs without dynamization: a static tree rebuilt over all n points.
void BM_StaticRebuild(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const auto points = uniform_points(n, 1);
  const spatial::PointView<float> view(points.front().data(), n, 3);
  for (auto _ : state) benchmark::DoNotOptimize(spatial::KdTree<float, 3>(view).size());
  state.counters["inserts_per_s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_StaticRebuild)->Arg(1 << 16)->Arg(1 << 18)->ArgName("n")->Unit(benchmark::kMillisecond);

// Deletes one at a time, in random order, of all n points (reconstructions
// included); the slowest single delete is the worst-case delete latency.
void BM_Delete(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const auto points = uniform_points(n, 2);
  std::vector<dynamic::Id> order;
  double worst = 0, total = 0;
  std::size_t worst_work = 0, rebuilds = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Tree tree(dynamic::DynamizeOptions{variant_of(state)});
    order = tree.insert(spatial::PointView<float>(points.front().data(), n, 3));
    std::shuffle(order.begin(), order.end(), Rng(3));
    state.ResumeTiming();
    for (dynamic::Id id : order) {
      const std::size_t work = tree.structure().work();
      const double start = thread_seconds();
      tree.remove(id);
      const double seconds = thread_seconds() - start;
      worst = std::max(worst, seconds);
      total += seconds;
      worst_work = std::max(worst_work, tree.structure().work() - work);
    }
    rebuilds = tree.structure().stats().rebuilds;
  }
  state.SetItemsProcessed(std::int64_t(state.iterations() * n));
  state.counters["max_delete_us"] = worst * 1e6;
  state.counters["mean_delete_us"] = total / double(state.iterations() * n) * 1e6;
  state.counters["max_delete_work"] = double(worst_work);
  state.counters["rebuilds"] = double(rebuilds);
}
BENCHMARK(BM_Delete)->ArgsProduct({{1 << 18}, {0, 1}})->ArgNames({"n", "worst_case"})->Unit(benchmark::kMillisecond);

// 10-NN queries on a tree built by n inserts and n/4 deletes, against a static tree of the same points.
void BM_Query(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const auto points = uniform_points(n, 4);
  const auto queries = uniform_points(10000, 5);
  Tree tree(dynamic::DynamizeOptions{variant_of(state)});
  std::vector<dynamic::Id> ids;
  for (const auto& p : points) ids.push_back(tree.insert(p));
  for (std::size_t i = 0; i < n / 4; ++i) tree.remove(ids[i * 4]);
  std::vector<Tree::Neighbor> out(10);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tree.query_into(queries[i++ % queries.size()], spatial::KnnRequest{10}, out.data()));
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
  state.counters["trees"] = double(tree.stats().structure.structures);
}
BENCHMARK(BM_Query)->ArgsProduct({{1 << 18}, {0, 1}})->ArgNames({"n", "worst_case"});

void BM_QueryStatic(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const auto points = uniform_points(n, 4);
  const auto queries = uniform_points(10000, 5);
  const spatial::KdTree<float, 3> tree(spatial::PointView<float>(points.front().data(), n * 3 / 4, 3));
  std::vector<spatial::Neighbor<float>> out(10);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tree.query_into(queries[i++ % queries.size()], spatial::KnnRequest{10}, out.data()));
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}
BENCHMARK(BM_QueryStatic)->Arg(1 << 18)->ArgName("n");

}  // namespace
