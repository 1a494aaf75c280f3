#pragma once
// The nearest comparison (post office problem, seed §5.4.1): the same inputs,
// timing loop and checks for every library; each program supplies an adapter.
//
// Inputs from anchors/WORKLOADS.md: the sites are the first 20k points of
// del2_uniform.f64 (uniform in [0,1)^2), the queries its last 200k points.
// Build the structure, then one nearest-site query at a time (threads > 1: the
// queries split with tbb::parallel_for). Sanity ("ok"): every 500th query
// against brute force (same squared distance). "checksum": FNV-1a of the
// nearest indices (uniform doubles have no ties), so run.py checks agreement.
//
// Adapter interface (struct Lib):
//   static constexpr const char* anchor;
//   struct Index;
//   static std::unique_ptr<Index> build(const double* xy, std::size_t n);
//   static std::uint32_t nearest(const Index&, const double* q);
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common.hpp"

namespace compare::nearest {

inline constexpr std::size_t kSites = 20000, kQueries = 200000;

template <class Lib>
void run_uniform(const Args& args) {
  const std::vector<double> all = read_raw<double>(args.path("del2_uniform.f64"));
  const std::size_t total = all.size() / 2;
  const std::size_t n = std::min(total / 2, args.scaled(kSites)), m = std::min(total / 2, args.scaled(kQueries));
  const std::vector<double> sites(all.begin(), all.begin() + 2 * n);
  const std::vector<double> queries(all.end() - 2 * m, all.end());

  std::unique_ptr<typename Lib::Index> index;
  const double build_s = median_time_s(args.reps, [&] {
    index.reset();
    index = Lib::build(sites.data(), n);
  });
  std::vector<std::uint32_t> nearest(m);
  const double query_s = median_time_s(args.reps, [&] {
    auto body = [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) nearest[i] = Lib::nearest(*index, &queries[2 * i]);
    };
    if (args.threads == 1) {
      body(0, m);
    } else {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 1024),
                        [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
    }
  });

  const auto squared = [&](std::size_t j, const double* q) {
    const double dx = sites[2 * j] - q[0], dy = sites[2 * j + 1] - q[1];
    return dx * dx + dy * dy;
  };
  bool ok = true;
  for (std::size_t i = 0; i < m && ok; i += 500) {
    const double* q = &queries[2 * i];
    double best = squared(0, q);
    for (std::size_t j = 1; j < n; ++j) best = std::min(best, squared(j, q));
    ok = nearest[i] < n && squared(nearest[i], q) == best;
  }
  Record("nearest", Lib::anchor, "uniform", args.threads)
      .timing(build_s, query_s, m, args.reps)
      .set("sites", static_cast<unsigned long long>(n))
      .set("checksum", hex64(neighbour_checksum<1>(nearest.data(), m)))
      .print(ok);
}

template <class Lib>
int run(int argc, char** argv) {
  return run_variants(argc, argv, {"uniform"}, [](const Args& args, const char*) { run_uniform<Lib>(args); });
}

}  // namespace compare::nearest
