// geods' ray accelerators of seed §2.5 — the uniform grid, the octree and 5D
// ray classification — on the ray comparison, through the ray::Accelerator
// interface. Compiled once per kind with GEODS_RAY_ACCEL = grid, octree, rays5d.
// Each thread keeps one RayCache (the per-level cache of the 5D classifier);
// the 5D classifier subdivides while the rays arrive, so most of its building
// is timed in query_s, not build_s.
//
// The 5D classifier runs only on mesh_100k, and with a tenth of the
// incoherent rays (its rate is still rays / query_s): on incoherent rays its
// beams are wide and its leaves long, about 10^4 rays/s, and 1M of them — or
// mesh_1m — would take most of `make bench`'s hour.
#include <string_view>

#include "geods/ray/accelerator.hpp"
#include "geods_mesh.hpp"
#include "ray_driver.hpp"

#ifndef GEODS_RAY_ACCEL
#error "define GEODS_RAY_ACCEL as grid, octree or rays5d"
#endif
#define GEODS_STRINGIFY_(x) #x
#define GEODS_STRINGIFY(x) GEODS_STRINGIFY_(x)

namespace {

struct Accel {
  static constexpr const char* anchor = "geods_" GEODS_STRINGIFY(GEODS_RAY_ACCEL);
  using Index = geods::ray::Accelerator;
  static std::unique_ptr<Index> build(const compare::PlyMesh& ply) {
    const geods::TriMesh& mesh = compare::ray::geods_mesh(ply);
    return geods::ray::make_accelerator(mesh, geods::ray::parse_accelerator_kind(GEODS_STRINGIFY(GEODS_RAY_ACCEL)));
  }
  static compare::ray::Hit intersect(const Index& accel, const float* r) {
    static thread_local geods::ray::RayCache cache;
    geods::Ray3f ray;
    ray.origin = {r[0], r[1], r[2]};
    ray.direction = {r[3], r[4], r[5]};
    const geods::RayHit hit = accel.intersect(ray, cache);
    return {hit.t, hit.prim};
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (std::string_view(GEODS_STRINGIFY(GEODS_RAY_ACCEL)) != "rays5d") return compare::ray::run<Accel>(argc, argv);
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  if (!args.wants("100k_coherent") && !args.wants("100k_incoherent")) return 0;
  const compare::PlyMesh mesh = compare::read_ply(args.path("mesh_100k.ply"));
  if (args.wants("100k_coherent")) compare::ray::run_variant<Accel>(args, mesh, "100k", "coherent", false);
  compare::Args fewer = args;
  fewer.scale *= 0.1;
  if (args.wants("100k_incoherent")) compare::ray::run_variant<Accel>(fewer, mesh, "100k", "incoherent", false);
  return 0;
}
