#pragma once
// Incremental collision detection (seed §4.2) and a broad phase over many
// moving meshes.
//
// IncrementalCollide keeps, for one pair of meshes, the bottom slice of the
// recursion tree of the simultaneous traversal: the node pairs where the last
// query stopped (pairs whose volumes were apart, and leaf pairs). The next
// frame starts from it: a slice pair still apart stays; one that now overlaps
// goes down (its subtree is traversed and its own bottom slice replaces it);
// siblings that are all apart, under a parent that is apart too, go up to the
// parent (repeatedly, as far as that holds). Every slice is a cut of the recursion tree
// and the triangle tests are exact, so every frame's contacts equal a query
// from scratch (tested); with small motions between frames only a few pairs
// change.
//
// BroadPhase: sweep and prune over the world boxes of N meshes (the root
// volume carried by each pose), the order kept between frames (insertion sort
// of a nearly sorted list), then the exact first-contact query on each pair
// of overlapping boxes: the pairs of meshes that collide, per frame.
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geods/collide/collide.hpp"

namespace geods::collide {

class IncrementalCollide {
 public:
  /// Both meshes must outlive this object.
  IncrementalCollide(const CollisionMesh& a, const CollisionMesh& b, DescendRule descend = DescendRule::larger);

  /// All contacts in the given poses (CollideMode::all), from the last slice.
  CollideResult update(const Posed& pose_a, const Posed& pose_b);
  /// Pairs in the bottom slice now.
  std::size_t slice_size() const { return slice_.size(); }
  /// Forgets the slice: the next update starts at the roots.
  void reset();

 private:
  struct Entry {
    std::uint32_t a, b;
    std::uint64_t parent;  // the recursion-tree parent pair (a << 32 | b), ~0 for the roots
    bool apart;            // the volumes were apart in the last update
  };
  const CollisionMesh* a_;
  const CollisionMesh* b_;
  DescendRule descend_;
  std::vector<Entry> slice_;
  // Recursion-tree parent of every pair above the slice (opened pairs; key: a << 32 | b).
  std::unordered_map<std::uint64_t, std::uint64_t> parent_;
};

class BroadPhase {
 public:
  /// The meshes must outlive this object.
  explicit BroadPhase(std::vector<const CollisionMesh*> meshes);
  /// The pairs (i < j) of meshes that intersect in the given poses (one per
  /// mesh), sorted. Throws geods::Error for a wrong number of poses.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> update(const std::vector<Posed>& poses);
  /// Pairs whose world boxes overlapped in the last update (narrow-phase queries).
  std::size_t candidates() const { return candidates_; }

 private:
  std::vector<const CollisionMesh*> meshes_;
  std::vector<std::uint32_t> order_;  // by the low x of the world box, kept between frames
  std::size_t candidates_ = 0;
};

}  // namespace geods::collide
