#include "geods/ray/bvh_accelerator.hpp"

#include <chrono>

namespace geods::ray {

std::unique_ptr<BvhAccelerator> BvhAccelerator::build(const TriMesh& mesh, const AcceleratorOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<BvhAccelerator> accel(new BvhAccelerator(mesh));
  accel->bvh_ = bvh::TriangleBvh::build(mesh, options.bvh);
  accel->build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return accel;
}

void BvhAccelerator::save(const std::filesystem::path& path) const {
  ArchiveWriter out(kArchiveKind, kArchiveVersion);
  add_sections(out);
  bvh_.add_sections(out);
  out.write(path);
}

std::unique_ptr<BvhAccelerator> BvhAccelerator::load(const std::filesystem::path& path) {
  const Archive in = Archive::open(path, kArchiveKind, kArchiveVersion);
  std::unique_ptr<BvhAccelerator> accel(new BvhAccelerator(in));
  if (accel->bvh_.num_triangles() != accel->num_triangles())
    throw in.error("the hierarchy and the corners hold different triangle counts");
  return accel;
}

RayHit BvhAccelerator::closest_hit(const Ray3f& ray, RayCache&) const { return bvh_.intersect(ray); }

std::uint32_t BvhAccelerator::any_hit(const Ray3f& ray, RayCache&) const {
  if (!bvh_.occluded(ray)) return RayHit::no_hit;
  return bvh_.intersect(ray).prim;
}

bvh::HitPacket BvhAccelerator::closest_hits(const bvh::RayPacket& packet, RayCache&) const {
  return bvh_.intersect(packet);
}

std::uint32_t BvhAccelerator::any_hits(const bvh::RayPacket& packet, RayCache&) const {
  return bvh_.occluded(packet);
}

bvh::HitPacket16 BvhAccelerator::closest_hits(const bvh::RayPacket16& packet, RayCache&) const {
  return bvh_.intersect(packet);
}

std::uint32_t BvhAccelerator::any_hits(const bvh::RayPacket16& packet, RayCache&) const {
  return bvh_.occluded(packet);
}

AcceleratorStats BvhAccelerator::stats() const {
  const bvh::BvhStats b = bvh_.stats();
  AcceleratorStats s;
  s.kind = "bvh";
  s.triangles = b.triangles;
  s.nodes = b.nodes;
  s.leaves = b.leaves;
  s.references = b.triangles;
  s.depth = std::size_t(b.depth);
  s.bytes = b.bytes + corners_.size() * sizeof(Vec3f);
  s.build_s = build_s_;
  return s;
}

}  // namespace geods::ray
