#pragma once
// The constrained (bounded) Voronoi diagram VD(S, L) of seed §5.3.2: sites S
// and non-crossing segments L between sites, which block sight. The bounded
// distance b(x, p) is |x - p| when the segment xp crosses no segment of L,
// infinite otherwise; the region of p holds the points to which p is the
// nearest site by b. Regions of sites that are close but do not see each
// other are separated by the segments (Figure 49).
//
// Construction on the constrained Delaunay triangulation DT(S, L) (Delaunay2
// with segments): the box is cut into convex pieces, the triangles of DT(S, L)
// and, outside the hull, a strip beyond each hull edge and a wedge at each hull
// corner. Every point of a piece sees one anchor site (a corner of its triangle,
// the hull vertex of its strip or wedge), so only sites within the anchor's
// reach B over the piece can be nearer. Each piece is cut further by the lines
// through a candidate site and the ends of a segment that may hide it (the
// shadow boundaries), so that in each cell the visible candidates are the same
// (decided with exact orientation tests at a point inside the cell); the cell
// is then split among its visible candidates by their bisectors. A region is
// a list of convex pieces. Floating point for the polygons; about O(n c^2 s)
// for c candidates and s segments near a triangle (small on sparse
// constraints; dense segment clusters cost more).
//
// Degenerate input: segments that cross each other (other than at shared end
// points) are an error (L must not cross); a segment through a site is split
// there (Delaunay2); zero-length segments (i, i) and indices out of range are
// errors; duplicates share the region of their first occurrence; collinear
// sites give the ordinary Voronoi diagram (segments on their line block no
// area). NaN or infinite coordinates, no points or an empty box: geods::Error.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

struct ConstrainedVoronoiStats {
  std::size_t sites = 0, distinct = 0, segments = 0, pieces = 0, cells = 0, max_candidates = 0;
};

class ConstrainedVoronoi {
 public:
  using Segment = std::array<std::uint32_t, 2>;
  struct Piece {
    std::uint32_t site;
    std::vector<Vec2d> polygon;  // convex, counter-clockwise
  };

  ConstrainedVoronoi(std::span<const Vec2d> points, std::span<const Segment> segments, const AABB2d& box);

  std::span<const Vec2d> points() const { return points_; }
  const AABB2d& box() const { return box_; }
  /// The constraint edges (segments split at sites on them), as point index pairs.
  const std::vector<Segment>& constraints() const { return constraints_; }
  std::uint32_t representative(std::uint32_t i) const { return representative_[i]; }
  /// The diagram as convex pieces, each in the region of one site (a representative); they tile the box.
  const std::vector<Piece>& pieces() const { return pieces_; }
  /// Whether the segment from x to site p crosses no constraint (the bounded distance is finite).
  bool visible(const Vec2d& x, std::uint32_t p) const;

  ConstrainedVoronoiStats stats() const;
  /// Checks that pieces are counter-clockwise convex polygons in the box, each
  /// seeing its site from its centroid. Throws geods::Error.
  void validate() const;

 private:
  std::vector<Vec2d> points_;
  std::vector<std::uint32_t> representative_;
  std::vector<Segment> constraints_;
  AABB2d box_;
  std::vector<Piece> pieces_;
  std::size_t cells_ = 0, max_candidates_ = 0;
};

}  // namespace geods::voronoi
