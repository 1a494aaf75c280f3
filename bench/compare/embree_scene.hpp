#pragma once
// The Embree 3 scene of one triangle mesh (RTC_BUILD_QUALITY_MEDIUM) and the device
// holding it, shared by the single-ray and the packet programs of bench/compare so
// both time the same build.
#include <embree3/rtcore.h>

#include <algorithm>
#include <memory>
#include <string>

#include "common.hpp"

/// A committed scene of `mesh` on `device`; the caller releases it. With
/// GEODS_EMBREE_ROBUST the scene is RTC_SCENE_FLAG_ROBUST: conservative box tests
/// and the watertight Pluecker triangle test, the like of geods' traversal.
inline RTCScene embree_mesh_scene(RTCDevice device, const compare::PlyMesh& mesh) {
  RTCScene scene = rtcNewScene(device);
#ifdef GEODS_EMBREE_ROBUST
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
#endif
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices()));
  std::copy(mesh.xyz.begin(), mesh.xyz.end(), v);
  auto* f = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                           3 * sizeof(unsigned), mesh.triangles()));
  std::copy(mesh.tris.begin(), mesh.tris.end(), f);
  rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_MEDIUM);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  return scene;
}

/// An Embree device of `threads` threads and its scene, released together.
struct EmbreeIndex {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  explicit EmbreeIndex(int threads) {
    const std::string config = "threads=" + std::to_string(threads);
    device = rtcNewDevice(config.c_str());
  }
  EmbreeIndex(const EmbreeIndex&) = delete;
  EmbreeIndex& operator=(const EmbreeIndex&) = delete;
  ~EmbreeIndex() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};
