// Embree 3 (RTC_BUILD_QUALITY_MEDIUM) packet API on the packet comparison:
// rtcIntersect8/rtcOccluded8 on 4 x 2 pixel tiles, or with
// GEODS_EMBREE_PACKET=16 rtcIntersect16/rtcOccluded16 on 4 x 4 tiles where the
// CPU and the library support 16-wide packets
// (RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED; elsewhere the program exits
// with compare::kUnavailable).
#include <embree3/rtcore.h>

#include "embree_scene.hpp"
#include "ray_packet_driver.hpp"

#ifndef GEODS_EMBREE_PACKET
#define GEODS_EMBREE_PACKET 8
#endif

namespace {

template <int N>
struct PacketTypes;
template <>
struct PacketTypes<8> {
  using RayHitN = RTCRayHit8;
  using RayN = RTCRay8;
};
template <>
struct PacketTypes<16> {
  using RayHitN = RTCRayHit16;
  using RayN = RTCRay16;
};

// rtcIntersect8/16 and rtcOccluded8/16 by the packet type.
inline void intersect_n(const int* valid, RTCScene s, RTCIntersectContext* c, RTCRayHit8* r) { rtcIntersect8(valid, s, c, r); }
inline void intersect_n(const int* valid, RTCScene s, RTCIntersectContext* c, RTCRayHit16* r) { rtcIntersect16(valid, s, c, r); }
inline void occluded_n(const int* valid, RTCScene s, RTCIntersectContext* c, RTCRay8* r) { rtcOccluded8(valid, s, c, r); }
inline void occluded_n(const int* valid, RTCScene s, RTCIntersectContext* c, RTCRay16* r) { rtcOccluded16(valid, s, c, r); }

struct Embree {
  static constexpr int N = GEODS_EMBREE_PACKET;
  static constexpr const char* anchor = N == 16 ? "embree16" : "embree8";
  static constexpr int kTileW = 4, kTileH = N / 4;
  using Index = EmbreeIndex;
  static inline int threads = 1;
  static std::unique_ptr<Index> build(const compare::PlyMesh& mesh) {
    auto index = std::make_unique<Index>(threads);
    const int property = N == 16 ? RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED : RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED;
    if (!rtcGetDeviceProperty(index->device, RTCDeviceProperty(property))) {
      std::fprintf(stderr, "Embree %s has no native packets of %d on this CPU\n", RTC_VERSION_STRING, N);
      std::exit(compare::kUnavailable);
    }
    index->scene = embree_mesh_scene(index->device, mesh);
    return index;
  }
  template <class RayN>
  static void fill(RayN& ray, const float* r, int n, int valid[]) {
    for (int i = 0; i < N; ++i) {
      const int k = i < n ? i : 0;
      ray.org_x[i] = r[6 * k], ray.org_y[i] = r[6 * k + 1], ray.org_z[i] = r[6 * k + 2];
      ray.dir_x[i] = r[6 * k + 3], ray.dir_y[i] = r[6 * k + 4], ray.dir_z[i] = r[6 * k + 5];
      ray.tnear[i] = 0.0f;
      ray.tfar[i] = std::numeric_limits<float>::infinity();
      ray.mask[i] = ~0u;
      ray.flags[i] = 0;
      ray.time[i] = 0.0f;
      ray.id[i] = unsigned(i);
      valid[i] = i < n ? -1 : 0;
    }
  }
  static void trace(const Index& index, const float* r, int n, bool any, compare::ray_packet::Hit* hits) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) int valid[N];
    if (any) {
      alignas(64) typename PacketTypes<N>::RayN ray;
      fill(ray, r, n, valid);
      occluded_n(valid, index.scene, &context, &ray);
      for (int i = 0; i < n; ++i)
        hits[i] = ray.tfar[i] < 0 ? compare::ray_packet::Hit{0.0f, 0} : compare::ray_packet::Hit{};
      return;
    }
    alignas(64) typename PacketTypes<N>::RayHitN rh;
    fill(rh.ray, r, n, valid);
    for (int i = 0; i < N; ++i) rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID, rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    intersect_n(valid, index.scene, &context, &rh);
    for (int i = 0; i < n; ++i)
      hits[i] = rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? compare::ray_packet::Hit{}
                                                            : compare::ray_packet::Hit{rh.ray.tfar[i], rh.hit.primID[i]};
  }
};

}  // namespace

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  Embree::threads = args.threads;
  return compare::ray_packet::run<Embree>(argc, argv);
}
