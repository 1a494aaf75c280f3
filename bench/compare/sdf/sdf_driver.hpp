#pragma once
// The sdf comparison: the signed distance (negative inside) of mesh_100k.ply at the 128^3
// samples of anchors/WORKLOADS.md (voxel and origin from params.txt, output [k][j][i]).
// Variants:
//   "whole"   every sample exact (OpenVDB: a band wide enough to cover the whole grid);
//   "band 3"  a narrow band of 3 voxels on each side of the surface (samples outside it keep
//             only their sign).
// Every program gets the same mesh and grid, loaded before timing, and checks its field the
// same way: 500 samples spread over the grid (a fixed SplitMix64 stream) against brute force
// over all triangles in double (the distance) and against the parity of ray crossings (the
// sign). Reported: build_s (structure built before the grid, where the library has one),
// query_s (the grid), count (samples), inside (negative samples), max_error_voxels (largest
// |error| of a checked sample inside the program's band, in voxels), sign_errors (checked
// samples at least a voxel from the surface whose sign differs from ray parity), query_cpu_s
// (the process CPU time of the grid, median of the repetitions).
#include <array>
#include <cmath>
#include <ctime>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "common.hpp"

namespace compare::sdf {

struct Workload {
  PlyMesh mesh;
  std::size_t n = 128;
  double voxel = 0;
  std::array<double, 3> origin{};
  std::array<double, 3> position(std::size_t i, std::size_t j, std::size_t k) const {
    return {origin[0] + double(i) * voxel, origin[1] + double(j) * voxel, origin[2] + double(k) * voxel};
  }
};

inline Workload load(const Args& args) {
  Workload w;
  w.mesh = read_ply(args.path("mesh_100k.ply"));
  std::ifstream f(args.path("params.txt"));
  std::string key;
  while (f >> key) {
    if (key == "sdf_n") f >> w.n;
    else if (key == "sdf_voxel") f >> w.voxel;
    else if (key == "sdf_origin") f >> w.origin[0] >> w.origin[1] >> w.origin[2];
    else std::getline(f, key);
  }
  if (!(w.voxel > 0)) die("params.txt: no sdf_voxel (run bench/compare/gen_workloads.py)");
  return w;
}

struct Variant {
  std::string name;
  double band;  // voxels on each side; infinity: the whole grid
};
inline std::vector<Variant> variants() {
  return {{"whole", std::numeric_limits<double>::infinity()}, {"band 3", 3.0}};
}

using V3 = std::array<double, 3>;
inline V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Squared distance from p to triangle abc (Ericson 5.1.5, in double).
inline double point_triangle_d2(const V3& p, const V3& a, const V3& b, const V3& c) {
  const V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto at = [&](const V3& q) { const V3 d = sub(p, q); return dot(d, d); };
  auto lerp = [](const V3& s, const V3& e, double t) {
    return V3{s[0] + t * (e[0] - s[0]), s[1] + t * (e[1] - s[1]), s[2] + t * (e[2] - s[2])};
  };
  if (d1 <= 0 && d2 <= 0) return at(a);
  const V3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(lerp(a, b, d1 / (d1 - d3)));
  const V3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(lerp(a, c, d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return at(lerp(b, c, (d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1 / (va + vb + vc), v = vb * denom, w = vc * denom;
  return at({a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w});
}

struct Check {
  std::size_t index;  // flat sample index
  double distance;    // brute force, signed by ray parity
  bool sign_known;    // at least a voxel from the surface and the rays agreed
};

// The 500 checked samples (the same for every program).
inline std::vector<Check> reference(const Workload& w) {
  const PlyMesh& m = w.mesh;
  auto vertex = [&](std::size_t t, int c) {
    const float* v = &m.xyz[3 * std::size_t(m.tris[3 * t + std::size_t(c)])];
    return V3{v[0], v[1], v[2]};
  };
  const V3 dirs[3] = {{0.5773, 0.6114, 0.5411}, {-0.3139, 0.8716, -0.3767}, {0.7013, -0.2215, -0.6776}};
  std::vector<Check> out;
  SplitMix64 rng(128);
  const std::size_t total = w.n * w.n * w.n;
  for (int s = 0; s < 500; ++s) {
    const std::size_t idx = rng.next() % total;
    const V3 p = w.position(idx % w.n, idx / w.n % w.n, idx / (w.n * w.n));
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < m.triangles(); ++t)
      best = std::min(best, point_triangle_d2(p, vertex(t, 0), vertex(t, 1), vertex(t, 2)));
    best = std::sqrt(best);
    int votes = 0, trusted = 0;
    for (const V3& d : dirs) {
      int crossings = 0;
      bool edge = false;
      for (std::size_t t = 0; t < m.triangles(); ++t) {  // Moeller-Trumbore
        const V3 a = vertex(t, 0), e1 = sub(vertex(t, 1), a), e2 = sub(vertex(t, 2), a);
        const V3 h = cross(d, e2);
        const double det = dot(e1, h);
        if (std::abs(det) < 1e-300) continue;
        const V3 sv = sub(p, a), q = cross(sv, e1);
        const double u = dot(sv, h) / det, v = dot(d, q) / det, tt = dot(e2, q) / det;
        if (tt <= 0 || u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9) continue;
        if (u < 1e-9 || v < 1e-9 || u + v > 1 - 1e-9) edge = true;
        ++crossings;
      }
      if (edge) continue;
      votes += crossings % 2;
      ++trusted;
    }
    const bool inside = 2 * votes > trusted;
    out.push_back({idx, inside ? -best : best, trusted > 0 && best > w.voxel});
  }
  return out;
}

/// build(workload, args) runs once and returns its time (0 if the library has no separate
/// structure); compute(variant) makes the field and is timed; value(i, j, k) reads it afterwards
/// (outside a band: anything of the right sign).
inline int run(int argc, char** argv, const char* anchor,
               const std::function<double(const Workload&, const Args&)>& build,
               const std::function<void(const Variant&)>& compute,
               const std::function<float(std::size_t, std::size_t, std::size_t)>& value, bool narrow_band = true,
               int max_reps = 1000) {
  Args args = parse_args(argc, argv);
  args.reps = std::min(args.reps, max_reps);
  ThreadLimit limit(args.threads);
  const Workload w = load(args);
  const std::vector<Check> checks = reference(w);
  const double build_s = build(w, args);
  for (const Variant& v : variants()) {
    if (!args.wants(v.name) || (!narrow_band && std::isfinite(v.band))) continue;
    // Also the process CPU time of the grid (all threads): on a busy machine the wall time
    // mostly measures waiting for a core.
    std::vector<double> cpu;
    const double query_s = median_time_s(args.reps, [&] {
      const std::clock_t c0 = std::clock();
      compute(v);
      cpu.push_back(double(std::clock() - c0) / CLOCKS_PER_SEC);
    });
    const std::size_t total = w.n * w.n * w.n;
    std::size_t inside = 0, sign_errors = 0;
    double max_error = 0;
    bool ok = true;
    {
      for (std::size_t k = 0; k < w.n; ++k)
        for (std::size_t j = 0; j < w.n; ++j)
          for (std::size_t i = 0; i < w.n; ++i) inside += value(i, j, k) < 0;
      for (const Check& c : checks) {
        const double d = value(c.index % w.n, c.index / w.n % w.n, c.index / (w.n * w.n));
        if (c.sign_known && (d < 0) != (c.distance < 0)) ++sign_errors;
        if (std::abs(c.distance) <= v.band * w.voxel)
          max_error = std::max(max_error, std::abs(std::abs(d) - std::abs(c.distance)) / w.voxel);
      }
    }
    ok = sign_errors == 0 && max_error < 1;  // a sanity check: the exactness is max_error_voxels
    Record r("sdf", anchor, v.name, args.threads);
    r.timing(build_s, query_s, total, args.reps);
    r.set("query_cpu_s", median(std::move(cpu)));
    r.set("inside", static_cast<unsigned long long>(inside));
    r.set("max_error_voxels", max_error);
    r.set("sign_errors", static_cast<unsigned long long>(sign_errors));
    r.print(ok);
  }
  return 0;
}

}  // namespace compare::sdf
