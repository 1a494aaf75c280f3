#pragma once
// Octree for ray shooting with the top-down parametric traversal of Revelles,
// Ureña and Lastra (seed §2.5.1). Leaves list the triangles that overlap
// their cell; a node is split at its middle into eight children until it holds
// at most leaf_size triangles or reaches max_depth, or when splitting does
// not pay: its children would hold four times its triangles in total or more
// (a child is hit by about a quarter of the rays that hit its parent).
//
// Traversal works only with ray parameters: the entry and exit parameters
// t0, t1 of a node's three slabs give the children's by the midpoints
// tm = (t0 + t1) / 2 (equation 2); the entry plane (Table 1) and the
// comparisons of Table 2 give the first child hit, and the exit plane of each
// child gives the next one by the automaton of Table 3. Children are numbered
// with bit 4 for the upper x half, 2 for y and 1 for z; a negative direction
// component is handled by mirroring the ray in that axis and XOR-ing the child
// index with the axis bit. A zero component is replaced by a tiny positive one
// for the traversal only (the triangle tests use the true ray).
//
// Layout: a flat node array; an inner node's eight children are consecutive;
// a leaf refers to a range of one triangle-index array.
#include <cstdint>
#include <vector>

#include "geods/ray/accelerator.hpp"

namespace geods::ray {

class RayOctree final : public Accelerator {
 public:
  struct Node {
    static constexpr std::uint32_t kInner = 0xFFFFFFFFu;
    std::uint32_t first = 0;  // inner: index of child 0; leaf: offset into triangles()
    std::uint32_t count = 0;  // kInner for an inner node, else the number of triangles
    bool leaf() const { return count != kInner; }
  };

  static std::unique_ptr<RayOctree> build(const TriMesh& mesh, const AcceleratorOptions& options = {});

  /// Deepest octree_max_depth (cells 2^-30 of the root's size are float noise).
  static constexpr std::uint32_t kMaxDepth = 30;

  static constexpr const char* kArchiveKind = "ray.RayOctree";
  static constexpr std::uint32_t kArchiveVersion = 1;
  /// The corners, the nodes and the leaf lists (the root box follows from the corners).
  void save(const std::filesystem::path& path) const override;
  /// Maps a file written by save() and validate()s it; geods::Error naming the file if it is bad.
  static std::unique_ptr<RayOctree> load(const std::filesystem::path& path);

  AcceleratorKind kind() const override { return AcceleratorKind::octree; }
  AcceleratorStats stats() const override;
  void validate() const override;

  const AABB3f& root_bounds() const { return root_bounds_; }
  const FlatArray<Node>& nodes() const { return nodes_; }
  const FlatArray<std::uint32_t>& triangles() const { return leaf_triangles_; }

 protected:
  RayHit closest_hit(const Ray3f& ray, RayCache& cache) const override;
  std::uint32_t any_hit(const Ray3f& ray, RayCache& cache) const override;

 private:
  explicit RayOctree(const TriMesh& mesh) : Accelerator(mesh) {}
  explicit RayOctree(const Archive& in) : Accelerator(in) {}
  void set_root_bounds();
  template <bool AnyHit>
  struct Traversal;

  AABB3f root_bounds_;
  FlatArray<Node> nodes_;
  FlatArray<std::uint32_t> leaf_triangles_;
  std::size_t depth_ = 0;  // of the deepest node; the traversal recurses this deep
};

}  // namespace geods::ray
