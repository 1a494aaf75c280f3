#pragma once
// An edge of a diagram clipped to a box: the piece of the bisector of sites
// a < b between p0 and p1 (the Voronoi diagram in L1/L∞, the power diagram,
// the farthest-point diagram).
#include <cstdint>

#include "geods/core/vec.hpp"

namespace geods::voronoi {

struct BisectorEdge {
  std::uint32_t a, b;
  Vec2d p0, p1;
};

}  // namespace geods::voronoi
