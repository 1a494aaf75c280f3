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
// parent (one level per frame, tried when one of them was tested again).
// What makes it pay on smooth motion: a pair found apart keeps the lower
// bound of its volumes' distance, and the motion of B relative to A is summed
// over the frames (the change of the relative rotation times the node's reach
// from B's origin, plus the change of the translation, bounds how far any
// point of the node moved); while that sum stays below the pair's gap the
// pair is not tested at all. Every slice is a cut of the recursion tree, the
// skipped pairs cannot touch, and the triangle tests are exact, so every
// frame's contacts equal a query from scratch (tested).
//
// BroadPhase: sweep and prune over the world boxes of N meshes (the root
// volume carried by each pose), the order kept between frames (insertion sort
// of a nearly sorted list), then the exact first-contact query on each pair
// of overlapping boxes: the pairs of meshes that collide, per frame.
#include <cstdint>
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
  /// Slice pairs the last update did not test (moved less than their gap).
  std::size_t skipped() const { return skipped_; }
  /// Forgets the slice: the next update starts at the roots.
  void reset();

 private:
  struct Entry {
    std::uint32_t a, b;
    std::uint32_t parent;  // the recursion-tree parent pair (its index in opened_), kNoIndex for the roots
    std::uint32_t frame;   // the update that tested it
    float gap;             // > 0: apart, a lower bound of the volumes' distance when tested; else 0
  };
  const CollisionMesh* a_;
  const CollisionMesh* b_;
  DescendRule descend_;
  std::vector<Entry> slice_;
  std::vector<double> reach_b_;  // per node of B: farthest point of its box from B's origin
  // Summed motion of B in A's frame: |R_k+1 - R_k|_F and |t_k+1 - t_k| over the frames.
  double rot_ = 0, trans_ = 0;
  std::vector<double> rot_at_{0.0}, trans_at_{0.0};  // rot_, trans_ after each update (16 bytes a frame)
  Eigen::Matrix3d last_r_ = Eigen::Matrix3d::Identity();
  Vec3d last_t_ = Vec3d::Zero();
  bool has_last_ = false;
  std::uint32_t frame_ = 0;
  std::size_t skipped_ = 0;
  // The pairs above the slice (opened), each with its own parent; freed slots are reused.
  struct Opened {
    std::uint32_t a, b, parent;
  };
  std::vector<Opened> opened_;
  std::vector<std::uint32_t> free_;
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
