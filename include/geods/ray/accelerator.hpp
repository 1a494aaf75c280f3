#pragma once
// One interface for the ray shooting accelerators of seed §2.5 (and the BVH of
// §4.1), so that they can be built over the same mesh and shot with the same
// rays: closest hit, any hit (shadow rays), statistics and build time.
//
// Every accelerator answers exactly like testing the ray against all triangles
// with the watertight RayTriangleTest: the same closest t, and on ties the
// smallest triangle index. Queries are const and thread-safe; a RayCache is the
// caller's per-thread (per ray-tree level, per light source) memory that
// speeds coherent queries up without changing any answer.
//
// save() writes an accelerator with its triangle copies to one archive
// (core/archive.hpp, kind "ray.<Class>"); load_accelerator() or the class's
// load() maps it back without the mesh, its arrays read in place.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/ray.hpp"
#include "geods/core/ray_triangle.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/bvh/build_options.hpp"
#include "geods/bvh/ray_packet.hpp"

namespace geods::ray {

enum class AcceleratorKind { bvh, grid, octree, rays5d };

/// "bvh", "grid", "octree", "rays5d".
std::string_view to_string(AcceleratorKind kind);
/// The inverse of to_string; throws geods::Error naming the valid kinds.
AcceleratorKind parse_accelerator_kind(std::string_view name);
/// Every kind, in declaration order.
std::span<const AcceleratorKind> all_accelerator_kinds();

struct AcceleratorOptions {
  // BVH (geods::bvh::TriangleBvh): its builder, bounding volume, leaf size,
  // arity. 8 wide by default (bvh's default is 4): one ray tests 8 boxes at
  // once with AVX, and incoherent rays fetch fewer nodes (docs/ray.md).
  bvh::BuildOptions bvh = [] {
    bvh::BuildOptions o;
    o.arity = 8;
    return o;
  }();
  // Uniform grid: about grid_density * n cells for n triangles (each axis gets
  // cells proportional to its extent), at most grid_max_resolution per axis.
  float grid_density = 4.0f;
  std::uint32_t grid_max_resolution = 512;
  // Octree: a node becomes a leaf with at most octree_leaf_size triangles or at
  // octree_max_depth.
  std::uint32_t octree_leaf_size = 8;
  std::uint32_t octree_max_depth = 12;
  // 5D ray classification: a node is subdivided (lazily, when a ray reaches it)
  // while it has more than rays5d_leaf_size candidates, is shallower than
  // rays5d_max_depth and the candidate lists of all nodes hold fewer than
  // rays5d_max_references entries. Objects farther than rays5d_cutoff times the
  // scene's extent along the dominant axis beyond a cell are not stored with it
  // (the cut-off distance memory optimization; <= 0 or inf keeps them all).
  std::uint32_t rays5d_leaf_size = 8;
  std::uint32_t rays5d_max_depth = 8;
  std::size_t rays5d_max_references = std::size_t(1) << 26;
  float rays5d_cutoff = 0.25f;
};

/// Size of a built accelerator. Fields that do not apply are 0.
struct AcceleratorStats {
  std::string kind;
  std::size_t triangles = 0;
  std::size_t nodes = 0;       // grid: cells; trees: nodes built so far
  std::size_t leaves = 0;      // grid: non-empty cells
  std::size_t references = 0;  // triangle references stored in cells / leaves / candidate lists
  std::size_t depth = 0;       // trees: deepest node (root = 0)
  std::size_t bytes = 0;       // memory of the structure (triangle copies included)
  double build_s = 0;          // wall time of the build
  std::uint32_t resolution[3] = {0, 0, 0};  // grid cells per axis
};

/// Per-thread memory of recent queries (seed §2.5.2): keep one per ray-tree
/// level (primary rays, shadow rays of each light source...). It never changes
/// an answer; counts of how often it helped are kept for statistics.
struct RayCache {
  std::uint64_t owner = 0;            // Accelerator::id() of the accelerator the entries belong to
  const void* cell = nullptr;         // rays5d: the leaf the previous ray ended in
  std::uint32_t occluder = RayHit::no_hit;  // the triangle that blocked the previous shadow ray
  std::uint64_t cell_hits = 0;        // queries that started in the cached leaf
  std::uint64_t occluder_hits = 0;    // shadow rays answered by the cached occluder
};

class Accelerator {
 public:
  virtual ~Accelerator() = default;
  Accelerator(const Accelerator&) = delete;
  Accelerator& operator=(const Accelerator&) = delete;

  virtual AcceleratorKind kind() const = 0;

  /// The closest hit in [ray.tmin, ray.tmax] (t = inf, prim = no_hit on a miss).
  RayHit intersect(const Ray3f& ray) const;
  RayHit intersect(const Ray3f& ray, RayCache& cache) const;
  /// Whether any triangle is hit in [ray.tmin, ray.tmax]. With a cache, the
  /// triangle that blocked the previous ray is tried first (the occluder cache).
  bool occluded(const Ray3f& ray) const;
  bool occluded(const Ray3f& ray, RayCache& cache) const;
  /// Up to 8 or 16 rays at once (bvh::RayPacket, bvh::RayPacket16; bit i of
  /// `active`: rays[i] is shot): hits[i] is what intersect(rays[i], cache)
  /// answers (no hit for the inactive rays), bit i of the mask what
  /// occluded(rays[i], cache) answers. The BVH traverses the packet's rays
  /// together (bvh/ray_packet.hpp); the other kinds shoot them one by one in
  /// lane order.
  bvh::HitPacket intersect(const bvh::RayPacket& packet, RayCache& cache) const;
  std::uint32_t occluded(const bvh::RayPacket& packet, RayCache& cache) const;
  bvh::HitPacket16 intersect(const bvh::RayPacket16& packet, RayCache& cache) const;
  std::uint32_t occluded(const bvh::RayPacket16& packet, RayCache& cache) const;

  /// Writes the accelerator to `path` (an archive of kind "ray.<Class>");
  /// throws geods::Error naming the file if it cannot be written.
  virtual void save(const std::filesystem::path& path) const = 0;

  virtual AcceleratorStats stats() const = 0;
  /// Checks the structure's invariants (every triangle reachable where a ray
  /// could hit it, ranges in bounds...); throws geods::Error on a violation.
  virtual void validate() const = 0;
  double build_s() const { return build_s_; }
  /// A number no other accelerator of this process has (caches are tied to it,
  /// not to an address that a later accelerator may reuse).
  std::uint64_t id() const { return id_; }
  std::size_t num_triangles() const { return corners_.size() / 3; }
  /// True for an accelerator from load(): its arrays view the mapped file.
  bool mapped() const { return corners_.mapped(); }

 protected:
  /// Copies the triangle corners (three per triangle, flat) after checking the mesh.
  explicit Accelerator(const TriMesh& mesh);
  /// Views the corners of an archive written with add_sections() (in place)
  /// after checking that they are finite; bounds and margin as the build computes them.
  explicit Accelerator(const Archive& in);
  /// The corners and build time, the sections every accelerator's archive starts with.
  void add_sections(ArchiveWriter& out) const;

  virtual RayHit closest_hit(const Ray3f& ray, RayCache& cache) const = 0;
  /// The index of some triangle hit in [ray.tmin, ray.tmax], or RayHit::no_hit.
  virtual std::uint32_t any_hit(const Ray3f& ray, RayCache& cache) const = 0;
  /// The packet queries on shootable rays (default: ray by ray with the cache).
  virtual bvh::HitPacket closest_hits(const bvh::RayPacket& packet, RayCache& cache) const;
  virtual std::uint32_t any_hits(const bvh::RayPacket& packet, RayCache& cache) const;
  virtual bvh::HitPacket16 closest_hits(const bvh::RayPacket16& packet, RayCache& cache) const;
  virtual std::uint32_t any_hits(const bvh::RayPacket16& packet, RayCache& cache) const;

  /// Tests triangle `prim` and keeps it in `best` if it is closer (ties: smaller index).
  bool test_closest(const RayTriangleTest<float>& test, std::uint32_t prim, float tmin, RayHit& best) const {
    const Vec3f* c = &corners_[std::size_t(prim) * 3];
    float t, u, v;
    if (!test.intersect(c[0], c[1], c[2], tmin, best.t, t, u, v)) return false;
    if (!(t < best.t || prim < best.prim)) return false;
    best = {t, prim, u, v};
    return true;
  }
  bool test_any(const RayTriangleTest<float>& test, std::uint32_t prim, float tmin, float tmax) const {
    const Vec3f* c = &corners_[std::size_t(prim) * 3];
    float t, u, v;
    return test.intersect(c[0], c[1], c[2], tmin, tmax, t, u, v);
  }
  /// Rays with a non-finite or zero direction, a non-finite origin or an empty
  /// interval hit nothing (as in the triangle test itself).
  static bool shootable(const Ray3f& ray);
  /// Throws geods::Error for a mesh or ray origin outside the range of the
  /// float ray-triangle test (core/ray_triangle.hpp).
  void check_range(const Ray3f& ray) const { check_ray_range(ray_range_problem_, ray.origin, "ray accelerator"); }

  FlatArray<Vec3f> corners_;    // triangle i: corners_[3i..3i+2]
  AABB3f bounds_;               // of all triangles
  std::string ray_range_problem_;  // ray_range_problem(bounds_): ray queries refuse the mesh when set
  // Cells and beams are widened by this much when triangles are assigned to
  // them, so that float rounding in the traversal never loses a triangle.
  float margin_ = 0;
  double build_s_ = 0;

 private:
  void set_bounds();
  // The packet queries of either size (accelerator.cpp).
  template <int N>
  bvh::HitPacketN<N> intersect_packet(const bvh::RayPacketN<N>& packet, RayCache& cache) const;
  template <int N>
  std::uint32_t occluded_packet(const bvh::RayPacketN<N>& packet, RayCache& cache) const;
  template <int N>
  bvh::HitPacketN<N> closest_hits_one_by_one(const bvh::RayPacketN<N>& packet, RayCache& cache) const;
  template <int N>
  std::uint32_t any_hits_one_by_one(const bvh::RayPacketN<N>& packet, RayCache& cache) const;

  std::uint64_t id_;
};

/// Builds the accelerator of the given kind over the mesh's triangles (which
/// are copied; the mesh may go away). Throws geods::Error for an invalid mesh
/// (indices out of range, non-finite coordinates).
std::unique_ptr<Accelerator> make_accelerator(const TriMesh& mesh, AcceleratorKind kind,
                                              const AcceleratorOptions& options = {});

/// Loads an accelerator of any kind saved with Accelerator::save() (the kind is
/// read from the file). Throws geods::Error naming the file if it is not one, or
/// is truncated, corrupt or of another version.
std::unique_ptr<Accelerator> load_accelerator(const std::filesystem::path& path);

}  // namespace geods::ray
