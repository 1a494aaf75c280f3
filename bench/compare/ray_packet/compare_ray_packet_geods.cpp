// geods::bvh::TriangleBvh (binned SAH, AABB, 8 wide as in the ray comparison)
// on the packet comparison: packets of 8 rays (4 x 2 pixels), intersect /
// occluded of bvh::RayPacket (bvh/ray_packet.hpp), dispatched by simd_level().
// GEODS_RAY_PACKET_16: packets of 16 rays (4 x 4 pixels, bvh::RayPacket16).
// GEODS_RAY_PACKET_SINGLE: the 4 x 2 tiles one ray at a time (the reference).
#include "../ray/geods_mesh.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "ray_packet_driver.hpp"

namespace {

struct Geods {
#if defined(GEODS_RAY_PACKET_SINGLE)
  static constexpr const char* anchor = "geods_single";
#elif defined(GEODS_RAY_PACKET_16)
  static constexpr const char* anchor = "geods16";
#else
  static constexpr const char* anchor = "geods";
#endif
#if defined(GEODS_RAY_PACKET_16)
  static constexpr int kTileW = 4, kTileH = 4;
#else
  static constexpr int kTileW = 4, kTileH = 2;
#endif
  using Index = geods::bvh::TriangleBvh;
  static std::unique_ptr<Index> build(const compare::PlyMesh& ply) {
    geods::bvh::BuildOptions options;
    options.arity = 8;
    return std::make_unique<Index>(Index::build(compare::ray::geods_mesh(ply), options));
  }
  static void trace(const Index& bvh, const float* r, int n, bool any, compare::ray_packet::Hit* hits) {
    geods::bvh::RayPacketN<kTileW * kTileH> packet;
    packet.active = (1u << n) - 1;
    for (int i = 0; i < n; ++i) {
      packet.rays[i].origin = {r[6 * i], r[6 * i + 1], r[6 * i + 2]};
      packet.rays[i].direction = {r[6 * i + 3], r[6 * i + 4], r[6 * i + 5]};
    }
#if defined(GEODS_RAY_PACKET_SINGLE)
    for (int i = 0; i < n; ++i) {
      if (any) {
        hits[i] = bvh.occluded(packet.rays[i]) ? compare::ray_packet::Hit{0.0f, 0} : compare::ray_packet::Hit{};
      } else {
        const geods::RayHit h = bvh.intersect(packet.rays[i]);
        hits[i] = {h.t, h.prim};
      }
    }
#else
    if (any) {
      const std::uint32_t mask = bvh.occluded(packet);
      for (int i = 0; i < n; ++i)
        hits[i] = (mask >> i & 1) ? compare::ray_packet::Hit{0.0f, 0} : compare::ray_packet::Hit{};
    } else {
      const geods::bvh::HitPacketN<kTileW * kTileH> out = bvh.intersect(packet);
      for (int i = 0; i < n; ++i) hits[i] = {out.hits[i].t, out.hits[i].prim};
    }
#endif
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::ray_packet::run<Geods>(argc, argv); }
