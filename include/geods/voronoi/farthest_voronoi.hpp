#pragma once
// The farthest-point Voronoi diagram (seed §5.3.3): the cell of site p is the
// set of points to which p is the farthest site. Only the corners of the
// convex hull have cells (non-empty and unbounded), and the diagram is a tree
// through the centre of the smallest enclosing circle. The cells are cut out of a box by the bisectors of the
// hull corners (floating point; the hull and its corners are decided with the
// exact orient2d): O(n log n + h^2) for h corners.
//
// Degenerate input: points inside the hull or on a hull edge (not corners)
// have empty cells; duplicates share the cell of their first occurrence
// (representative()); collinear points: the two extreme points split the plane
// by their bisector; a single distinct point owns the whole box. NaN or
// infinite coordinates, no points or an empty box: geods::Error.
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/bisector_edge.hpp"

namespace geods::voronoi {

struct FarthestVoronoiStats {
  std::size_t sites = 0, distinct = 0, corners = 0, edges = 0, cell_vertices = 0;
};

class FarthestVoronoi {
 public:
  /// A piece of the bisector of corners a < b inside the box.
  using Edge = BisectorEdge;

  FarthestVoronoi(std::span<const Vec2d> points, const AABB2d& box);

  std::span<const Vec2d> points() const { return points_; }
  const AABB2d& box() const { return box_; }
  std::uint32_t representative(std::uint32_t i) const { return representative_[i]; }
  /// The hull corners counter-clockwise (for collinear points the two extremes): the sites with a cell.
  const std::vector<std::uint32_t>& corners() const { return corners_; }
  /// The cell of each point clipped to the box, counter-clockwise; empty for points that are not corners.
  const std::vector<std::vector<Vec2d>>& cells() const { return cells_; }
  const std::vector<Edge>& edges() const { return edges_; }

  FarthestVoronoiStats stats() const;
  /// Checks that cells are counter-clockwise polygons in the box and that both
  /// ends of every edge are equidistant from its two sites. Throws geods::Error.
  void validate() const;

 private:
  std::vector<Vec2d> points_;
  std::vector<std::uint32_t> representative_, corners_;
  AABB2d box_;
  std::vector<std::vector<Vec2d>> cells_;
  std::vector<Edge> edges_;
};

}  // namespace geods::voronoi
