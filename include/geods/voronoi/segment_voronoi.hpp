#pragma once
// The Voronoi diagram of line segments and points (seed §5.3.3, Figure 47) and
// the medial axis of a polygon taken from it.
//
// Sites: points and closed segments that meet only at shared endpoints. Each
// segment is split into three elementary sites, its two endpoints and its open
// interior, so that every bisector is a line (point-point, segment-segment, a
// segment and its own endpoint) or a parabolic arc (a point and a segment's
// interior). Edges keep that exact description (`EdgeCurve`) and are sampled
// only for drawing and path output (`sample_edge`).
//
// Input rules (each tested):
// - coordinates must be finite (geods::Error otherwise);
// - the input is snapped to an integer grid: x -> round((x - c) * 2^k) with c
//   the centre of the bounding box and 2^k the largest power of two that
//   keeps every snapped coordinate within +-2^25 (so the grid step is about
//   3e-8 of the half-extent, and integer input of extent below 2^25 is kept
//   exactly). All combinatorial decisions are made on the snapped
//   coordinates; `snapped_point` gives them back in input units;
// - crossing segments are split at their intersection (the rounded crossing
//   point), and a segment with an endpoint in another's interior is split
//   there; `split_count()` says how many cuts were made (a crossing cuts both
//   segments);
// - zero-length segments (after the snap) become point sites, duplicate
//   points and segments are kept once, a point site on a segment's interior
//   splits the segment there;
// - collinear overlapping segments raise geods::Error.
//
// Construction: Fortune's sweep generalized to segments (the structure of
// Boost.Polygon's voronoi_builder, written anew): site events for points and
// segments, circle events for every triple of point/segment sites.
// Every predicate is exact on the snapped integers, no epsilon: orientation
// tests in doubles and 128-bit integers; the tangent circles (closed forms
// with integer coefficients and the segment lengths, the root chosen by the
// cyclic order of the tangency points), their order, and site-against-circle
// and centre-against-vertical-segment tests by a double interval filter and,
// when it cannot decide, MPFR balls evaluated past the expression's BFMSS
// separation bound (docs/voronoi.md, "Predicates (exact)").
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

struct SegmentVoronoiStats {
  std::size_t input_points = 0, input_segments = 0;
  std::size_t points = 0, segments = 0;  // after splitting and removing duplicates
  std::size_t splits = 0;                // cuts made in segments at crossings and touching points
  std::size_t vertices = 0, edges = 0;
  std::size_t parabolic_edges = 0, secondary_edges = 0, infinite_edges = 0;
  std::size_t bytes = 0;
};

class SegmentVoronoi {
 public:
  static constexpr std::uint32_t kInfinity = std::numeric_limits<std::uint32_t>::max();

  /// A Voronoi vertex: its position and its distance to its nearest sites.
  struct Vertex {
    Vec2d position;
    double clearance = 0;
  };
  /// One Voronoi edge (not a half-edge): the bisector of sites site[0] and
  /// site[1] between vertex[0] and vertex[1] (kInfinity for an unbounded end).
  /// Walking from vertex[1] to vertex[0], site[0] is on the right.
  /// `primary` is false for the edge between a segment and one of its own
  /// endpoints (the perpendicular through the endpoint).
  struct Edge {
    std::array<std::uint32_t, 2> site{kInfinity, kInfinity};
    std::array<std::uint32_t, 2> vertex{kInfinity, kInfinity};
    bool parabolic = false;
    bool primary = true;
    /// For a segment site: +1 when the edge lies right of the segment walked
    /// from its first to its second endpoint, -1 left (0 for a point site).
    std::array<std::int8_t, 2> side{0, 0};
  };
  /// The curve of an edge: a line origin + t * direction, or the parabola with
  /// the given focus and the directrix origin + t * direction (direction of
  /// unit length); [t0, t1] is the edge's part (either may be infinite).
  struct EdgeCurve {
    bool parabolic = false;
    Vec2d origin, direction, focus;
    double t0 = 0, t1 = 0;
    Vec2d point(double t) const;
  };

  /// Builds the diagram of `points` (n x 2, row-major) and `segments`
  /// (m x 4 as x0 y0 x1 y1, row-major). Throws geods::Error on bad input.
  SegmentVoronoi(std::span<const double> points, std::span<const double> segments);

  // Sites: the points first (input points and segment endpoints, each once),
  // then the segments; site ids index the concatenation.
  std::size_t num_points() const { return points_.size(); }
  std::size_t num_segments() const { return segments_.size(); }
  std::size_t num_sites() const { return points_.size() + segments_.size(); }
  bool is_segment(std::uint32_t site) const { return site >= points_.size(); }
  /// A point's position (the snapped coordinate in input units).
  Vec2d point(std::uint32_t p) const { return points_[p]; }
  /// A segment's endpoints as point ids.
  std::array<std::uint32_t, 2> segment(std::uint32_t s) const { return segments_[s]; }
  /// The input segment (row) a segment came from, and the input point a point site came from
  /// (kInfinity for a segment endpoint or a split point).
  std::uint32_t segment_source(std::uint32_t s) const { return segment_source_[s]; }
  std::uint32_t point_source(std::uint32_t p) const { return point_source_[p]; }
  std::size_t split_count() const { return splits_; }

  const std::vector<Vertex>& vertices() const { return vertices_; }
  const std::vector<Edge>& edges() const { return edges_; }
  /// The edge ids bounding each site's cell: cells()[site] (with both ends).
  std::vector<std::vector<std::uint32_t>> cells() const;

  /// Distance from x to a site (closed segment for a segment site).
  double site_distance(std::uint32_t site, const Vec2d& x) const;
  /// The exact curve of an edge; unbounded ends have t = +-infinity.
  EdgeCurve edge_curve(std::uint32_t e) const;
  /// Points along edge e, at most `step` apart (parabolas in their
  /// parameter), clipped to `box` for unbounded ends.
  std::vector<Vec2d> sample_edge(std::uint32_t e, double step, const AABB2d& box) const;
  /// Smallest distance to the sites along edge e (at an end or at the
  /// bisector's closest point to the sites when that lies inside the edge).
  double edge_clearance(std::uint32_t e) const;
  /// The same for the part of edge e between curve parameters a <= b.
  double edge_clearance(std::uint32_t e, double a, double b) const;
  /// Arc length of edge e between curve parameters a <= b (exact for lines and parabolas).
  double edge_length(std::uint32_t e, double a, double b) const;
  /// Points of edge e from parameter a to parameter b (either order), at most about `step` apart.
  std::vector<Vec2d> sample_edge(std::uint32_t e, double a, double b, double step) const;

  /// The medial axis: the primary edges inside the region bounded by the
  /// segments (even-odd rule; the segments should form closed polygons).
  std::vector<std::uint32_t> medial_axis() const;
  /// Even-odd inside test against the segments (builds an index: for many
  /// points, medial_axis() shares one).
  bool inside(const Vec2d& x) const;
  /// The segments as endpoint pairs.
  std::vector<std::array<Vec2d, 2>> segment_geometry() const;

  /// A box around the sites and the vertices.
  AABB2d bounds() const;
  SegmentVoronoiStats stats() const;
  /// Checks the structure (sites of each edge, vertex ends, equidistance of vertices to their sites).
  void validate() const;

 private:
  void build(std::span<const double> points, std::span<const double> segments);

  double scale_ = 1;  // snapped = (x - centre) * scale_
  Vec2d centre_{0, 0};
  std::vector<Vec2d> points_;
  std::vector<std::array<std::uint32_t, 2>> segments_;
  std::vector<std::uint32_t> segment_source_, point_source_;
  std::size_t input_points_ = 0, input_segments_ = 0, splits_ = 0;
  std::vector<Vertex> vertices_;
  std::vector<Edge> edges_;
};

}  // namespace geods::voronoi
