#pragma once
// The packed node of the wide (4- or 8-ary) AABB layout used by the ray
// queries of TriangleBvh: the boxes of all children side by side, one row per
// bound, so that one SIMD operation tests a ray against every child (GCC/Clang
// vector extensions: SSE for 4 wide, AVX when available for 8 wide, plain
// scalar code elsewhere).
#include <cstdint>
#include <limits>

namespace geods::bvh {

template <int W>
struct alignas(64) WideNode {  // whole cache lines: 128 bytes (4 wide), 256 (8 wide)
  static_assert(W == 4 || W == 8, "wide nodes hold 4 or 8 children");
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  /// bounds[2 a][i] = lo of child i on axis a, bounds[2 a + 1][i] = hi.
  /// Empty slots hold lo = +inf, hi = -inf, which no ray interval without
  /// NaN overlaps (the traversal drops them by child index otherwise).
  float bounds[6][W];
  /// Inner child (count 0): index of its WideNode; leaf child (count > 0): its
  /// first TriangleGroup (ray_triangle4.hpp) and count = its number of groups;
  /// empty slot: kEmpty with count 0.
  std::uint32_t child[W];
  std::uint32_t count[W];
};

}  // namespace geods::bvh
