#pragma once
// Voronoi diagrams of points under the L1 (Manhattan), L-infinity (Chebyshev)
// and Euclidean metrics (seed §5.3.3, Figure 46), as cells and edges clipped to a box.
//
// Under L1 the bisector of two sites is a polyline: two axis-parallel rays
// joined by a 45-degree segment (vertical rays when |dx| > |dy|, horizontal
// when |dy| > |dx|). L-infinity is L1 turned by 45 degrees (max(|x|, |y|) =
// (|x + y| + |x - y|) / 2), so its bisectors have a segment parallel to an axis
// and diagonal rays. Cells are star-shaped around their site but not always
// convex, and more than three cells can meet where bisectors overlap.
//
// Degenerate pairs: when |dx| = |dy| the L1 bisector contains two quadrants of
// points equidistant from both sites. Convention: such a quadrant belongs to
// the site nearer to it in x, so the bisector is the diagonal segment with
// vertical rays (the limit of |dx| > |dy|); under L-infinity the same rule in
// the turned frame gives diagonal rays. It is implemented by adding
// 1e-9 * |x - site_x| (L1; |(x - site_x) + (y - site_y)| for L-infinity) to the
// distances, which moves no boundary by more than 1e-9 of its distance to the sites.
//
// Under L2 the diagram is Voronoi2's (the dual of the Delaunay triangulation,
// exact predicates) clipped to the box. Under L1 and L-infinity each cell is
// cut out of a frame around the box and the sites
// by the bisectors of its site and its 16 nearest sites; farther sites are then
// offered nearest first and join only if they take part of the current cell
// (some point of its boundary is nearer to them; a site's region is star-shaped
// around it, so that catches every one that matters), until they are farther
// than twice the cell's reach (d(p, q) > 2 max_{x in cell} d(p, x)). Each
// bisector piece keeps the parts not nearer to another site, decided on the
// piecewise-linear distance functions along it, and the pieces are joined
// around the site. About O(n k^2) for k ~ 20 sites per cell on spread-out
// sites, more for cells that reach far (sites on the hull); in parallel;
// floating point, not exact predicates.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/bisector_edge.hpp"

namespace geods::voronoi {

enum class Metric { l2, l1, linf };

/// "l2", "l1", "linf".
std::string metric_name(Metric metric);
/// Parses "l2", "l1", "linf" (also "euclidean", "manhattan", "chebyshev"); throws geods::Error otherwise.
Metric parse_metric(const std::string& name);
/// The distance between a and b under `metric`.
double metric_distance(Metric metric, const Vec2d& a, const Vec2d& b);

struct MetricVoronoiStats {
  std::size_t sites = 0, distinct = 0;
  std::size_t edges = 0;           // bisector pieces in the box
  std::size_t cell_vertices = 0;   // summed over the cells
  std::size_t max_candidates = 0;  // most sites consulted for one cell (L2: most Delaunay neighbours of a site)
};

class MetricVoronoi {
 public:
  /// A piece of the diagram inside the box: part of the bisector of sites a < b (representatives).
  using Edge = BisectorEdge;

  /// Throws geods::Error for no points, 2^30 or more, non-finite coordinates or
  /// ones beyond +-3.5e100 (core/coordinate_range.hpp), an empty box, or
  /// (L1, L-infinity) distinct points closer than 1e-6 of the extent of the
  /// box and the points, which the construction cannot resolve (docs/voronoi.md).
  MetricVoronoi(std::span<const Vec2d> points, Metric metric, const AABB2d& box);

  Metric metric() const { return metric_; }
  const AABB2d& box() const { return box_; }
  std::span<const Vec2d> points() const { return points_; }
  std::uint32_t representative(std::uint32_t i) const { return representative_[i]; }
  /// The cell of each point clipped to the box, counter-clockwise (duplicates repeat
  /// their first occurrence's cell; empty if the cell misses the box).
  const std::vector<std::vector<Vec2d>>& cells() const { return cells_; }
  const std::vector<Edge>& edges() const { return edges_; }

  MetricVoronoiStats stats() const;
  /// Checks that every cell is a counter-clockwise polygon inside the box,
  /// that the cells cover the box, that every site inside the box is inside
  /// its cell, and that both ends of every edge are equidistant from its two
  /// sites. Throws geods::Error.
  void validate() const;

 private:
  std::vector<Vec2d> points_;
  std::vector<std::uint32_t> representative_;
  Metric metric_;
  AABB2d box_;
  std::vector<std::vector<Vec2d>> cells_;
  std::vector<Edge> edges_;
  std::size_t max_candidates_ = 0;
};

}  // namespace geods::voronoi
