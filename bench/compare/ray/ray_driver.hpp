#pragma once
// The ray comparison (anchors/WORKLOADS.md, workload "ray"): build an
// accelerator over mesh_1m.ply / mesh_100k.ply, then the closest hit of every
// ray of rays_coherent.f32 / rays_incoherent.f32 (t in [0, inf)), one ray at a
// time; threads > 1 split the rays with tbb::parallel_for.
//
// A library plugs in with a struct Lib:
//   static constexpr const char* anchor;                    // "geods", "embree", ...
//   using Index = ...;
//   static std::unique_ptr<Index> build(const compare::PlyMesh& mesh);
//   static compare::ray::Hit intersect(const Index&, const float* ray);  // ray = ox oy oz dx dy dz
// optionally
//   static bool wants_mesh(const std::string& mesh);  // e.g. CGAL: "100k" only
//
//   static bool occluded(const Index&, const float* ray);  // any hit with t in [0, inf)
//
// Variants: "1m_coherent", "1m_incoherent", "100k_coherent", "100k_incoherent"
// (closest hit) and, for the libraries with occluded, the same with "_any"
// (any hit, rtcOccluded1's question; the check then compares hit or miss only).
// Check: every 10000th ray against brute force (Möller-Trumbore in double):
// same hit/miss and t within 1e-4, allowing one grazing disagreement per 100.
// "hits" (number of rays that hit) must agree across libraries; "mean_t" too,
// up to float rounding.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common.hpp"

namespace compare::ray {

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  std::uint32_t prim = std::numeric_limits<std::uint32_t>::max();
  bool hit() const { return prim != std::numeric_limits<std::uint32_t>::max(); }
};

/// Closest hit in double, the reference of the sanity check.
inline double brute_force_t(const PlyMesh& mesh, const float* r) {
  double best = std::numeric_limits<double>::infinity();
  const double o[3] = {r[0], r[1], r[2]}, d[3] = {r[3], r[4], r[5]};
  for (std::size_t f = 0; f < mesh.triangles(); ++f) {
    const float* a = &mesh.xyz[3 * std::size_t(mesh.tris[3 * f])];
    const float* b = &mesh.xyz[3 * std::size_t(mesh.tris[3 * f + 1])];
    const float* c = &mesh.xyz[3 * std::size_t(mesh.tris[3 * f + 2])];
    double e1[3], e2[3], s[3];
    for (int k = 0; k < 3; ++k) e1[k] = double(b[k]) - a[k], e2[k] = double(c[k]) - a[k], s[k] = o[k] - a[k];
    const double p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det == 0) continue;
    const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    if (u < 0 || u > 1) continue;
    const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    if (v < 0 || u + v > 1) continue;
    const double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    if (t >= 0 && t < best) best = t;
  }
  return best;
}

template <class Lib>
constexpr bool has_occluded = requires(const typename Lib::Index& index, const float* r) { Lib::occluded(index, r); };

/// hits[i] for the rays [begin, end): the closest hit, or with `any` a hit at
/// t = 0 if anything is hit; threads > 1 split them with tbb::parallel_for.
template <class Lib>
void trace(const typename Lib::Index& index, const std::vector<float>& rays, std::size_t begin, std::size_t end,
           bool any, std::vector<Hit>& hits, int threads) {
  auto body = [&](std::size_t b, std::size_t e) {
    if constexpr (has_occluded<Lib>) {
      if (any) {
        for (std::size_t i = b; i < e; ++i) hits[i] = Lib::occluded(index, &rays[6 * i]) ? Hit{0.0f, 0} : Hit{};
        return;
      }
    }
    for (std::size_t i = b; i < e; ++i) hits[i] = Lib::intersect(index, &rays[6 * i]);
  };
  if (threads == 1) return body(begin, end);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
}

template <class Lib>
void run_variant(const Args& args, const PlyMesh& mesh, const std::string& mesh_name, const std::string& rays_name,
                 bool any) {
  std::vector<float> rays = read_raw<float>(args.path("rays_" + rays_name + ".f32"));
  const std::size_t m = std::min(rays.size() / 6, args.scaled(rays.size() / 6));
  rays.resize(6 * m);
  std::vector<Hit> hits(m);

  std::unique_ptr<typename Lib::Index> index;
  const double build_s = median_time_s(args.reps, [&] {
    index.reset();
    index = Lib::build(mesh);
  });
  auto trace_all = [&] { trace<Lib>(*index, rays, 0, m, any, hits, args.threads); };
  const double query_s = median_time_s(args.reps, trace_all);

  std::size_t hit_count = 0;
  double sum_t = 0;
  for (const Hit& h : hits)
    if (h.hit()) ++hit_count, sum_t += h.t;
  std::size_t checked = 0, disagreements = 0;
  for (std::size_t i = 0; i < m; i += 10000) {
    const double t = brute_force_t(mesh, &rays[6 * i]);
    const bool same = std::isinf(t) ? !hits[i].hit()
                                    : hits[i].hit() && (any || std::abs(hits[i].t - t) <= 1e-4 * std::max(1.0, t));
    disagreements += !same;
    ++checked;
  }
  Record("ray", Lib::anchor, mesh_name + "_" + rays_name + (any ? "_any" : ""), args.threads)
      .timing(build_s, query_s, m, args.reps)
      .set("triangles", static_cast<unsigned long long>(mesh.triangles()))
      .set("hits", static_cast<unsigned long long>(hit_count))
      .set("mean_t", hit_count ? sum_t / double(hit_count) : 0.0)
      .set("mrays_per_s", double(m) / query_s * 1e-6)
      .set("checked", static_cast<unsigned long long>(checked))
      .set("disagreements", static_cast<unsigned long long>(disagreements))
      .print(disagreements * 100 <= checked);
}

/// Calls fn(mesh, mesh_name, rays_name, any) for every variant --only selects,
/// "_any" ones only if with_any; each mesh is read once.
template <class Fn>
void for_each_variant(const Args& args, bool with_any, bool (*wants_mesh)(const std::string&), Fn&& fn) {
  for (const char* mesh_name : {"1m", "100k"}) {
    if (wants_mesh && !wants_mesh(mesh_name)) continue;
    // (rays, any hit) of the variants wanted on this mesh
    std::vector<std::pair<std::string, bool>> wanted;
    for (const char* rays_name : {"coherent", "incoherent"}) {
      const std::string variant = std::string(mesh_name) + "_" + rays_name;
      if (args.wants(variant)) wanted.emplace_back(rays_name, false);
      if (with_any && args.wants(variant + "_any")) wanted.emplace_back(rays_name, true);
    }
    if (wanted.empty()) continue;
    const PlyMesh mesh = read_ply(args.path(std::string("mesh_") + mesh_name + ".ply"));
    for (const auto& [rays_name, any] : wanted) fn(mesh, mesh_name, rays_name, any);
  }
}

template <class Lib>
int run(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  const ThreadLimit limit(args.threads);
  bool (*wants_mesh)(const std::string&) = nullptr;
  if constexpr (requires { Lib::wants_mesh(std::string()); }) wants_mesh = &Lib::wants_mesh;
  for_each_variant(args, has_occluded<Lib>, wants_mesh,
                   [&](const PlyMesh& mesh, const std::string& mesh_name, const std::string& rays_name, bool any) {
                     run_variant<Lib>(args, mesh, mesh_name, rays_name, any);
                   });
  return 0;
}

}  // namespace compare::ray
