// Shared by the del2 comparison programs: the inputs (del2_uniform.f64, del2_grid.f64 of
// anchors/WORKLOADS.md, the first n * --scale points), the timing loop and the checks.
//
// A library provides   static Result triangulate(const std::vector<double>& xy, std::size_t n)
// returning the counts of its triangulation, and max_reps; the driver times it (median of
// min(--reps, max_reps), a fresh triangulation each time) and checks Euler's formula
// t = 2n - h - 2 with every input point a vertex (the workloads have no duplicates).
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "common.hpp"

namespace del2 {

struct Result {
  std::size_t vertices = 0;   // distinct points that are vertices of the triangulation
  std::size_t triangles = 0;  // finite triangles
  std::size_t hull = 0;       // hull edges (= hull vertices, collinear ones included)
};

template <class Library>
void run_variant(const compare::Args& args, const std::string& variant) {
  std::vector<double> xy = compare::read_raw<double>(args.path("del2_" + variant + ".f64"));
  const std::size_t n = std::min(xy.size() / 2, args.scaled(xy.size() / 2));
  xy.resize(2 * n);
  Result result;
  const int reps = std::min(args.reps, Library::max_reps);
  const double build_s = compare::median_time_s(reps, [&] { result = Library::triangulate(xy, n); });
  const bool euler = result.triangles == 2 * result.vertices - result.hull - 2;
  const bool all_vertices = result.vertices == n;
  compare::Record(Library::workload, Library::anchor, variant, args.threads)
      .timing(build_s, 0.0, n, reps)
      .set("triangles", static_cast<unsigned long long>(result.triangles))
      .set("hull", static_cast<unsigned long long>(result.hull))
      .set("vertices", static_cast<unsigned long long>(result.vertices))
      .set("euler", euler)
      .set("all_vertices", all_vertices)
      .print(euler && all_vertices);
}

template <class Library>
int run(int argc, char** argv) {
  return compare::run_variants(argc, argv, {"uniform", "grid"}, run_variant<Library>);
}

}  // namespace del2
