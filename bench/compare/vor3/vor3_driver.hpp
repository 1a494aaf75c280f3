// Shared by the vor3 comparison programs: the input (the first 200k points of del3_uniform.f64 of
// anchors/WORKLOADS.md, uniform in the unit cube), the timing loop and the checks.
//
// A library provides   static Result cells(const std::vector<double>& xyz, std::size_t n)
// computing every point's Voronoi cell clipped to the unit cube [0, 1]^3 and keeping, per cell,
// its corners, its faces as corner loops, the site or box side across each face, its volume and
// its centroid; it returns the counts over the cells. The driver times it (median of --reps, fresh
// cells each time) and checks that the volumes sum to the cube's; the face counts must agree
// between libraries (points in general position: one combinatorial diagram).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common.hpp"

namespace vor3 {

struct Result {
  std::size_t cells = 0;     // cells with a volume
  std::size_t faces = 0;     // faces, each shared face counted per cell
  std::size_t vertices = 0;  // corners, counted per cell
  double volume = 0;         // sum of the cell volumes
};

template <class Library>
void run_variant(const compare::Args& args, const std::string& variant) {
  std::vector<double> xyz = compare::read_raw<double>(args.path("del3_uniform.f64"));
  const std::size_t n = std::min(xyz.size() / 3, args.scaled(200000));
  xyz.resize(3 * n);
  Result result;
  const double build_s = compare::median_time_s(args.reps, [&] { result = Library::cells(xyz, n); });
  const bool partition = result.cells == n && std::abs(result.volume - 1.0) < 1e-9;
  compare::Record("vor3", Library::anchor, variant, args.threads)
      .timing(build_s, 0.0, n, args.reps)
      .set("cells", static_cast<unsigned long long>(result.cells))
      .set("faces", static_cast<unsigned long long>(result.faces))
      .set("vertices", static_cast<unsigned long long>(result.vertices))
      .set("volume_error", result.volume - 1.0)
      .print(partition);
}

template <class Library>
int run(int argc, char** argv) {
  return compare::run_variants(argc, argv, {"uniform_200k"}, run_variant<Library>);
}

}  // namespace vor3
