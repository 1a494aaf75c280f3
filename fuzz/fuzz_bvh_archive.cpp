// libFuzzer target: TriangleBvh and the ray accelerators loaded from archives.
// The first byte picks what reads the rest: 0 a TriangleBvh through the
// structure checks only (checksums skipped, so mutations reach validate()),
// 1 TriangleBvh::load, 2 ray::load_accelerator; a loaded structure is queried.
#include "fuzz_common.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/archive.hpp"
#include "geods/ray/accelerator.hpp"

namespace {

geods::Ray3f probe_ray() {
  geods::Ray3f ray;
  ray.origin = geods::Vec3f(0.1f, 0.2f, -5.0f);
  ray.direction = geods::Vec3f(0.01f, 0.02f, 1.0f);
  return ray;
}

void query(const geods::bvh::TriangleBvh& bvh) {
  bvh.intersect(probe_ray());
  bvh.occluded(probe_ray());
  bvh.closest_point(geods::Vec3f(0.3f, 0.1f, 0.2f));
  bvh.contains(geods::Vec3f(0.3f, 0.1f, 0.2f));
  bvh.cull_box(geods::AABB3f(geods::Vec3f(-1, -1, -1), geods::Vec3f(1, 1, 1)));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t selector = data[0] % 3;
  return geods::fuzz::read_as(data + 1, size - 1, "in.geods", [&](const auto& p) {
    using geods::bvh::TriangleBvh;
    if (selector == 0) {
      const auto archive = geods::Archive::open(p, TriangleBvh::kArchiveKind, TriangleBvh::kArchiveVersion,
                                                geods::Archive::Verify::structure_only);
      query(TriangleBvh::from_sections(archive));
    } else if (selector == 1) {
      query(TriangleBvh::load(p));
    } else {
      const auto accel = geods::ray::load_accelerator(p);
      accel->intersect(probe_ray());
      accel->occluded(probe_ray());
    }
  });
}
