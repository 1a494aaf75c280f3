#pragma once
// The history DAG of an incremental Delaunay triangulation (seed §5.2;
// Guibas-Knuth-Sharir, the Delaunay tree of Boissonnat-Teillaud without its
// conflict lists): a node per triangle ever created, its children the
// triangles that replaced it by a split or a flip. Locating a point is a
// descent from the roots to the leaf (a current triangle) that contains it:
// O(log i) expected for a random order of insertion, whatever the order's
// locality.
//
// Outside the hull the regions of the ghost triangles are the cones from a
// fixed interior point (the centroid of the first triangle) through the hull
// edges; the DAG therefore assumes the hull never shrinks and serves
// construction only. If rounding puts the centroid outside the first triangle
// (wildly mixed magnitudes), usable() is false and construction walks instead.
#include <cstdint>
#include <vector>

#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay_core.hpp"

namespace geods::voronoi {

class HistoryDag {
 public:
  /// Starts at the core's first triangle and its three ghost triangles
  /// (triangles 0-3, as make_first_triangle() leaves them); room for about
  /// 9 nodes per point of `points`.
  HistoryDag(const DelaunayCore& core, std::size_t points);
  bool usable() const { return usable_; }
  std::size_t nodes() const { return nodes_.size(); }

  /// The current triangle that contains q (the core's last triangle if none does,
  /// which exact predicates rule out).
  std::uint32_t start(const Vec2d& q) const;

  // Hooks: each replaced triangle gets the new ones as children.
  void split_triangle(std::uint32_t t, std::uint32_t t1, std::uint32_t t2);
  void split_edge(std::uint32_t e, std::uint32_t twin, std::uint32_t t1, std::uint32_t t2);
  void flip(std::uint32_t e, std::uint32_t f);
  bool fixed(std::uint32_t /*e*/) const { return false; }

 private:
  struct Node {
    std::uint32_t vertex[3];
    std::uint32_t child[3];
    std::uint32_t triangle;  // the triangle slot while the node is a leaf
  };
  std::uint32_t add_node(std::uint32_t t);
  bool contains(std::uint32_t node, const Vec2d& q) const;

  const DelaunayCore* core_;
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> triangle_node_;  // per triangle slot: its leaf node
  Vec2d center_;                              // a point strictly inside the first triangle
  bool usable_;
};

}  // namespace geods::voronoi
