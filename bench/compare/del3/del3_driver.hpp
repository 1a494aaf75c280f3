// Shared by the del3 comparison programs: the inputs (del3_uniform.f64 of anchors/WORKLOADS.md:
// 1M points, and the first 200k), the timing loop, the memory measurement and the checks.
//
// A library provides   static Result tetrahedralize(const std::vector<double>& xyz, std::size_t n)
// returning the counts of its tetrahedralization (and the resident memory it added while it
// was alive), and max_reps; the driver times it (median of min(--reps, max_reps), a fresh
// tetrahedralization each time) and checks the one fact of WORKLOADS.md, every input point a
// vertex (the workload has no duplicates); the counts of tetrahedra must agree between libraries.
#pragma once
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "common.hpp"

namespace del3 {

struct Result {
  std::size_t vertices = 0;    // distinct points that are vertices
  std::size_t tetrahedra = 0;  // finite tetrahedra
  std::size_t hull = 0;        // hull triangles
  double bytes = 0;            // memory held by the structure and the input copy (memory_since)
};

/// The memory a structure holds: the larger of the growth of the bytes malloc has handed out
/// (mallinfo2, exact whatever pages earlier builds freed) and of the resident set (which also sees
/// allocators beside malloc, such as the TBB scalable allocator of CGAL's Parallel_tag, but not
/// pages reused from an earlier build). Take `memory_mark()` before, `memory_since(mark)` while alive.
struct MemoryMark {
  double heap = 0, resident = 0;
};
inline double resident_bytes();
inline MemoryMark memory_mark() {
  const struct mallinfo2 m = mallinfo2();
  return {double(m.uordblks + m.hblkhd), resident_bytes()};
}
inline double memory_since(const MemoryMark& before) {
  const MemoryMark now = memory_mark();
  return std::max(now.heap - before.heap, now.resident - before.resident);
}

/// Resident set size of this process in bytes (from /proc/self/statm).
inline double resident_bytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long size = 0, resident = 0;
  const int got = std::fscanf(f, "%lu %lu", &size, &resident);
  std::fclose(f);
  return got == 2 ? double(resident) * double(sysconf(_SC_PAGESIZE)) : 0.0;
}

template <class Library>
void run_variant(const compare::Args& args, const std::string& variant) {
  std::vector<double> xyz = compare::read_raw<double>(args.path("del3_uniform.f64"));
  const std::size_t full = variant == "uniform_200k" ? 200000 : 1000000;
  const std::size_t n = std::min(xyz.size() / 3, args.scaled(full));
  xyz.resize(3 * n);
  // Memory: a first, untimed build.
  Result result = Library::tetrahedralize(xyz, n, args.threads);
  const double bytes = result.bytes;
  const int reps = std::min(args.reps, Library::max_reps);
  const double build_s = compare::median_time_s(reps, [&] { result = Library::tetrahedralize(xyz, n, args.threads); });
  result.bytes = bytes;
  const bool all_vertices = result.vertices == n;
  compare::Record(Library::workload, Library::anchor, variant, args.threads)
      .timing(build_s, 0.0, n, reps)
      .set("tetrahedra", static_cast<unsigned long long>(result.tetrahedra))
      .set("hull", static_cast<unsigned long long>(result.hull))
      .set("vertices", static_cast<unsigned long long>(result.vertices))
      .set("bytes_per_point", result.bytes / double(n))
      .set("all_vertices", all_vertices)
      .print(all_vertices);
}

template <class Library>
int run(int argc, char** argv) {
  return compare::run_variants(argc, argv, {"uniform_200k", "uniform_1m"}, run_variant<Library>);
}

}  // namespace del3
