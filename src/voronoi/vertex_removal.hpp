#pragma once
// Removal of a vertex from a Delaunay triangulation (Devillers): the vertex's
// edges are flipped away one Delaunay ear at a time until its degree is 3, then
// the vertex is cut out, its three triangles merged into one. O(d^2) for degree d.
#include <cstdint>

#include "geods/voronoi/delaunay_core.hpp"

namespace geods::voronoi {

/// Removes internal vertex v (core.vertex_edge[v] must be a half-edge leaving
/// it). False if no ear could be flipped (the caller then rebuilds); the
/// triangulation is still valid, with v in it.
bool remove_vertex(DelaunayCore& core, std::uint32_t v);

}  // namespace geods::voronoi
