#pragma once
// Morton (Z-order) codes: interleave the bits of 2 or 3 integer coordinates,
// x in the lowest bit. 32-bit codes hold 16 bits (2D) or 10 bits (3D) per
// coordinate; 64-bit codes hold 32 bits (2D) or 21 bits (3D).
#include <cstdint>
#include <vector>

#include "geods/core/aabb.hpp"

namespace geods {

namespace morton_detail {
// Spread the low bits of x so that there is one (2D) or two (3D) zero bits between them.
constexpr std::uint32_t spread2_32(std::uint32_t x) {
  x &= 0x0000ffffu;
  x = (x | (x << 8)) & 0x00ff00ffu;
  x = (x | (x << 4)) & 0x0f0f0f0fu;
  x = (x | (x << 2)) & 0x33333333u;
  x = (x | (x << 1)) & 0x55555555u;
  return x;
}
constexpr std::uint32_t compact2_32(std::uint32_t x) {
  x &= 0x55555555u;
  x = (x | (x >> 1)) & 0x33333333u;
  x = (x | (x >> 2)) & 0x0f0f0f0fu;
  x = (x | (x >> 4)) & 0x00ff00ffu;
  x = (x | (x >> 8)) & 0x0000ffffu;
  return x;
}
constexpr std::uint64_t spread2_64(std::uint64_t x) {
  x &= 0x00000000ffffffffull;
  x = (x | (x << 16)) & 0x0000ffff0000ffffull;
  x = (x | (x << 8)) & 0x00ff00ff00ff00ffull;
  x = (x | (x << 4)) & 0x0f0f0f0f0f0f0f0full;
  x = (x | (x << 2)) & 0x3333333333333333ull;
  x = (x | (x << 1)) & 0x5555555555555555ull;
  return x;
}
constexpr std::uint64_t compact2_64(std::uint64_t x) {
  x &= 0x5555555555555555ull;
  x = (x | (x >> 1)) & 0x3333333333333333ull;
  x = (x | (x >> 2)) & 0x0f0f0f0f0f0f0f0full;
  x = (x | (x >> 4)) & 0x00ff00ff00ff00ffull;
  x = (x | (x >> 8)) & 0x0000ffff0000ffffull;
  x = (x | (x >> 16)) & 0x00000000ffffffffull;
  return x;
}
constexpr std::uint32_t spread3_32(std::uint32_t x) {
  x &= 0x000003ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}
constexpr std::uint32_t compact3_32(std::uint32_t x) {
  x &= 0x09249249u;
  x = (x | (x >> 2)) & 0x030c30c3u;
  x = (x | (x >> 4)) & 0x0300f00fu;
  x = (x | (x >> 8)) & 0x030000ffu;
  x = (x | (x >> 16)) & 0x000003ffu;
  return x;
}
constexpr std::uint64_t spread3_64(std::uint64_t x) {
  x &= 0x00000000001fffffull;
  x = (x | (x << 32)) & 0x001f00000000ffffull;
  x = (x | (x << 16)) & 0x001f0000ff0000ffull;
  x = (x | (x << 8)) & 0x100f00f00f00f00full;
  x = (x | (x << 4)) & 0x10c30c30c30c30c3ull;
  x = (x | (x << 2)) & 0x1249249249249249ull;
  return x;
}
constexpr std::uint64_t compact3_64(std::uint64_t x) {
  x &= 0x1249249249249249ull;
  x = (x | (x >> 2)) & 0x10c30c30c30c30c3ull;
  x = (x | (x >> 4)) & 0x100f00f00f00f00full;
  x = (x | (x >> 8)) & 0x001f0000ff0000ffull;
  x = (x | (x >> 16)) & 0x001f00000000ffffull;
  x = (x | (x >> 32)) & 0x00000000001fffffull;
  return x;
}
}  // namespace morton_detail

/// Bits above the code's capacity per coordinate are ignored.
constexpr std::uint32_t morton2d_encode32(std::uint32_t x, std::uint32_t y) {
  return morton_detail::spread2_32(x) | (morton_detail::spread2_32(y) << 1);
}
constexpr std::uint64_t morton2d_encode64(std::uint32_t x, std::uint32_t y) {
  return morton_detail::spread2_64(x) | (morton_detail::spread2_64(y) << 1);
}
constexpr std::uint32_t morton3d_encode32(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return morton_detail::spread3_32(x) | (morton_detail::spread3_32(y) << 1) | (morton_detail::spread3_32(z) << 2);
}
constexpr std::uint64_t morton3d_encode64(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return morton_detail::spread3_64(x) | (morton_detail::spread3_64(y) << 1) | (morton_detail::spread3_64(z) << 2);
}

inline Vec<std::uint32_t, 2> morton2d_decode32(std::uint32_t code) {
  return {morton_detail::compact2_32(code), morton_detail::compact2_32(code >> 1)};
}
inline Vec<std::uint32_t, 2> morton2d_decode64(std::uint64_t code) {
  return {std::uint32_t(morton_detail::compact2_64(code)), std::uint32_t(morton_detail::compact2_64(code >> 1))};
}
inline Vec3u morton3d_decode32(std::uint32_t code) {
  return {morton_detail::compact3_32(code), morton_detail::compact3_32(code >> 1), morton_detail::compact3_32(code >> 2)};
}
inline Vec3u morton3d_decode64(std::uint64_t code) {
  return {std::uint32_t(morton_detail::compact3_64(code)), std::uint32_t(morton_detail::compact3_64(code >> 1)),
          std::uint32_t(morton_detail::compact3_64(code >> 2))};
}

/// 64-bit Morton codes of points quantized to the 2^32 (2D) or 2^21 (3D) grid
/// over `box` (points outside are clamped). Computed in parallel.
std::vector<std::uint64_t> morton_codes(const std::vector<Vec2d>& points, const AABB2d& box);
std::vector<std::uint64_t> morton_codes(const std::vector<Vec3d>& points, const AABB3d& box);

/// The permutation that sorts the points along the Z-order curve (ties by index,
/// so the order is deterministic).
std::vector<std::uint32_t> morton_order(const std::vector<Vec2d>& points);
std::vector<std::uint32_t> morton_order(const std::vector<Vec3d>& points);

}  // namespace geods
