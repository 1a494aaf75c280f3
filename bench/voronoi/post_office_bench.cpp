// Nearest-site queries per second (post office problem, seed §5.4.1): the slab
// structure of Theorem 8, walking in the Delaunay graph (from a sampled start,
// and from the previous answer for coherent queries), and the k-d tree, on
// uniform sites; one query at a time on one thread. Builds of the diagram,
// the slab structure and the L1 diagram.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/metric_voronoi.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace {

using namespace geods;

std::vector<Vec2d> uniform(std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2d> p(n);
  for (Vec2d& v : p) v = {rng.uniform(), rng.uniform()};
  return p;
}

const std::vector<Vec2d>& sites(std::size_t n) {
  static std::map<std::size_t, std::vector<Vec2d>> cache;
  auto& p = cache[n];
  if (p.empty()) p = uniform(n, 1);
  return p;
}

const voronoi::Voronoi2& diagram(std::size_t n) {
  static std::map<std::size_t, std::unique_ptr<voronoi::Voronoi2>> cache;
  auto& v = cache[n];
  if (!v) v = std::make_unique<voronoi::Voronoi2>(sites(n));
  return *v;
}

const std::vector<Vec2d>& queries() {
  static const std::vector<Vec2d> q = uniform(100000, 2);
  return q;
}

template <typename Locate>
void run_queries(benchmark::State& state, const Locate& locate) {
  const auto& q = queries();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(locate(q[i]));
    if (++i == q.size()) i = 0;
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}

// Arg: number of sites.
void BM_NearestSlab(benchmark::State& state) {
  const voronoi::SlabLocator slab(diagram(std::size_t(state.range(0))));
  run_queries(state, [&](const Vec2d& q) { return slab.nearest(q); });
  state.counters["MB"] = double(slab.stats().bytes) / 1e6;
}
BENCHMARK(BM_NearestSlab)->Arg(1000)->Arg(10000)->Arg(50000);

void BM_NearestWalk(benchmark::State& state) {
  const voronoi::WalkLocator walk(diagram(std::size_t(state.range(0))));
  run_queries(state, [&](const Vec2d& q) { return walk.nearest(q); });
}
BENCHMARK(BM_NearestWalk)->Arg(1000)->Arg(10000)->Arg(50000)->Arg(1000000);

// Coherent queries (a random walk with steps of about a cell), each walk starting at the previous answer.
void BM_NearestWalkCoherent(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const voronoi::WalkLocator walk(diagram(n));
  Rng rng(3);
  Vec2d q(0.5, 0.5);
  const double step = 1.0 / std::sqrt(double(n));
  std::uint32_t previous = 0;
  for (auto _ : state) {
    q = (q + Vec2d(rng.uniform(-step, step), rng.uniform(-step, step))).cwiseMax(0.0).cwiseMin(1.0);
    benchmark::DoNotOptimize(previous = walk.nearest(q, previous));
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}
BENCHMARK(BM_NearestWalkCoherent)->Arg(10000)->Arg(1000000);

void BM_NearestKdTree(benchmark::State& state) {
  const auto& p = sites(std::size_t(state.range(0)));
  const spatial::KdTree<double, 2> tree{spatial::PointView<double>(std::span<const Vec2d>(p))};
  spatial::Neighbor<double> out;
  run_queries(state, [&](const Vec2d& q) {
    tree.query_into(std::span<const double>(q.data(), 2), {1}, &out);
    return out.index;
  });
}
BENCHMARK(BM_NearestKdTree)->Arg(1000)->Arg(10000)->Arg(50000)->Arg(1000000);

void BM_Voronoi2Build(benchmark::State& state) {
  const auto& p = sites(std::size_t(state.range(0)));
  set_num_threads(1);
  for (auto _ : state) benchmark::DoNotOptimize(voronoi::Voronoi2(p).edges().data());
  set_num_threads(0);
  state.SetItemsProcessed(std::int64_t(state.iterations() * state.range(0)));
}
BENCHMARK(BM_Voronoi2Build)->Arg(10000)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_SlabBuild(benchmark::State& state) {
  const voronoi::Voronoi2& v = diagram(std::size_t(state.range(0)));
  set_num_threads(1);
  for (auto _ : state) benchmark::DoNotOptimize(voronoi::SlabLocator(v).stats().crossings);
  set_num_threads(0);
}
BENCHMARK(BM_SlabBuild)->Arg(10000)->Unit(benchmark::kMillisecond);

void BM_L1DiagramBuild(benchmark::State& state) {
  const auto& p = sites(std::size_t(state.range(0)));
  set_num_threads(1);
  for (auto _ : state)
    benchmark::DoNotOptimize(voronoi::MetricVoronoi(p, voronoi::Metric::l1, AABB2d({0, 0}, {1, 1})).edges().data());
  set_num_threads(0);
  state.SetItemsProcessed(std::int64_t(state.iterations() * state.range(0)));
}
BENCHMARK(BM_L1DiagramBuild)->Arg(2000)->Unit(benchmark::kMillisecond);

}  // namespace
