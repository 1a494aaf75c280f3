// Cost per call of the exact predicates against their plain double
// determinants, on three kinds of input:
//   random           uniform points: the filter decides nearly every call;
//   near_degenerate  points on a line / plane / circle / sphere moved by a
//                    few ulps: the filter fails, the expansions decide;
//   degenerate       exactly collinear / coplanar / co-circular /
//                    co-spherical integer points, as in grids and meshes.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"

namespace {

using geods::Rng;
using Point = std::array<double, 3>;

constexpr int kBatch = 4096;  // input sets per batch, reused across iterations

enum class Kind { Random, NearDegenerate, Degenerate };

// One input set of up to 5 points; 2D predicates use x and y.
using Inputs = std::array<Point, 5>;

double nudge(double x, Rng& rng) {
  const int steps = int(rng.below(5)) - 2;
  for (int s = 0; s < std::abs(steps); ++s)
    x = std::nextafter(x, steps > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity());
  return x;
}

Point random_point(Rng& rng) { return {rng.uniform(), rng.uniform(), rng.uniform()}; }
Point integer_point(Rng& rng, int n) { return {double(rng.below(n)), double(rng.below(n)), double(rng.below(n))}; }

// dim 2: points[2] on the line points[0..1]; dim 3: points[3] on the plane points[0..2].
void make_flat(Inputs& p, int dim, double s, double t) {
  for (int k = 0; k < 3; ++k) {
    p[dim][k] = p[0][k] + s * (p[1][k] - p[0][k]);
    if (dim == 3) p[dim][k] += t * (p[2][k] - p[0][k]);
  }
}

std::vector<Point> lattice_sphere(int r, int dim) {
  std::vector<Point> points;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y)
      for (int z = (dim == 3 ? -r : 0); z <= (dim == 3 ? r : 0); ++z)
        if (x * x + y * y + z * z == r * r) points.push_back({double(x), double(y), double(z)});
  return points;
}

std::vector<Inputs> make_batch(Kind kind, int dim, bool round) {
  Rng rng(std::uint64_t(kind) * 10 + std::uint64_t(dim) + (round ? 100 : 0));
  const std::vector<Point> lattice = lattice_sphere(dim == 2 ? 65 : 9, dim);
  const int count = dim + (round ? 2 : 1);
  std::vector<Inputs> batch(kBatch);
  for (Inputs& p : batch) {
    if (kind == Kind::Random) {
      for (Point& q : p) q = random_point(rng);
    } else if (kind == Kind::NearDegenerate && !round) {
      for (Point& q : p) q = random_point(rng);
      make_flat(p, dim, rng.uniform(-1, 2), rng.uniform(-1, 2));
      for (double& x : p[dim]) x = nudge(x, rng);
    } else if (kind == Kind::NearDegenerate) {
      const Point center = random_point(rng);
      for (int i = 0; i < count; ++i) {
        const double z = dim == 3 ? rng.uniform(-1, 1) : 0.0, a = rng.uniform(0, 2 * std::numbers::pi);
        const double r = std::sqrt(1 - z * z);
        p[i] = {center[0] + r * std::cos(a), center[1] + r * std::sin(a), center[2] + z};
      }
      for (double& x : p[count - 1]) x = nudge(x, rng);
    } else if (!round) {
      for (Point& q : p) q = integer_point(rng, 1000);
      make_flat(p, dim, double(rng.below(5)) - 2, double(rng.below(5)) - 2);
    } else {
      const Point shift = integer_point(rng, 1000);
      for (int i = 0; i < count; ++i) {
        const Point& q = lattice[rng.below(lattice.size())];
        p[i] = {q[0] + shift[0], q[1] + shift[1], q[2] + shift[2]};
      }
    }
  }
  return batch;
}

const std::vector<Inputs>& batch(Kind kind, int dim, bool round) {
  static std::array<std::array<std::array<std::vector<Inputs>, 2>, 2>, 3> cache;
  std::vector<Inputs>& b = cache[int(kind)][dim - 2][round ? 1 : 0];
  if (b.empty()) b = make_batch(kind, dim, round);
  return b;
}

template <typename Call>
void run(benchmark::State& state, const std::vector<Inputs>& inputs, Call call) {
  for (auto _ : state) {
    double sum = 0;
    for (const Inputs& p : inputs) sum += call(p);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * std::int64_t(inputs.size()));
}

void BM_orient2d(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 2, false), [](const Inputs& p) { return geods::orient2d(p[0].data(), p[1].data(), p[2].data()); });
}
void BM_orient2d_fast(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 2, false),
      [](const Inputs& p) { return geods::orient2d_fast(p[0].data(), p[1].data(), p[2].data()); });
}
void BM_orient3d(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 3, false),
      [](const Inputs& p) { return geods::orient3d(p[0].data(), p[1].data(), p[2].data(), p[3].data()); });
}
void BM_orient3d_fast(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 3, false),
      [](const Inputs& p) { return geods::orient3d_fast(p[0].data(), p[1].data(), p[2].data(), p[3].data()); });
}
void BM_incircle(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 2, true),
      [](const Inputs& p) { return geods::incircle(p[0].data(), p[1].data(), p[2].data(), p[3].data()); });
}
void BM_incircle_fast(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 2, true),
      [](const Inputs& p) { return geods::incircle_fast(p[0].data(), p[1].data(), p[2].data(), p[3].data()); });
}
void BM_insphere(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 3, true), [](const Inputs& p) {
    return geods::insphere(p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data());
  });
}
void BM_insphere_fast(benchmark::State& state, Kind kind) {
  run(state, batch(kind, 3, true), [](const Inputs& p) {
    return geods::insphere_fast(p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data());
  });
}

#define GEODS_PREDICATE_BENCHMARKS(name)                                    \
  BENCHMARK_CAPTURE(name, random, Kind::Random);                           \
  BENCHMARK_CAPTURE(name, near_degenerate, Kind::NearDegenerate);          \
  BENCHMARK_CAPTURE(name, degenerate, Kind::Degenerate);

GEODS_PREDICATE_BENCHMARKS(BM_orient2d)
GEODS_PREDICATE_BENCHMARKS(BM_orient2d_fast)
GEODS_PREDICATE_BENCHMARKS(BM_orient3d)
GEODS_PREDICATE_BENCHMARKS(BM_orient3d_fast)
GEODS_PREDICATE_BENCHMARKS(BM_incircle)
GEODS_PREDICATE_BENCHMARKS(BM_incircle_fast)
GEODS_PREDICATE_BENCHMARKS(BM_insphere)
GEODS_PREDICATE_BENCHMARKS(BM_insphere_fast)

}  // namespace
