#pragma once
// The post office problem (seed §5.4.1): the nearest site of a query point,
// by point location in the Voronoi diagram, two ways.
//
// SlabLocator is the slab structure of Theorem 8: vertical lines through every
// Voronoi vertex cut the plane into slabs; inside a slab no two Voronoi edges
// cross, so they are stored sorted bottom to top, each with the cell below it.
// A query finds its slab and then its cell by two binary searches: O(log n).
// The slabs are stored plainly (not persistently), so the space is the total
// number of edge-slab crossings: O(n^2) in the worst case, about n^1.5 for
// uniformly spread sites (stats() reports it); meant for up to ~10^5 sites.
//
// WalkLocator walks in the Delaunay graph (the cell adjacency of the Voronoi
// diagram): from a start site it moves to a neighbour nearer to the query until
// none is; in a Delaunay triangulation that ends at a nearest site. The start is
// a hint (the previous answer for coherent queries) or the nearest of a sample
// of about 2 n^(1/3) sites (jump and walk: expected O(n^(1/3)) steps for uniform sites).
//
// Both end with the same exact step (distances compared with exact arithmetic),
// so the answer is always a nearest site: the representative of a point at the
// smallest distance; among sites at exactly equal distance, any one of them.
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "geods/core/default_init_allocator.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {

/// From `start` (a representative site), moves to a Delaunay neighbour that is
/// strictly nearer to q (exact comparison) while there is one; returns the site
/// reached, a nearest site of q.
std::uint32_t descend_to_nearest(const Voronoi2& diagram, const Vec2d& q, std::uint32_t start);

struct SlabLocatorStats {
  std::size_t slabs = 0;
  std::size_t crossings = 0;      // stored (edge, slab) entries
  std::size_t max_crossings = 0;  // in one slab
  std::size_t bytes = 0;
};

class SlabLocator {
 public:
  /// Keeps a reference to `diagram`, which must outlive the locator.
  explicit SlabLocator(const Voronoi2& diagram);

  /// The representative index of a nearest site of q. Throws geods::Error for non-finite q.
  std::uint32_t nearest(const Vec2d& q) const;
  /// nearest() of every query, in parallel.
  std::vector<std::uint32_t> nearest_batch(std::span<const Vec2d> queries) const;
  /// The site whose cell contains q by the slab search alone, without the exact
  /// final step (wrong only within rounding of the Voronoi edges).
  std::uint32_t locate(const Vec2d& q) const;

  SlabLocatorStats stats() const;
  /// Checks that every slab holds the Voronoi edges that cross it, sorted bottom
  /// to top, each with the sites on its two sides. Throws geods::Error.
  void validate() const;

 private:
  struct Line {  // of a stored half-edge: y = y0 + slope * (x - x0)
    double x0, y0, slope;
  };
  double edge_y(std::uint32_t e, double x) const {
    const Line& l = lines_[e];
    return l.y0 + (x - l.x0) * l.slope;
  }
  double slab_middle(std::size_t s) const;  // an x inside slab s
  // The entries are all written by the parallel fill and sorts: resize() leaves them
  // uninitialized (no sequential zero-fill of n^1.5 entries; their pages are first touched in parallel).
  using Entries = std::vector<std::uint32_t, DefaultInitAllocator<std::allocator<std::uint32_t>>>;

  const Voronoi2* diagram_;
  std::vector<Line> lines_;                  // per half-edge of the diagram (only stored ones are set)
  std::vector<double> xs_;                   // slab boundaries, increasing; slab s spans (xs_[s-1], xs_[s])
  std::vector<std::uint32_t> offsets_;       // slab s holds entries [offsets_[s], offsets_[s+1])
  Entries edge_;                             // per entry: a half-edge of the edge, with its site above it
  Entries below_;                            // per entry: the site below the edge
  std::vector<std::uint32_t> top_;           // per slab: the site above its highest edge
};

class WalkLocator {
 public:
  /// Keeps a reference to `diagram`, which must outlive the locator.
  explicit WalkLocator(const Voronoi2& diagram);

  /// The representative index of a nearest site of q (jump and walk).
  std::uint32_t nearest(const Vec2d& q) const;
  /// The same, walking from `hint` (any point index; its representative is used).
  std::uint32_t nearest(const Vec2d& q, std::uint32_t hint) const;
  /// nearest() of every query: the queries are visited in Z-order, each walk
  /// starting at the previous answer, in parallel chunks.
  std::vector<std::uint32_t> nearest_batch(std::span<const Vec2d> queries) const;

  const Voronoi2& diagram() const { return *diagram_; }

 private:
  const Voronoi2* diagram_;
  std::vector<std::uint32_t> samples_;
};

}  // namespace geods::voronoi
