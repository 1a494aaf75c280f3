// geods collide: CollisionMesh (SAH, leaf size 2) of mesh_100k, shared by A
// and B, one query per pose; OBBs (principal axes), or with GEODS_COLLIDE_RSS
// rectangle swept spheres.
//
// Variant `motion` (OBB only): a smooth motion of B, 1000 frames (x --scale)
// slerped between 10 successive poses of the workload (100 frames from one to
// the next), all contacts per frame: from scratch (anchor geods) or, with
// GEODS_COLLIDE_INCREMENTAL, by one IncrementalCollide over the sequence
// (anchor geods_incremental; its first frame is a query from scratch).
#include <Eigen/Geometry>
#include <memory>

#include "collide_driver.hpp"
#include "geods/collide/collide.hpp"
#include "geods/collide/incremental.hpp"

namespace {

using namespace geods;

#if defined(GEODS_COLLIDE_RSS)
constexpr const char* kAnchor = "geods_rss";
constexpr collide::CollisionVolume kVolume = collide::CollisionVolume::rss;
#elif defined(GEODS_COLLIDE_INCREMENTAL)
constexpr const char* kAnchor = "geods_incremental";
constexpr collide::CollisionVolume kVolume = collide::CollisionVolume::obb;
#else
constexpr const char* kAnchor = "geods";
constexpr collide::CollisionVolume kVolume = collide::CollisionVolume::obb;
#endif

std::shared_ptr<collide::CollisionMesh> build(const collide_bench::Workload& w) {
  TriMesh m;
  for (std::size_t i = 0; i < w.mesh.vertices(); ++i)
    m.vertices.emplace_back(w.mesh.xyz[3 * i], w.mesh.xyz[3 * i + 1], w.mesh.xyz[3 * i + 2]);
  for (std::size_t i = 0; i < w.mesh.triangles(); ++i)
    m.triangles.push_back({std::uint32_t(w.mesh.tris[3 * i]), std::uint32_t(w.mesh.tris[3 * i + 1]),
                           std::uint32_t(w.mesh.tris[3 * i + 2])});
  collide::CollisionMeshOptions options;
  options.bv = kVolume;
  return std::make_shared<collide::CollisionMesh>(m, options);
}

// Frame k of the smooth motion: between poses k / 100 and k / 100 + 1.
std::vector<collide::Posed> motion(const collide_bench::Workload& w, std::size_t frames) {
  const std::size_t steps = 100;
  std::vector<collide::Posed> out;
  for (std::size_t k = 0; k < frames; ++k) {
    const std::size_t s = (k / steps) % (w.count() - 1);
    const collide::Posed p0 = collide::Posed::from_row(&w.poses[7 * s]), p1 = collide::Posed::from_row(&w.poses[7 * s + 7]);
    const double u = double(k % steps) / double(steps);
    collide::Posed p;
    p.rotation = p0.rotation.normalized().slerp(u, p1.rotation.normalized());
    p.translation = (1 - u) * p0.translation + u * p1.translation;
    out.push_back(p);
  }
  return out;
}

[[maybe_unused]] int run_motion(const compare::Args& args) {  // unused by the RSS program
  const collide_bench::Workload w = collide_bench::load(args);
  std::shared_ptr<collide::CollisionMesh> m;
  const double build_s = compare::median_time_s(args.reps, [&] { m = build(w); });
  const std::vector<collide::Posed> frames = motion(w, args.scaled(1000));
  std::vector<collide_bench::PoseResult> results(frames.size());
  const double query_s = compare::median_time_s(args.reps, [&] {
#if defined(GEODS_COLLIDE_INCREMENTAL)
    collide::IncrementalCollide inc(*m, *m);
#endif
    for (std::size_t i = 0; i < frames.size(); ++i) {
#if defined(GEODS_COLLIDE_INCREMENTAL)
      const auto c = inc.update(collide::Posed{}, frames[i]);
#else
      const auto c = collide::collide(*m, collide::Posed{}, *m, frames[i], {collide::CollideMode::all});
#endif
      results[i].colliding = c.colliding;
      results[i].pairs = c.pairs.size();
    }
  });
  const std::string c = collide_bench::check("all", results);
  std::fprintf(stderr, "%s motion: %s, %.4f ms per frame\n", kAnchor, c.c_str(), 1e3 * query_s / double(frames.size()));
  compare::Record("collide", kAnchor, "motion", args.threads)
      .timing(build_s, query_s / double(frames.size()), 1, args.reps)
      .set("poses", static_cast<unsigned long long>(frames.size()))
      .set("check", c)
      .print(true);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
#if defined(GEODS_COLLIDE_INCREMENTAL)
  return compare::run_variants(argc, argv, {"motion"}, [](const compare::Args& args, const char*) { run_motion(args); });
#else
  const int rc = collide_bench::run(
      argc, argv, kAnchor, build,
      [](const std::shared_ptr<collide::CollisionMesh>& m, const std::string& variant, const collide_bench::Workload& w,
         std::size_t i) {
        const collide::Posed pose = collide::Posed::from_row(&w.poses[7 * i]);
        collide_bench::PoseResult r;
        if (variant == "distance") {
          const auto d = collide::distance(*m, collide::Posed{}, *m, pose);
          r.distance = d.distance;
          r.colliding = d.distance == 0;
        } else {
          const auto c = collide::collide(*m, collide::Posed{}, *m, pose,
                                          {variant == "all" ? collide::CollideMode::all : collide::CollideMode::first});
          r.colliding = c.colliding;
          r.pairs = c.pairs.size();
        }
        return r;
      });
#if !defined(GEODS_COLLIDE_RSS)
  if (rc == 0) return compare::run_variants(argc, argv, {"motion"}, [](const compare::Args& args, const char*) { run_motion(args); });
#endif
  return rc;
#endif
}
