#pragma once
// Proximity applications of the Voronoi diagram (seed §5.4.3), each in time
// linear in the size of the diagram (plus sorting for the spanning tree):
// closest pair, all nearest neighbours, Euclidean minimum spanning tree, and
// the k nearest sites of a query point.
//
// They rest on two facts about the Delaunay graph (the cell adjacency of the
// Voronoi diagram): it contains the nearest-neighbour graph and the Euclidean
// minimum spanning tree, and the (i+1)-th nearest site of any query point is a
// Delaunay neighbour of one of its i nearest. Duplicate points are at distance
// 0 from their first occurrence.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay3.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {

struct ClosestPair {
  std::uint32_t i = 0, j = 0;  // i < j, point indices
  double distance = 0;
};

/// The two nearest points (ties: the smallest (i, j)). Throws geods::Error for fewer than 2 points.
ClosestPair closest_pair(const Voronoi2& diagram);
ClosestPair closest_pair(std::span<const Vec2d> points);

/// For every point, the index of its nearest other point (ties: the smallest
/// index; a duplicate's nearest is another copy). Throws for fewer than 2 points.
std::vector<std::uint32_t> all_nearest_neighbors(const Voronoi2& diagram);
std::vector<std::uint32_t> all_nearest_neighbors(std::span<const Vec2d> points);

struct SpanningTree {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;  // n - 1 pairs (i < j), by increasing length
  double length = 0;                                           // sum of the edge lengths
};

/// The Euclidean minimum spanning tree: Kruskal's algorithm on the Delaunay
/// edges (O(n log n)), duplicates joined to their first occurrence by
/// zero-length edges. Ties are broken by (length, i, j), so it is deterministic.
SpanningTree emst(const Voronoi2& diagram);
SpanningTree emst(std::span<const Vec2d> points);

/// The same in 3D (seed §5.4.3 carries over): from the Delaunay
/// tetrahedralization's edges. A removed point takes no part (its nearest is
/// no_index). Without tetrahedra (fewer than four non-coplanar points) every
/// pair of sites is a candidate: O(n^2).
ClosestPair closest_pair(const Delaunay3& dt);
ClosestPair closest_pair(std::span<const Vec3d> points);
std::vector<std::uint32_t> all_nearest_neighbors(const Delaunay3& dt);
std::vector<std::uint32_t> all_nearest_neighbors(std::span<const Vec3d> points);
SpanningTree emst(const Delaunay3& dt);
SpanningTree emst(std::span<const Vec3d> points);

/// The k nearest distinct sites of q (representative indices), nearest first,
/// ties by index; fewer if there are fewer sites. Best-first search in the
/// Delaunay graph from a nearest site: O(k log k) after the location.
std::vector<std::uint32_t> k_nearest_sites(const WalkLocator& locator, const Vec2d& q, std::size_t k);

}  // namespace geods::voronoi
