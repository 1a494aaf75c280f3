// geods::field::edt on the edt workload: edt_256.u8 (256^3, x fastest, 1 = foreground), unit
// spacing. Reported: the time, the sum and the largest of the distances (WORKLOADS.md gives
// 19,311,553.80 and 47.707), and 5 random foreground voxels checked against brute force.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

#include "common.hpp"
#include "geods/field/edt.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  if (!args.wants("256")) return 0;
  const std::size_t n = 256;
  geods::Grid3<std::uint8_t> mask(n, n, n);
  mask.data = compare::read_raw<std::uint8_t>(args.path("edt_256.u8"));
  if (mask.data.size() != n * n * n) compare::die("edt_256.u8: expected 256^3 voxels");

  geods::field::EdtResult r;
  const double s = compare::median_time_s(args.reps, [&] { r = geods::field::edt(mask.view()); });
  long double sum = 0;  // 80 bits: the cents of the checksum do not depend on the summation order
  double max = 0;
  for (const double d : r.distance.data) sum += d, max = std::max(max, d);

  // 5 random foreground voxels against every background voxel.
  std::mt19937_64 rng(5);
  bool ok = true;
  for (int t = 0; t < 5; ++t) {
    std::size_t q;
    do q = rng() % mask.size(); while (!mask.data[q]);
    double best = INFINITY;
    for (std::size_t i = 0; i < mask.size(); ++i)
      if (!mask.data[i]) {
        const double dx = double(q % n) - double(i % n), dy = double(q / n % n) - double(i / n % n),
                     dz = double(q / (n * n)) - double(i / (n * n));
        best = std::min(best, dx * dx + dy * dy + dz * dz);
      }
    ok = ok && r.distance.data[q] == std::sqrt(best);
  }
  char checksum[64];
  std::snprintf(checksum, sizeof checksum, "%.2Lf / %.3f", sum, max);
  compare::Record("edt", "geods", "256", args.threads)
      .timing(0, s, mask.size(), args.reps)
      .set("checksum", checksum)
      .print(ok);
  return 0;
}
