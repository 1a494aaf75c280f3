#pragma once
// Point location while a Delaunay triangulation is built: a strategy gives the
// triangle from which DelaunayCore's visibility walk finishes locating the next
// point, and follows the triangulation's changes as the core's Hooks.
//
// The strategies, all ending with an exact step that settles what rounding
// leaves open:
//   WalkFromLast    the triangle of the last change (with BRIO's spatial order a
//                   few steps; Delaunay2Location::walk);
//   HistoryDag      descent in the DAG of every triangle ever created (O(log i)
//                   expected in any order; Delaunay2Location::history_dag,
//                   history_dag.hpp);
//   SlabLocator     for a finished diagram, slabs between the Voronoi vertices
//                   (post_office.hpp), finished by descend_to_nearest.
#include <concepts>
#include <cstdint>

#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay_core.hpp"

namespace geods::voronoi {

/// A point-location strategy for insertion: start(q) is a triangle of the core
/// near q; the hooks keep the strategy in step with the triangulation.
template <class L>
concept InsertionLocation = requires(L& location, const Vec2d& q, std::uint32_t i) {
  { location.start(q) } -> std::same_as<std::uint32_t>;
  location.split_triangle(i, i, i);
  location.split_edge(i, i, i, i);
  location.flip(i, i);
  { location.fixed(i) } -> std::same_as<bool>;
};

/// Walk from the triangle of the last change: no state beside the triangulation.
struct WalkFromLast : NoHooks {
  const DelaunayCore* core;
  std::uint32_t start(const Vec2d& /*q*/) const { return core->last_triangle; }
};

}  // namespace geods::voronoi
