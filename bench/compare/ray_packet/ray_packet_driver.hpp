#pragma once
// The packet comparison (issue 19): the coherent rays of the ray workload
// (rays_coherent.f32, 1024x1024 pinhole camera) in packets of neighbouring
// pixels, 4 x 2 pixel tiles for packets of 8 (4 x 4 for Embree's 16), over
// mesh_1m.ply / mesh_100k.ply. Variants "<mesh>_closest" (closest hit:
// geods TriangleBvh::intersect(RayPacket) vs rtcIntersect8/16) and
// "<mesh>_any" (any hit with t in [0, inf): occluded(RayPacket) vs
// rtcOccluded8/16). Threads > 1 split the packets with tbb::parallel_for.
//
// A library plugs in with a struct Lib:
//   static constexpr const char* anchor;
//   static constexpr int kTileW, kTileH;   // pixels of one packet (kTileW * kTileH rays)
//   using Index = ...;
//   static std::unique_ptr<Index> build(const compare::PlyMesh& mesh);
//   // n <= kTileW * kTileH rays (ox oy oz dx dy dz each), hits out; any: occlusion only
//   static void trace(const Index&, const float* rays, int n, bool any, compare::ray_packet::Hit* hits);
// Check: every 10000th ray against brute force in double (ray/ray_driver.hpp);
// "hits" (rays that hit) must agree across libraries and with the single-ray
// comparison of the same rays.
#include <time.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "../ray/ray_driver.hpp"

namespace compare::ray_packet {

using Hit = compare::ray::Hit;

/// The rays of the 1024 x 1024 image (row-major) reordered tile by tile, tiles
/// of tile_w x tile_h pixels in row-major order of tiles.
inline std::vector<float> tile_order(const std::vector<float>& rays, int tile_w, int tile_h) {
  const int size = 1024;
  std::vector<float> out;
  out.reserve(rays.size());
  for (int ty = 0; ty < size; ty += tile_h)
    for (int tx = 0; tx < size; tx += tile_w)
      for (int y = ty; y < ty + tile_h; ++y)
        for (int x = tx; x < tx + tile_w; ++x) {
          const float* r = &rays[6 * (std::size_t(y) * size + std::size_t(x))];
          out.insert(out.end(), r, r + 6);
        }
  return out;
}

template <class Lib>
void run_variant(const Args& args, const PlyMesh& mesh, const std::string& mesh_name, bool any) {
  const std::vector<float> raw = read_raw<float>(args.path("rays_coherent.f32"));
  if (raw.size() != 6u * 1024 * 1024) throw std::runtime_error("rays_coherent.f32: expected 1024 x 1024 rays");
  std::vector<float> rays = tile_order(raw, Lib::kTileW, Lib::kTileH);
  constexpr int P = Lib::kTileW * Lib::kTileH;
  // --scale keeps whole packets.
  const std::size_t m = std::min(rays.size() / 6, (args.scaled(rays.size() / 6) + P - 1) / P * P);
  rays.resize(6 * m);
  std::vector<Hit> hits(m);

  std::unique_ptr<typename Lib::Index> index;
  const double build_s = median_time_s(args.reps, [&] {
    index.reset();
    index = Lib::build(mesh);
  });
  const std::size_t packets = (m + P - 1) / P;
  auto trace_all = [&] {
    auto body = [&](std::size_t b, std::size_t e) {
      for (std::size_t p = b; p < e; ++p) {
        const std::size_t first = p * P;
        Lib::trace(*index, &rays[6 * first], int(std::min<std::size_t>(P, m - first)), any, &hits[first]);
      }
    };
    if (args.threads == 1) {
      body(0, packets);
    } else {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, packets, 128),
                        [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
    }
  };
  // CPU time of the process as well (the wall clock of a loaded machine says little).
  const auto cpu_s = [] {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  };
  const double cpu_start = cpu_s();
  const double query_s = median_time_s(args.reps, trace_all);
  const double query_cpu_s = (cpu_s() - cpu_start) / std::max(1, args.reps);

  std::size_t hit_count = 0;
  double sum_t = 0;
  for (const Hit& h : hits)
    if (h.hit()) ++hit_count, sum_t += any ? 0.0 : h.t;
  std::size_t checked = 0, disagreements = 0;
  for (std::size_t i = 0; i < m; i += 10000) {
    const double t = compare::ray::brute_force_t(mesh, &rays[6 * i]);
    const bool same = std::isinf(t) ? !hits[i].hit()
                                    : hits[i].hit() && (any || std::abs(hits[i].t - t) <= 1e-4 * std::max(1.0, t));
    disagreements += !same;
    ++checked;
  }
  Record("ray_packet", Lib::anchor, mesh_name + (any ? "_any" : "_closest"), args.threads)
      .timing(build_s, query_s, m, args.reps)
      .set("triangles", static_cast<unsigned long long>(mesh.triangles()))
      .set("packet", P)
      .set("hits", static_cast<unsigned long long>(hit_count))
      .set("mean_t", hit_count && !any ? sum_t / double(hit_count) : 0.0)
      .set("mrays_per_s", double(m) / query_s * 1e-6)
      .set("query_cpu_s", query_cpu_s)
      .set("checked", static_cast<unsigned long long>(checked))
      .set("disagreements", static_cast<unsigned long long>(disagreements))
      .print(disagreements * 100 <= checked);
}

template <class Lib>
int run(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  const ThreadLimit limit(args.threads);
  for (const char* mesh_name : {"1m", "100k"}) {
    const std::string closest = std::string(mesh_name) + "_closest", any = std::string(mesh_name) + "_any";
    if (!args.wants(closest) && !args.wants(any)) continue;
    const PlyMesh mesh = read_ply(args.path(std::string("mesh_") + mesh_name + ".ply"));
    if (args.wants(closest)) run_variant<Lib>(args, mesh, mesh_name, false);
    if (args.wants(any)) run_variant<Lib>(args, mesh, mesh_name, true);
  }
  return 0;
}

}  // namespace compare::ray_packet
