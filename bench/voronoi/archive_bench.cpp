// Loading a saved Delaunay2 and Voronoi2 against building them, on uniform
// points: load maps the file and reads its arrays in place, so it should cost
// a small fraction of a build.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "geods/core/rng.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace {

using namespace geods;

std::vector<Vec2d> uniform(std::size_t n) {
  Rng rng(1);
  std::vector<Vec2d> p(n);
  for (Vec2d& v : p) v = {rng.uniform(), rng.uniform()};
  return p;
}

std::filesystem::path saved(const std::string& name, std::size_t n) {
  return std::filesystem::temp_directory_path() / ("geods_bench_" + name + "_" + std::to_string(n) + ".geods");
}

void BM_Delaunay2Build(benchmark::State& state) {
  const std::vector<Vec2d> p = uniform(std::size_t(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(voronoi::Delaunay2(p).triangle_count());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Delaunay2Build)->Arg(1 << 20)->Unit(benchmark::kMillisecond);

void BM_Delaunay2Load(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const std::filesystem::path path = saved("delaunay2", n);
  voronoi::Delaunay2(uniform(n)).save(path);
  for (auto _ : state) benchmark::DoNotOptimize(voronoi::Delaunay2::load(path).triangle_count());
  state.SetItemsProcessed(state.iterations() * state.range(0));
  std::filesystem::remove(path);
}
BENCHMARK(BM_Delaunay2Load)->Arg(1 << 20)->Unit(benchmark::kMillisecond);

// Queries on a triangulation of 2^20 uniform points, random query points.
// Arg: 0 on the built triangulation, 1 on the same loaded (read from the mapped file).
template <class Query>
void run_delaunay2_queries(benchmark::State& state, Query query) {
  const std::size_t n = std::size_t(1) << 20;
  voronoi::Delaunay2 dt(uniform(n));
  if (state.range(0) == 1) {
    const std::filesystem::path path = saved("delaunay2_queries", n);
    dt.save(path);
    dt = voronoi::Delaunay2::load(path);
    std::filesystem::remove(path);
  }
  Rng rng(2);
  std::vector<Vec2d> q(4096);
  for (Vec2d& v : q) v = {rng.uniform(), rng.uniform()};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(query(dt, q[i]));
    if (++i == q.size()) i = 0;
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()));
}

void BM_Delaunay2Locate(benchmark::State& state) {
  run_delaunay2_queries(state, [](const voronoi::Delaunay2& dt, const Vec2d& q) { return dt.locate(q); });
}
BENCHMARK(BM_Delaunay2Locate)->Arg(0)->Arg(1);

void BM_Delaunay2Nearest(benchmark::State& state) {
  run_delaunay2_queries(state, [](const voronoi::Delaunay2& dt, const Vec2d& q) { return dt.nearest(q); });
}
BENCHMARK(BM_Delaunay2Nearest)->Arg(0)->Arg(1);

void BM_Voronoi2Build(benchmark::State& state) {
  const std::vector<Vec2d> p = uniform(std::size_t(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(voronoi::Voronoi2(p).vertices().size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Voronoi2Build)->Arg(1 << 20)->Unit(benchmark::kMillisecond);

void BM_Voronoi2Load(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const std::filesystem::path path = saved("voronoi2", n);
  voronoi::Voronoi2(uniform(n)).save(path);
  for (auto _ : state) benchmark::DoNotOptimize(voronoi::Voronoi2::load(path).vertices().size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
  std::filesystem::remove(path);
}
BENCHMARK(BM_Voronoi2Load)->Arg(1 << 20)->Unit(benchmark::kMillisecond);

}  // namespace
