#pragma once
// The k-th order Voronoi diagram (seed §5.3.3): the plane split into regions
// whose points have the same set of k nearest sites. Each region is convex and
// is the intersection of the half-planes "nearer to t than to s" for t in its
// set and s outside it.
//
// Construction, for small k: the order-1 regions are the Voronoi cells (the
// box cut by the bisectors of each site's Delaunay2 neighbours); each order-j region R(T) is split
// by the Voronoi diagram of the sites outside T, restricted to R(T). Only the
// Delaunay neighbours of T can be the (j+1)-th nearest site in R(T) (the
// (j+1)-th nearest neighbour of a point is a Delaunay neighbour of one of its
// j nearest), so each piece is R(T) cut by the bisectors of those candidates;
// the pieces with the same set T + s make up the convex region of that set,
// the convex hull of their corners. O(k^2 n) regions and pieces times the
// candidates per region; floating point for the polygons, the triangulation
// exact. A corner two pieces share is computed by each in its own rounding:
// it is joined by its name (its three equidistant sites, or the bisector and
// box side it lies on), not by its coordinates, so that regions of sites
// 1e-12 of the box apart keep corners 1e-14 apart.
//
// Degenerate input: duplicates count once (representative(); region sets
// hold representatives); ties on region boundaries go either way; collinear
// sites give strips. k must be between 1 and the number of distinct sites
// (k equal to it gives one region, the whole box). NaN or infinite
// coordinates, no points, a bad k or an empty box: geods::Error.
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

struct KthOrderVoronoiStats {
  std::size_t sites = 0, distinct = 0, k = 0, regions = 0, pieces = 0, region_vertices = 0;
};

class KthOrderVoronoi {
 public:
  struct Region {
    std::vector<std::uint32_t> sites;  // the k nearest sites, ascending representatives
    std::vector<Vec2d> polygon;        // counter-clockwise, clipped to the box
  };

  KthOrderVoronoi(std::span<const Vec2d> points, std::size_t k, const AABB2d& box);

  std::span<const Vec2d> points() const { return points_; }
  std::size_t k() const { return k_; }
  const AABB2d& box() const { return box_; }
  std::uint32_t representative(std::uint32_t i) const { return representative_[i]; }
  /// The regions with a non-empty part in the box, sorted by their site sets.
  const std::vector<Region>& regions() const { return regions_; }

  KthOrderVoronoiStats stats() const;
  /// Checks that regions are counter-clockwise polygons in the box with k
  /// distinct sites each, the sets unique. Throws geods::Error.
  void validate() const;

 private:
  std::vector<Vec2d> points_;
  std::vector<std::uint32_t> representative_;
  std::size_t k_ = 0, distinct_ = 0, pieces_ = 0;
  AABB2d box_;
  std::vector<Region> regions_;
};

}  // namespace geods::voronoi
