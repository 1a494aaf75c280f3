// The min/max octree against the exhaustive scan on a 160^3 volume holding
// spheres of several radii: the smaller the surface, the more the octree saves
// (the scan always reads every sample). Arg: sphere radius in voxels; the octree
// with both vertex-sharing modes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "geods/core/parallel.hpp"
#include "geods/iso/marching_cubes.hpp"
#include "geods/iso/min_max_octree.hpp"

namespace {

using namespace geods;

constexpr std::size_t kSide = 160;

// Distance from the centre of the volume: the sphere of radius r is the level set r
// (inside = samples >= r would be outside, so negate: inside is the ball).
const Grid3<float>& volume() {
  static const Grid3<float> g = [] {
    Grid3<float> v(kSide, kSide, kSide);
    const double c = 0.5 * double(kSide - 1) + 0.3;
    for (std::size_t k = 0; k < kSide; ++k)
      for (std::size_t j = 0; j < kSide; ++j)
        for (std::size_t i = 0; i < kSide; ++i)
          v(i, j, k) = -float(std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)));
    return v;
  }();
  return g;
}

iso::IsoOptions no_normals() {
  iso::IsoOptions o;
  o.normals = false;
  return o;
}

void BM_IsoScan(benchmark::State& state) {
  set_num_threads(1);
  std::size_t cells = 0;
  for (auto _ : state) benchmark::DoNotOptimize(iso::isosurface(volume(), -double(state.range(0)), no_normals(), &cells));
  state.counters["cells_visited_pct"] = 100.0 * double(cells) / std::pow(double(kSide - 1), 3);
  set_num_threads(0);
}

// Arg 0: radius; arg 1: 0 = VertexSharing::block_masks (the default), 1 = hash_table.
void BM_IsoOctree(benchmark::State& state) {
  set_num_threads(1);
  static const iso::MinMaxOctree<float> tree(volume());
  const iso::VertexSharing sharing = state.range(1) ? iso::VertexSharing::hash_table : iso::VertexSharing::block_masks;
  state.SetLabel(state.range(1) ? "hash_table" : "block_masks");
  std::size_t cells = 0;
  for (auto _ : state) {
    iso::OctreeIsoResult r = tree.isosurface(-double(state.range(0)), no_normals(), sharing);
    cells = r.cells_visited;
    benchmark::DoNotOptimize(r);
  }
  state.counters["cells_visited_pct"] = 100.0 * double(cells) / std::pow(double(kSide - 1), 3);
  set_num_threads(0);
}

void BM_IsoOctreeBuild(benchmark::State& state) {
  set_num_threads(1);
  for (auto _ : state) benchmark::DoNotOptimize(std::make_unique<iso::MinMaxOctree<float>>(volume()));
  set_num_threads(0);
}

BENCHMARK(BM_IsoScan)->Arg(4)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IsoOctree)->ArgsProduct({{4, 16, 64}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IsoOctreeBuild)->Unit(benchmark::kMillisecond);

}  // namespace
