#pragma once
// Packets of rays traversed together through the wide AABB layout of
// TriangleBvh (issue 19; Wald et al.'s coherent ray packets, the peer of
// Embree's rtcIntersect8/16 and rtcOccluded8/16). A packet holds up to N = 8
// or 16 rays (one AVX or AVX-512 register of floats per ray attribute) and an
// active mask. The rays share every node fetch, stack entry and ordering
// decision: at each wide node the packet's frustum (interval bounds of its
// rays) is tested against all children at once, and each child it keeps
// against all active rays (one N-lane slab test; a child is visited when any
// lane hits it, with the mask of the lanes that do). At a leaf, when every ray
// is sheared along the same axes (coherent packets), at least 3 lanes are live
// and the CPU runs AVX, each triangle is tested against all lanes at once;
// else each live ray tests the leaf's triangle groups (RayTriangle4Test).
// Packets of 16 are traced 16 lanes wide where the CPU runs AVX-512, else as
// two packets of 8 (its rays 0-7 and 8-15).
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

/// Rays per packet of RayPacket: 8, like rtcIntersect8 (an AVX register of
/// floats); RayPacket16 holds 16, like rtcIntersect16 (AVX-512).
inline constexpr int kPacketSize = 8;

/// Up to N rays (N = 8 or 16); bit i of `active` says whether rays[i] is shot.
template <int N>
struct RayPacketN {
  static_assert(N == 8 || N == 16, "packets of 8 or 16 rays");
  static constexpr int size = N;
  Ray3f rays[N];
  std::uint32_t active = (1u << N) - 1;
};

/// The closest hit of each ray of a packet (no hit for inactive rays).
template <int N>
struct HitPacketN {
  static_assert(N == 8 || N == 16, "packets of 8 or 16 rays");
  RayHit hits[N];
};

using RayPacket = RayPacketN<kPacketSize>;
using HitPacket = HitPacketN<kPacketSize>;
using RayPacket16 = RayPacketN<16>;
using HitPacket16 = HitPacketN<16>;

}  // namespace geods::bvh
