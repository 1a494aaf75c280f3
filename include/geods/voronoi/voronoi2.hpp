#pragma once
// The Voronoi diagram of points in the plane (seed §5.1) as the dual of their
// Delaunay triangulation, in a half-edge representation.
//
// Vertices are the circumcentres of the Delaunay triangles. Triangles whose
// circumcircles coincide (co-circular sites, decided with the exact incircle
// predicate) share one Voronoi vertex, so a vertex may have degree > 3 and no
// edge has zero length. Every Voronoi edge is a pair of twin half-edges, one
// per side; a half-edge has its cell (`site`) on its left, so the half-edges of
// a cell, followed by `next`, run counter-clockwise around it. Unbounded edges
// have origin and/or target kInfinity: a ray from the circumcentre of a hull
// triangle, or, when all sites are collinear, a whole line (parallel bisectors;
// then every cell is unbounded). The `next` of an edge that runs off to
// infinity is the cell's edge that comes back from infinity, so every cell is
// one cycle. Each half-edge lies on the line line_point(e) + t * direction(e).
//
// Duplicate points share the cell of their first occurrence (representative()).
//
// Cells are convex polygons; cell_polygon(i, box) clips one to a box.
// Size: at most 2n - 5 vertices and 3n - 6 edges for n distinct sites.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <utility>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

class Delaunay2;

/// The bounding box of `points` grown by `margin` times its larger side on
/// every side (a frame like the curve Gamma of the seed's Figure 42); a unit
/// square around a single point. Throws geods::Error for no points.
AABB2d frame_around(std::span<const Vec2d> points, double margin = 0.25);

struct Voronoi2Stats {
  std::size_t sites = 0;     // input points
  std::size_t distinct = 0;  // sites without duplicates
  std::size_t vertices = 0;
  std::size_t edges = 0;     // undirected (half-edge pairs)
  std::size_t unbounded_cells = 0;
  std::size_t bytes = 0;
};

class Voronoi2 {
 public:
  static constexpr std::uint32_t kInfinity = 0xffffffffu;  // origin/target of an unbounded end
  static constexpr std::uint32_t kNoEdge = 0xffffffffu;

  struct Edge {
    std::uint32_t site;    // the cell on the left (a representative site)
    std::uint32_t twin;    // the same edge seen from the neighbouring cell
    std::uint32_t next;    // the next half-edge counter-clockwise around `site`
    std::uint32_t origin;  // vertex index or kInfinity
    std::uint32_t target;  // vertex index or kInfinity
  };

  /// The Voronoi diagram of `points` (triangulates them with Delaunay2).
  /// Throws geods::Error for no points or non-finite coordinates.
  explicit Voronoi2(std::span<const Vec2d> points);
  /// The dual of a Delaunay2 (copied: the diagram does not refer to it).
  /// Throws geods::Error if points were removed from it.
  explicit Voronoi2(const Delaunay2& triangulation);
  /// The dual of any Delaunay triangulation of `points` in the flat half-edge
  /// form: counter-clockwise `triangles` (3 indices each), `halfedges[e]` the
  /// opposite half-edge or kNoEdge on the hull, and `representative[i]` the
  /// first occurrence of point i (i itself if it is not a duplicate). No
  /// triangles means the distinct points are collinear (or fewer than 3).
  Voronoi2(std::span<const Vec2d> points, std::span<const std::uint32_t> triangles,
           std::span<const std::uint32_t> halfedges, std::span<const std::uint32_t> representative);

  std::span<const Vec2d> points() const { return points_; }
  std::size_t size() const { return points_.size(); }
  const FlatArray<Vec2d>& vertices() const { return vertices_; }
  const FlatArray<Edge>& edges() const { return edges_; }
  std::uint32_t representative(std::uint32_t i) const { return representative_[i]; }

  /// One half-edge of the cell of point i (of its representative), or kNoEdge
  /// if there is only one distinct site (its cell is the whole plane).
  std::uint32_t cell_edge(std::uint32_t i) const { return cell_edge_[representative_[i]]; }
  /// Whether the cell of point i is bounded (its site is not on the convex hull).
  bool bounded(std::uint32_t i) const;
  /// The Delaunay neighbours of a representative site (sites whose cells share
  /// an edge or, for co-circular sites, only a vertex), each once.
  std::span<const std::uint32_t> neighbors(std::uint32_t site) const {
    return {neighbors_.data() + neighbor_offsets_[site], neighbors_.data() + neighbor_offsets_[site + 1]};
  }

  /// Unit vector along half-edge e, from its origin towards its target.
  Vec2d direction(std::uint32_t e) const;
  /// A point of the line of half-edge e: the midpoint of its two sites.
  Vec2d line_point(std::uint32_t e) const;
  /// The site on the other side of half-edge e.
  std::uint32_t opposite_site(std::uint32_t e) const { return edges_[edges_[e].twin].site; }

  /// The cell of point i clipped to `box`, counter-clockwise (empty if the
  /// cell misses the box).
  std::vector<Vec2d> cell_polygon(std::uint32_t i, const AABB2d& box) const;
  /// cell_polygon of every point, in parallel.
  std::vector<std::vector<Vec2d>> cell_polygons(const AABB2d& box) const;
  /// frame_around(points(), margin).
  AABB2d default_box(double margin = 0.25) const { return frame_around(points_, margin); }
  /// The part of half-edge e inside `box` (from its origin side to its target side), if any.
  std::optional<std::pair<Vec2d, Vec2d>> clipped_edge(std::uint32_t e, const AABB2d& box) const;

  /// Writes the diagram to `path` as a geods archive (core/archive.hpp, kind
  /// "voronoi.Voronoi2"). Throws geods::Error naming the file if it cannot be written.
  void save(const std::filesystem::path& path) const;
  /// The diagram save()d to `path`, its arrays read in place from the mapped
  /// file (no copy: a diagram larger than memory can be queried). Throws
  /// geods::Error naming the file if it is missing, truncated, corrupt, of
  /// another kind or version, or its arrays are not a diagram: indices in
  /// range, twins mutual, `next` a permutation within each cell, so that every
  /// walk around a cell comes back (O(n) integer work; Verify::full and
  /// structure_only, which skips the checksums, run all of
  /// validate(): one cycle per cell, and the geometry).
  static Voronoi2 load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);

  Voronoi2Stats stats() const;
  /// Checks twins, next cycles, that each cell's cycle holds only its site,
  /// that every finite vertex is equidistant from the sites of its edges, and
  /// that the cell of every site contains the site. Throws geods::Error.
  void validate() const;

 private:
  void check_cells() const;  // validate()'s checks of the links, O(n) with no walks: what load() checks
  Voronoi2() = default;  // for load()
  void build_dual(std::span<const std::uint32_t> triangles, std::span<const std::uint32_t> halfedges,
                  std::vector<Vec2d>& vertices, std::vector<Edge>& edges, std::vector<std::uint32_t>& cell_edge) const;
  void build_collinear(std::vector<Edge>& edges, std::vector<std::uint32_t>& cell_edge) const;
  void build_neighbors(std::span<const std::uint32_t> triangles);

  // Owned when built, views of the file's pages when loaded.
  FlatArray<Vec2d> points_;
  FlatArray<std::uint32_t> representative_;
  FlatArray<Vec2d> vertices_;
  FlatArray<Edge> edges_;
  FlatArray<std::uint32_t> cell_edge_;  // per point; only representatives are set
  FlatArray<std::uint32_t> neighbor_offsets_, neighbors_;
};

}  // namespace geods::voronoi
