// Loading a saved min/max octree of a 256^3 float volume against building it:
// the node ranges and the samples are read in place from the mapped file, not recomputed or copied.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>

#include "geods/iso/min_max_octree.hpp"

namespace {

using namespace geods;

constexpr std::size_t kSide = 256;

Grid3<float> waves() {
  Grid3<float> v(kSide, kSide, kSide);
  for (std::size_t k = 0; k < kSide; ++k)
    for (std::size_t j = 0; j < kSide; ++j)
      for (std::size_t i = 0; i < kSide; ++i) v(i, j, k) = float(std::sin(0.1 * i) * std::cos(0.07 * j) + 0.01 * k);
  return v;
}

void BM_MinMaxOctreeBuild(benchmark::State& state) {
  const Grid3<float> volume = waves();
  for (auto _ : state) benchmark::DoNotOptimize(iso::MinMaxOctree<float>(volume).stats().nodes);
}
BENCHMARK(BM_MinMaxOctreeBuild)->Unit(benchmark::kMillisecond);

void BM_MinMaxOctreeLoad(benchmark::State& state) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "geods_bench_min_max_octree.geods";
  iso::MinMaxOctree<float>(waves()).save(path);
  for (auto _ : state) benchmark::DoNotOptimize(iso::MinMaxOctree<float>::load(path).stats().nodes);
  std::filesystem::remove(path);
}
BENCHMARK(BM_MinMaxOctreeLoad)->Unit(benchmark::kMillisecond);

}  // namespace
