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
