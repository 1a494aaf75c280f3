#pragma once
// Packets of rays traversed together through the wide AABB layout of
// TriangleBvh (issue 19; Wald et al.'s coherent ray packets, the peer of
// Embree's rtcIntersect8/rtcOccluded8). A packet holds up to kPacketSize = 8
// rays (one AVX register of floats per ray attribute) and an active mask. The
// rays share every node fetch, stack entry and ordering decision: at each
// wide node the packet's frustum (interval bounds of its rays) is tested
// against all children at once, and each child it keeps against all active
// rays (one 8-lane slab test; a child is visited when any lane hits it, with
// the mask of the lanes that do). At a leaf, when every ray is sheared along
// the same axes (coherent packets), at least 3 lanes are live and the CPU
// runs AVX, each triangle is tested against all lanes at once; else each
// live ray tests the leaf's triangle groups (RayTriangle4Test).
//
// Each ray's answer is bit-identical to the single-ray query: the slab test
// of a lane is the single-ray test's arithmetic, the triangle test is the
// same, so every ray reaches the same closest t; when two different
// triangles tie at a ray's closest t (a ray through a shared edge or vertex),
// which one the single ray keeps depends on its visiting order, so such a
// ray is shot again alone. Rays with a non-finite or zero direction, a
// non-finite origin or a NaN interval are shot alone too.
#include <cstdint>

#include "geods/core/ray.hpp"
#include "geods/core/ray_triangle.hpp"

namespace geods::bvh {

/// Rays per packet: 8, like rtcIntersect8 (an AVX register of floats).
inline constexpr int kPacketSize = 8;

/// Up to kPacketSize rays; bit i of `active` says whether rays[i] is shot.
struct RayPacket {
  Ray3f rays[kPacketSize];
  std::uint32_t active = (1u << kPacketSize) - 1;
};

/// The closest hit of each ray of a packet (no hit for inactive rays).
struct HitPacket {
  RayHit hits[kPacketSize];
};

}  // namespace geods::bvh
