#pragma once
// Deferred, self-organizing BSP (seed §3.4.4) for segment-triangle intersection queries.
// The tree starts as one preliminary leaf holding every triangle. A query descends from
// the root (child holding the segment's start first, the other only if the segment
// crosses the plane and nothing was hit) and counts accesses per node; a preliminary leaf
// tests its list in order of past hits (the list is kept sorted by hit counts) and is
// split once its counter reaches `threshold`, by the plane of its most-hit triangle
// (triangles straddling it go to both children: no fragments). The answer is exact: the
// segment-triangle test uses the exact orient3d of core. The oblivious variant builds every
// leaf down to `leaf_size` up front (threshold 0) for comparison.
#include <array>
#include <cstdint>
#include <vector>

#include "geods/bsp/bsp_tree.hpp"

namespace geods::bsp {

struct DeferredStats {
  std::size_t queries = 0;
  std::size_t node_visits = 0;     // nodes traversed by all queries
  std::size_t triangle_tests = 0;  // segment-triangle tests by all queries
  std::size_t splits = 0;          // preliminary leaves split
  std::size_t nodes = 0;
};

class DeferredBsp {
 public:
  /// threshold: accesses of a preliminary leaf before it is split (0: build everything now);
  /// leaf_size: a leaf with at most this many triangles is never split.
  DeferredBsp(const Triangles& mesh, std::size_t threshold = 8, std::size_t leaf_size = 8);
  /// Does the closed segment p-q meet a triangle? (Updates counters; may split leaves.)
  bool intersects(const Vec3d& p, const Vec3d& q);
  const DeferredStats& stats() const { return stats_; }

 private:
  struct DNode {
    std::array<double, 4> plane{};  // of the splitting triangle (exact orient3d decides sides)
    std::uint32_t tri = kNoIndex;   // splitting triangle; kNoIndex: preliminary leaf
    std::uint32_t neg = kNoIndex, pos = kNoIndex;
    std::size_t accesses = 0;
    std::vector<std::uint32_t> list;  // preliminary leaf: triangles, most hit first
  };
  bool query(std::uint32_t node, const Vec3d& p, const Vec3d& q);
  void split(std::uint32_t node);
  int side(std::uint32_t tri, const Vec3d& x) const;

  Triangles mesh_;
  std::vector<DNode> nodes_;
  std::vector<std::uint32_t> hits_;  // per triangle
  std::size_t threshold_, leaf_size_;
  DeferredStats stats_;
};

}  // namespace geods::bsp
