#pragma once
// What every collide program shares: the workload (mesh_100k.ply against
// itself, A at identity, B in each of the 1000 poses of collide_poses.f64),
// the three variants and the record each prints. The check field is the
// same for every library: "colliding poses/pairs" for first and all
// contacts, "colliding poses/sum of the least distances to 1e-6" for distance.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common.hpp"

namespace collide_bench {

struct Workload {
  compare::PlyMesh mesh;
  std::vector<double> poses;  // 7 per pose: qw qx qy qz tx ty tz
  std::size_t count() const { return poses.size() / 7; }
};

/// The mesh and the first 1000 x --scale poses; with stride k only every k-th of them
/// (for libraries too slow for all).
inline Workload load(const compare::Args& args, std::size_t stride = 1) {
  Workload w;
  w.mesh = compare::read_ply(args.path("mesh_100k.ply"));
  const std::vector<double> all = compare::read_raw<double>(args.path("collide_poses.f64"));
  const std::size_t n = std::min(all.size() / 7, args.scaled(1000));
  for (std::size_t i = 0; i < n; i += stride) w.poses.insert(w.poses.end(), all.begin() + 7 * i, all.begin() + 7 * i + 7);
  return w;
}

/// Per pose: whether it collides, contact pairs (all) and the least distance (distance).
struct PoseResult {
  bool colliding = false;
  std::size_t pairs = 0;
  double distance = 0;
};

inline std::string check(const std::string& variant, const std::vector<PoseResult>& r) {
  std::size_t colliding = 0, pairs = 0;
  double sum = 0;
  for (const auto& p : r) colliding += p.colliding, pairs += p.pairs, sum += p.distance;
  char buf[96];
  if (variant == "distance")
    std::snprintf(buf, sizeof buf, "%zu/%.6f", colliding, sum);
  else if (variant == "all")
    std::snprintf(buf, sizeof buf, "%zu/%zu", colliding, pairs);
  else
    std::snprintf(buf, sizeof buf, "%zu", colliding);
  return buf;
}

/// Runs the variants with a library: build() -> structure (timed), query(structure,
/// variant, workload, pose index) -> PoseResult. Prints query_s per pose (count 1).
template <class Build, class Query>
int run(int argc, char** argv, const char* anchor, Build&& build, Query&& query,
        std::initializer_list<const char*> variants = {"first", "all", "distance"}, std::size_t stride = 1) {
  return compare::run_variants(argc, argv, variants, [&](const compare::Args& args, const char* variant) {
    const Workload w = load(args, stride);
    decltype(build(w)) model{};
    const double build_s = compare::median_time_s(args.reps, [&] { model = build(w); });
    std::vector<PoseResult> results(w.count());
    const double query_s = compare::median_time_s(args.reps, [&] {
      for (std::size_t i = 0; i < w.count(); ++i) results[i] = query(model, std::string(variant), w, i);
    });
    const std::string c = check(variant, results);
    std::fprintf(stderr, "%s %s: %s, %.4f ms per pose\n", anchor, variant, c.c_str(), 1e3 * query_s / double(w.count()));
    compare::Record("collide", anchor, variant, args.threads)
        .timing(build_s, query_s / double(w.count()), 1, args.reps)
        .set("poses", static_cast<unsigned long long>(w.count()))
        .set("check", c)
        .print(true);
  });
}

}  // namespace collide_bench
