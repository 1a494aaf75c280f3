#pragma once
// The mc comparison: isosurfaces of volume_256.f32 (256^3 float32, x fastest) without normals.
// Every program gets the same volume, loaded before timing, and runs the same variants:
//   "iso 0.3"  the workload of anchors/WORKLOADS.md (closed surface, ~228k triangles);
//   "iso 1.8"  a small surface around the highest blob peak (crosses far under 5 % of the
//              cells), where geods' min/max octree skips almost all of the volume.
// `run` times extract(volume, iso) -> (vertices, triangles) and prints one JSON line per
// variant: query_s = extraction, build_s = structure built once before (the octree), count =
// triangles (quads of OpenVDB count as two).
#include <functional>
#include <string>
#include <vector>

#include "common.hpp"

namespace compare::mc {

inline constexpr std::size_t kSide = 256;

struct Extracted {
  std::size_t vertices = 0, triangles = 0;
  std::size_t cells_visited = 0;  // octree only
};

struct Variant {
  std::string name;
  double iso;
};

inline std::vector<Variant> variants() { return {{"iso 0.3", 0.3}, {"iso 1.8", 1.8}}; }

inline std::vector<float> load_volume(const Args& args) {
  std::vector<float> v = read_raw<float>(args.path("volume_256.f32"));
  if (v.size() != kSide * kSide * kSide) die("volume_256.f32: expected 256^3 floats");
  return v;
}

/// prepare(volume) runs once (untimed unless it returns a build time); extract(iso) is timed.
inline int run(int argc, char** argv, const char* anchor, const std::function<double()>& build,
               const std::function<Extracted(double)>& extract) {
  const Args args = parse_args(argc, argv);
  ThreadLimit limit(args.threads);
  const double build_s = build();
  for (const Variant& v : variants()) {
    if (!args.wants(v.name)) continue;
    Extracted out;
    const double query_s = median_time_s(args.reps, [&] { out = extract(v.iso); });
    // The surface of volume_256 at 0.3 is closed; every library finds about 228k triangles.
    const bool ok = out.triangles > 0 && (v.iso != 0.3 || (out.triangles > 200000 && out.triangles < 260000));
    Record r("mc", anchor, v.name, args.threads);
    r.timing(build_s, query_s, out.triangles, args.reps).set("vertices", static_cast<unsigned long long>(out.vertices));
    r.set("triangles", static_cast<unsigned long long>(out.triangles));
    if (out.cells_visited) r.set("cells_visited_pct", 100.0 * double(out.cells_visited) / double(255 * 255 * 255));
    r.print(ok);
  }
  return 0;
}

}  // namespace compare::mc
