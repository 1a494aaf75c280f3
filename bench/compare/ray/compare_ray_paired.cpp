// geods' BVH and Embree 3 (default mode) timed in one process, taking turns on
// the same rays: the ratio of their times with the machine's drift shared by
// both. Run by hand, not by run.py (no compare.json entry): on a shared VM the
// separate programs' times move by 5-10 % between runs minutes apart, more
// than the gaps this measures.
//
// Per variant: both indices are built --reps times, taking turns; then, after
// one untimed pass each, --reps passes over the rays in chunks of 2^18, each
// chunk traced by one library and then the other (who goes first alternates
// by chunk and by pass). Prints one JSON line per variant: the time of each
// per pass, ratio = Embree's time / geods' over all passes (> 1: geods
// faster), ratio_min / ratio_max over single passes, build_ratio likewise
// from the median builds. Threads > 1 split each chunk with tbb::parallel_for.
//
//   compare_ray_paired --data build/anchors-data --threads 1 --reps 4 --only 100k_incoherent
#include <algorithm>
#include <cmath>
#include <vector>

#include "embree_ray.hpp"
#include "geods_bvh_ray.hpp"
#include "ray_driver.hpp"

namespace compare::ray {
namespace {

void run_paired(const Args& args, const PlyMesh& mesh, const std::string& mesh_name, const std::string& rays_name,
                bool any) {
  using G = Geods;
  using E = Embree;
  std::vector<float> rays = read_raw<float>(args.path("rays_" + rays_name + ".f32"));
  const std::size_t m = std::min(rays.size() / 6, args.scaled(rays.size() / 6));
  rays.resize(6 * m);

  std::unique_ptr<G::Index> g;
  std::unique_ptr<E::Index> e;
  std::vector<double> build_g, build_e;
  for (int r = 0; r < args.reps; ++r) {
    g.reset(), e.reset();
    build_g.push_back(time_s([&] { g = G::build(mesh); }));
    build_e.push_back(time_s([&] { e = E::build(mesh); }));
  }

  std::vector<Hit> hits_g(m), hits_e(m);
  trace<G>(*g, rays, 0, m, any, hits_g, args.threads);
  trace<E>(*e, rays, 0, m, any, hits_e, args.threads);
  constexpr std::size_t kChunk = std::size_t(1) << 18;
  double total_g = 0, total_e = 0;
  std::vector<double> ratios;
  for (int pass = 0; pass < args.reps; ++pass) {
    double pass_g = 0, pass_e = 0;
    for (std::size_t b = 0, chunk = 0; b < m; b += kChunk, ++chunk) {
      const std::size_t end = std::min(m, b + kChunk);
      const bool geods_first = (chunk + std::size_t(pass)) % 2 == 0;
      for (int turn = 0; turn < 2; ++turn) {
        if ((turn == 0) == geods_first) {
          pass_g += time_s([&] { trace<G>(*g, rays, b, end, any, hits_g, args.threads); });
        } else {
          pass_e += time_s([&] { trace<E>(*e, rays, b, end, any, hits_e, args.threads); });
        }
      }
    }
    ratios.push_back(pass_e / pass_g);
    total_g += pass_g, total_e += pass_e;
  }

  // Both libraries answer the same question: the same rays hit (closest hits
  // may differ on grazing rays, as in ray_driver's check against brute force).
  std::size_t hit_g = 0, hit_e = 0, differ = 0;
  for (std::size_t i = 0; i < m; ++i) {
    hit_g += hits_g[i].hit(), hit_e += hits_e[i].hit();
    differ += hits_g[i].hit() != hits_e[i].hit() ||
              (!any && hits_g[i].hit() && std::abs(hits_g[i].t - hits_e[i].t) > 1e-4f * std::max(1.0f, hits_e[i].t));
  }
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  Record("ray_paired", "geods_vs_embree", mesh_name + "_" + rays_name + (any ? "_any" : ""), args.threads)
      .set("count", static_cast<unsigned long long>(m))
      .set("passes", args.reps)
      .set("geods_s", total_g / args.reps)
      .set("embree_s", total_e / args.reps)
      .set("ratio", total_e / total_g)
      .set("ratio_min", *lo)
      .set("ratio_max", *hi)
      .set("build_ratio", median(build_e) / median(build_g))
      .set("hits_geods", static_cast<unsigned long long>(hit_g))
      .set("hits_embree", static_cast<unsigned long long>(hit_e))
      .set("differ", static_cast<unsigned long long>(differ))
      .print(differ * 1000 <= m);
}

}  // namespace
}  // namespace compare::ray

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  compare::ray::Embree::threads = args.threads;
  compare::ray::for_each_variant(args, true, nullptr,
                                 [&](const compare::PlyMesh& mesh, const std::string& mesh_name,
                                     const std::string& rays_name, bool any) {
                                   compare::ray::run_paired(args, mesh, mesh_name, rays_name, any);
                                 });
  return 0;
}
