#pragma once
// Embree 3 (RTC_BUILD_QUALITY_MEDIUM, rtcIntersect1 / rtcOccluded1 one ray at a time) as a
// library of the ray comparison (ray_driver.hpp); with GEODS_EMBREE_ROBUST defined, the
// scene takes RTC_SCENE_FLAG_ROBUST (embree_scene.hpp).
#include <embree3/rtcore.h>

#include <limits>
#include <memory>

#include "embree_scene.hpp"
#include "ray_driver.hpp"

namespace compare::ray {

struct Embree {
#ifdef GEODS_EMBREE_ROBUST
  static constexpr const char* anchor = "embree_robust";
#else
  static constexpr const char* anchor = "embree";
#endif
  using Index = EmbreeIndex;
  static inline int threads = 1;
  static std::unique_ptr<Index> build(const PlyMesh& mesh) {
    auto index = std::make_unique<Index>(threads);
    index->scene = embree_mesh_scene(index->device, mesh);
    return index;
  }
  static Hit intersect(const Index& index, const float* r) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = r[0], rh.ray.org_y = r[1], rh.ray.org_z = r[2];
    rh.ray.dir_x = r[3], rh.ray.dir_y = r[4], rh.ray.dir_z = r[5];
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u;
    rh.ray.flags = 0;
    rh.ray.time = 0.0f;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(index.scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    return {rh.ray.tfar, rh.hit.primID};
  }
  static bool occluded(const Index& index, const float* r) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = r[0], ray.org_y = r[1], ray.org_z = r[2];
    ray.dir_x = r[3], ray.dir_y = r[4], ray.dir_z = r[5];
    ray.tnear = 0.0f;
    ray.tfar = std::numeric_limits<float>::infinity();
    ray.mask = ~0u;
    ray.flags = 0;
    ray.time = 0.0f;
    rtcOccluded1(index.scene, &context, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
  }
};

}  // namespace compare::ray
