#pragma once
// The power diagram of weighted points and its dual, the regular (weighted
// Delaunay) triangulation (seed §5.3.3, "Weights").
//
// The power of a point x with respect to site p of weight w is |x - p|^2 - w
// (a circle of radius sqrt(w) around p for w >= 0). The power cell of p is the
// set of points whose power is smallest for p: a convex polygon, possibly
// empty. Its dual, the regular triangulation, is the projection of the lower
// convex hull of the lifted points (x, y, x^2 + y^2 - w); with equal weights it
// is the Delaunay triangulation and the power diagram is the Voronoi diagram.
//
// Construction: incremental insertion in BRIO order on DelaunayCore's arrays
// (walk, split, flip), with Edelsbrunner and Shah's flips: 2-2 where the
// quadrilateral is convex, 3-1 where a vertex of degree 3 becomes redundant,
// and 4-2 where a vertex of degree 4 lies on the new diagonal. Every decision
// is exact: orient2d, and power_test below (a filter, then big integers).
//
// Degenerate input, the rules:
//  - A point is redundant when its power cell has an empty interior (its lift
//    is not strictly below the lower hull of the others: on a face counts as
//    redundant). Redundant points are in no triangle, their cells are empty,
//    and redundant() lists them. Points on the convex hull's corners are never
//    redundant.
//  - Equal points: the heaviest is the site and the lighter ones are
//    redundant; equal points of equal weight are duplicates of the first
//    occurrence (representative()), which share its cell (or its redundancy).
//  - Ties of the power test (four lifted points on a plane, the weighted
//    co-circular case) are not conflicts: one of the valid regular
//    triangulations is returned, as Delaunay2 does for co-circular points.
//  - All points collinear (or fewer than 3 distinct): no triangles,
//    degenerate() is true, and chain() is the non-redundant sites along their
//    line (the lower hull of the lifted line); cells are parallel strips.
//  - NaN or infinite coordinates or weights, mismatched sizes, no points:
//    geods::Error. Coordinates follow the range rule of
//    core/coordinate_range.hpp (power centres are cubic: degree 3); |weights|
//    must stay below the square of that limit.
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/bisector_edge.hpp"

namespace geods::voronoi {

/// For counter-clockwise a, b, c: > 0 if the lift of (d, wd) lies strictly
/// below the plane through the lifts of (a, wa), (b, wb), (c, wc) (d "in
/// conflict"; for equal weights: d inside the circle through a, b, c), < 0 above,
/// 0 on it. The sign flips for clockwise a, b, c. The sign is exact for any
/// finite input (a floating-point filter, then big integers).
int power_test(const Vec2d& a, double wa, const Vec2d& b, double wb, const Vec2d& c, double wc, const Vec2d& d,
               double wd);

/// For collinear a, m, b with m strictly between a and b: > 0 if the lift of
/// (m, wm) lies strictly below the segment between the lifts of (a, wa) and
/// (b, wb) (m keeps a cell between them), < 0 above, 0 on it. Exact.
int collinear_power_test(const Vec2d& a, double wa, const Vec2d& m, double wm, const Vec2d& b, double wb);

struct RegularTriangulationStats {
  std::size_t points = 0;      // input points
  std::size_t vertices = 0;    // sites with a cell (vertices of the triangulation)
  std::size_t redundant = 0;   // points whose cell has an empty interior (lighter equal points included)
  std::size_t duplicates = 0;  // equal points of equal weight merged into their first occurrence
  std::size_t triangles = 0;
  std::size_t hull = 0;
  std::size_t flips = 0;     // 2-2 flips
  std::size_t removals = 0;  // 3-1 and 4-2 flips (a vertex became redundant)
};

class RegularTriangulation {
 public:
  static constexpr std::uint32_t no_edge = std::uint32_t(-1);

  /// Throws geods::Error for no points, a weight count other than the point
  /// count, non-finite values, or coordinates or weights out of range.
  RegularTriangulation(std::span<const Vec2d> points, std::span<const double> weights, std::uint64_t seed = 0x5eed);

  std::span<const Vec2d> points() const { return points_; }
  std::span<const double> weights() const { return weights_; }
  /// Counter-clockwise triangles, three input indices each (sites only).
  const std::vector<std::uint32_t>& triangles() const { return triangles_; }
  /// The opposite half-edge of each half-edge, no_edge on the hull.
  const std::vector<std::uint32_t>& halfedges() const { return halfedges_; }
  /// Hull sites counter-clockwise (collinear hull sites included); for a degenerate set, chain().
  const std::vector<std::uint32_t>& hull() const { return hull_; }
  /// Degenerate sets: the sites sorted along their line. Empty otherwise.
  const std::vector<std::uint32_t>& chain() const { return chain_; }
  bool degenerate() const { return triangles_.empty(); }
  std::size_t triangle_count() const { return triangles_.size() / 3; }

  /// The point that stands for point i: i itself, or the first occurrence of an
  /// equal point of equal weight.
  std::uint32_t representative(std::uint32_t i) const { return representative_[i]; }
  /// Whether point i (through its representative) has an empty power cell.
  bool is_redundant(std::uint32_t i) const { return redundant_flag_[representative_[i]] != 0; }
  /// The redundant points, ascending (duplicates of redundant points included).
  std::vector<std::uint32_t> redundant() const;
  /// The neighbours of site i (a representative) in the triangulation (for a
  /// degenerate set, along the chain), ascending; empty for a redundant point.
  std::span<const std::uint32_t> neighbors(std::uint32_t site) const {
    return {neighbors_.data() + neighbor_offsets_[site], neighbors_.data() + neighbor_offsets_[site + 1]};
  }

  RegularTriangulationStats stats() const;
  /// Checks that triangles are counter-clockwise, twins mutual, every interior
  /// edge locally regular (exact power_test <= 0), and every redundant
  /// representative not below the triangle or hull edge under it. Throws geods::Error.
  void validate() const;

 private:
  void build(std::uint64_t seed);
  void build_collinear();
  void build_neighbors();

  std::vector<Vec2d> points_;
  std::vector<double> weights_;
  std::vector<std::uint32_t> representative_;
  std::vector<std::uint8_t> redundant_flag_;
  std::vector<std::uint32_t> triangles_, halfedges_, hull_, chain_;
  std::vector<std::uint32_t> neighbor_offsets_, neighbors_;
  std::size_t flips_ = 0, removals_ = 0;
};

struct PowerDiagramStats {
  std::size_t sites = 0, cells = 0, redundant = 0, edges = 0, cell_vertices = 0;
};

/// The power diagram clipped to a box: each cell cut out of the box by the
/// power bisectors of its site and its neighbours in the regular triangulation
/// (floating point, O(n) for the whole diagram after the triangulation).
class PowerDiagram {
 public:
  /// A piece of the power bisector of sites a < b inside the box.
  using Edge = BisectorEdge;

  /// Throws geods::Error as RegularTriangulation, or for an empty box.
  PowerDiagram(std::span<const Vec2d> points, std::span<const double> weights, const AABB2d& box);
  PowerDiagram(RegularTriangulation triangulation, const AABB2d& box);

  const RegularTriangulation& triangulation() const { return triangulation_; }
  std::span<const Vec2d> points() const { return triangulation_.points(); }
  std::span<const double> weights() const { return triangulation_.weights(); }
  const AABB2d& box() const { return box_; }
  /// The cell of each point clipped to the box, counter-clockwise; empty for a
  /// redundant point or a cell that misses the box; duplicates repeat their
  /// representative's cell.
  const std::vector<std::vector<Vec2d>>& cells() const { return cells_; }
  const std::vector<Edge>& edges() const { return edges_; }

  PowerDiagramStats stats() const;
  /// Checks that every cell is a counter-clockwise polygon in the box and that
  /// both ends of every edge have equal power for its two sites. Throws geods::Error.
  void validate() const;

 private:
  RegularTriangulation triangulation_;
  AABB2d box_;
  std::vector<std::vector<Vec2d>> cells_;
  std::vector<Edge> edges_;
};

/// The power of x with respect to (p, w): |x - p|^2 - w.
inline double power_distance(const Vec2d& x, const Vec2d& p, double w) { return (x - p).squaredNorm() - w; }

}  // namespace geods::voronoi
