#pragma once
// The convex hull of a 3D point set (Quickhull with exact orientation tests):
// the combinatorial decisions use the exact orient3d of predicates.hpp, so the
// result is a closed, convex, consistently oriented triangulated surface for
// any finite input, including coplanar and duplicate points.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/vec.hpp"

namespace geods {

struct ConvexHull3 {
  /// Affine dimension of the points: -1 none, 0 all equal, 1 collinear,
  /// 2 coplanar, 3 a solid hull.
  int dimension = -1;
  /// Indices of the input points that are corners of the hull, ascending.
  /// Points inside a face or an edge are not corners. For dimension 2 these are
  /// the corners of the planar hull polygon, for dimension 1 the two ends, for
  /// dimension 0 the first point.
  std::vector<std::uint32_t> vertices;
  /// Dimension 3 only: triangles over input indices, counter-clockwise seen from
  /// outside. Coplanar neighbouring faces are not merged.
  std::vector<std::array<std::uint32_t, 3>> faces;
};

/// Throws geods::Error for a NaN or infinite coordinate, or for more than
/// 2^32 - 1 points. Expected O(n log n).
ConvexHull3 convex_hull3(std::span<const Vec3d> points);

}  // namespace geods
