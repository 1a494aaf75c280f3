#pragma once
// The grid, the octree and the 5D classifier widen their cells and triangle
// boxes by a small margin, so that the triangle/box tests that fill them stay
// conservative under rounding.
#include "geods/core/aabb.hpp"

namespace geods::ray::detail {

/// The box widened by m on every side.
inline AABB3f widened(const AABB3f& box, float m) { return {box.lo.array() - m, box.hi.array() + m}; }

}  // namespace geods::ray::detail
