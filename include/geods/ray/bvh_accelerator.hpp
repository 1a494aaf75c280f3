#pragma once
// The bounding volume hierarchy of the bvh module (seed §4.1) behind the
// Accelerator interface, so that it can be compared with the grid, the octree
// and 5D ray classification on the same scene and the same rays.
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/ray/accelerator.hpp"

namespace geods::ray {

class BvhAccelerator final : public Accelerator {
 public:
  /// Builds a bvh::TriangleBvh with options.bvh.
  static std::unique_ptr<BvhAccelerator> build(const TriMesh& mesh, const AcceleratorOptions& options = {});

  static constexpr const char* kArchiveKind = "ray.BvhAccelerator";
  static constexpr std::uint32_t kArchiveVersion = 2;
  /// The corners and the hierarchy's sections (bvh::TriangleBvh::save's).
  void save(const std::filesystem::path& path) const override;
  /// Maps a file written by save(); throws geods::Error naming the file if it is bad.
  static std::unique_ptr<BvhAccelerator> load(const std::filesystem::path& path);

  AcceleratorKind kind() const override { return AcceleratorKind::bvh; }
  AcceleratorStats stats() const override;
  void validate() const override { bvh_.validate(); }
  const bvh::TriangleBvh& hierarchy() const { return bvh_; }

 protected:
  RayHit closest_hit(const Ray3f& ray, RayCache& cache) const override;
  /// TriangleBvh::occluded does not say which triangle blocks the ray, so a
  /// blocked ray is shot again for its closest hit to refresh the occluder cache.
  std::uint32_t any_hit(const Ray3f& ray, RayCache& cache) const override;
  /// The packet traversal of bvh::TriangleBvh (no occluder cache: the packet
  /// does not say which triangle blocks a ray).
  bvh::HitPacket closest_hits(const bvh::RayPacket& packet, RayCache& cache) const override;
  std::uint32_t any_hits(const bvh::RayPacket& packet, RayCache& cache) const override;
  bvh::HitPacket16 closest_hits(const bvh::RayPacket16& packet, RayCache& cache) const override;
  std::uint32_t any_hits(const bvh::RayPacket16& packet, RayCache& cache) const override;

 private:
  explicit BvhAccelerator(const TriMesh& mesh) : Accelerator(mesh) {}
  explicit BvhAccelerator(const Archive& in) : Accelerator(in), bvh_(bvh::TriangleBvh::from_sections(in)) {}
  bvh::TriangleBvh bvh_;
};

}  // namespace geods::ray
