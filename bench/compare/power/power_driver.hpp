// Shared by the power comparison programs: the inputs (the points of del2_uniform.f64 and
// del2_grid.f64 of anchors/WORKLOADS.md, the first n * --scale, with weights made here), the
// timing loop and the checks.
//
// Weights: `uniform` gets w = (r u)^2 for u uniform in [0, 1) (SplitMix64 seed 2001) and r
// the mean spacing 1/sqrt(n): circles up to the spacing, so that a share of the points is
// redundant; `grid` gets w = 0.25 * (k * 2654435761 mod 3) on the integer grid: exact ties of
// the power test everywhere.
//
// A library provides   static Result triangulate(xy, w, n)   returning the counts of its
// regular triangulation; the driver times it (median of --reps, a fresh triangulation each
// time) and checks Euler's formula t = 2v - h - 2 over the non-redundant vertices.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common.hpp"

namespace power {

struct Result {
  std::size_t vertices = 0;   // points with a cell (not hidden / redundant)
  std::size_t triangles = 0;  // finite triangles
  std::size_t hull = 0;       // hull edges
};

inline std::vector<double> weights(const std::string& variant, std::size_t n) {
  std::vector<double> w(n);
  if (variant == "grid") {
    for (std::size_t k = 0; k < n; ++k) w[k] = 0.25 * double((k * 2654435761u) % 3);
  } else {
    compare::SplitMix64 rng(2001);
    const double r = 1 / std::sqrt(double(n));
    for (double& x : w) {
      const double u = double(rng.next() >> 11) * 0x1.0p-53;
      x = (r * u) * (r * u);
    }
  }
  return w;
}

template <class Library>
void run_variant(const compare::Args& args, const std::string& variant) {
  std::vector<double> xy = compare::read_raw<double>(args.path("del2_" + variant + ".f64"));
  const std::size_t n = std::min(xy.size() / 2, args.scaled(xy.size() / 2));
  xy.resize(2 * n);
  const std::vector<double> w = weights(variant, n);
  Result result;
  const double build_s = compare::median_time_s(args.reps, [&] { result = Library::triangulate(xy, w, n); });
  const bool euler = result.triangles == 2 * result.vertices - result.hull - 2;
  compare::Record("power", Library::anchor, variant, args.threads)
      .timing(build_s, 0.0, n, args.reps)
      .set("triangles", static_cast<unsigned long long>(result.triangles))
      .set("vertices", static_cast<unsigned long long>(result.vertices))
      .set("hull", static_cast<unsigned long long>(result.hull))
      .set("euler", euler)
      .print(euler);
}

template <class Library>
int run(int argc, char** argv) {
  return compare::run_variants(argc, argv, {"uniform", "grid"}, run_variant<Library>);
}

}  // namespace power
