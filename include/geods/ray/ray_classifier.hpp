#pragma once
// 5D ray classification of Arvo and Kirk (seed §2.5.2). A ray is a point of
// five dimensions: its origin (x, y, z) in the scene box B and its direction
// as a point (u, v) in [-1, 1]^2 on one of the six faces of the direction cube
// (the face of the dominant axis and its sign; u, v are the two other
// components divided by the dominant one's magnitude). There is one 5D octree
// per face; a node's cell (a box of origins times a square of directions) is
// the beam of all rays it classifies, and it lists the candidate triangles
// whose bounding boxes meet that beam, sorted by their minimum along the
// face's dominant axis.
//
// Subdivision is lazy, as rays arrive: a ray descends from the root of its
// face to the leaf containing its 5D point; a node with more than leaf_size
// candidates, above max_depth, is split into 2^5 = 32 children (all five
// coordinates halved), and a child's list is filtered from its parent's, so
// candidate lists shrink while subdividing. Building is paid for by the
// queries (rent or buy): a child is built only once the rays that stopped at
// its parent have tested as many candidates as the parent's children built so
// far cost (one pass over the parent's list each), so incoherent rays do not
// build a deep tree that only one ray uses, and coherent rays get one quickly. Children are built one at a time
// under a lock and published atomically, so concurrent queries are safe; the
// tree's shape may depend on the order rays arrive, the answers never do.
// Once the lists of all nodes hold max_references entries, nodes stop splitting.
//
// Queries: the candidates of the leaf are tested in order and the loop stops
// at the first candidate that starts beyond the closest hit so far (sorted
// along the dominant axis). The cut-off distance bounds memory: a cell stores
// only triangles starting within cutoff * (extent of B along the axis) beyond
// its far side; when no hit is found before that distance, the query starts
// again from the point of the ray at the cut-off. A RayCache keeps the leaf
// of the previous ray (the per-level cache for coherent rays: the next ray
// starts there if its 5D point is inside) and the last occluder of shadow rays.
//
// save() stores the triangles and the rays5d options, not the 5D trees: they
// are built by the queries (their shape depends on which rays came in which
// order), linked by pointers and published atomically, so a saved tree would
// be a snapshot of one workload in a second, pointer-free layout. load() sorts
// the six root lists again (the build, O(n log n)) and the trees regrow as
// rays arrive; the answers are the same.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "geods/ray/accelerator.hpp"

namespace geods::ray {

class RayClassifier final : public Accelerator {
 public:
  ~RayClassifier() override;

  static std::unique_ptr<RayClassifier> build(const TriMesh& mesh, const AcceleratorOptions& options = {});

  static constexpr const char* kArchiveKind = "ray.RayClassifier";
  static constexpr std::uint32_t kArchiveVersion = 1;
  /// The corners and the rays5d options (see above: the trees are rebuilt on demand).
  void save(const std::filesystem::path& path) const override;
  /// Reads a file written by save() and builds the roots again (build_s() is that time).
  static std::unique_ptr<RayClassifier> load(const std::filesystem::path& path);

  AcceleratorKind kind() const override { return AcceleratorKind::rays5d; }
  AcceleratorStats stats() const override;
  /// Checks every node built so far: its list is sorted and exactly the
  /// parent's candidates that meet its beam within the cut-off. O(nodes * n).
  void validate() const override;

  const AABB3f& scene_bounds() const { return scene_; }
  /// Candidate references the lists hold now (grows as rays are shot).
  std::size_t references() const { return references_.load(std::memory_order_relaxed); }

 protected:
  RayHit closest_hit(const Ray3f& ray, RayCache& cache) const override;
  std::uint32_t any_hit(const Ray3f& ray, RayCache& cache) const override;

 private:
  struct Node;
  struct Ray5;
  explicit RayClassifier(const TriMesh& mesh);
  explicit RayClassifier(const Archive& in);
  // Checks the options, then sorts the six roots (the whole eager build).
  void build_roots(const AcceleratorOptions& options);
  template <bool AnyHit>
  std::uint32_t shoot(const Ray3f& ray, RayCache& cache, RayHit& best) const;
  const Node& locate(const Ray5& r, RayCache& cache) const;
  bool beam_meets(const Node& node, std::uint32_t prim) const;
  void build_child(const Node& parent, Node& child) const;

  AcceleratorOptions options_;
  AABB3f scene_;                          // B: the triangles' bounds, widened
  std::vector<AABB3f> boxes_;             // triangle bounds, widened by the margin
  std::array<std::unique_ptr<Node>, 6> roots_;
  float cutoff_[3] = {0, 0, 0};           // cut-off distance along each axis
  mutable std::atomic<std::size_t> references_{0};
  mutable std::atomic<std::size_t> nodes_{6};
  mutable std::atomic<std::size_t> depth_{0};
  mutable std::array<std::mutex, 64> locks_;
};

}  // namespace geods::ray
