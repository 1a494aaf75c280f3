#pragma once
// A bounding volume hierarchy over the triangles of a TriMesh (float):
// closest and any hit for rays (watertight, core/ray_triangle.hpp), closest
// point, point containment, box and frustum culling. Any builder and any
// bounding volume of build_options.hpp; the default (binned SAH, AABB, 4 wide)
// is the fast path, whose ray queries test the 4 child boxes of a node at once.
//
// save() writes the whole hierarchy, triangle copies included, to one archive
// (core/archive.hpp, kind "bvh.TriangleBvh"); load() maps it and queries read
// the file's pages in place, without the mesh it was built over. A built
// hierarchy keeps its wide nodes and triangle groups in transparent huge pages
// (huge_page_allocator.hpp); a loaded one reads them from the page cache in
// ordinary pages (the kernel gives huge pages to anonymous memory, not to
// mappings of ordinary files), which costs incoherent rays some TLB misses.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "geods/bvh/aabb_bv.hpp"
#include "geods/bvh/build_options.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/bvh/kdop.hpp"
#include "geods/bvh/obb.hpp"
#include "geods/bvh/ray_packet.hpp"
#include "geods/bvh/ray_triangle4.hpp"
#include "geods/bvh/rss.hpp"
#include "geods/bvh/sphere.hpp"
#include "geods/bvh/topology.hpp"
#include "geods/bvh/wide_node.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/plane.hpp"
#include "geods/core/ray_triangle.hpp"
#include "geods/core/tri_mesh.hpp"

namespace geods::bvh {

struct BvhStats {
  std::size_t triangles = 0;
  std::size_t nodes = 0;    // inner nodes and leaves of the hierarchy
  std::size_t leaves = 0;
  int depth = 0;            // edges on the longest root-to-leaf path
  std::size_t bytes = 0;    // nodes, bounding volumes, wide nodes, triangles, ids
  /// Expected cost of a ray (equation 7 unrolled, unit costs): (sum over inner
  /// nodes of area + sum over leaves of area x triangles) / root area.
  double sah_cost = 0;
  /// Definition 4: mean over inner nodes of Vol(node) / sum of Vol(children).
  double tightness_volume = 0;
  /// Definition 3: mean of h(B, G) / diam(G) over the nodes of the top three
  /// levels, h estimated on a 5x5x5 grid of sample points inside each volume
  /// and diam(G) from the extents of G along the 13 directions of the 26-DOP.
  double tightness_hausdorff = 0;
};

/// Closest point of the mesh to a query point.
struct ClosestPoint {
  Vec3f point = Vec3f::Zero();
  std::uint32_t prim = RayHit::no_hit;  // triangle index; no_hit for an empty mesh
  float distance = std::numeric_limits<float>::infinity();
};

using VolumeArray = std::variant<FlatArray<AABB3f>, FlatArray<Sphere3f>, FlatArray<Kdop<float, 6>>,
                                 FlatArray<Kdop<float, 14>>, FlatArray<Kdop<float, 18>>,
                                 FlatArray<Kdop<float, 26>>, FlatArray<Obb3f>, FlatArray<Rss3f>>;

/// A triangle of the mesh, copied into the hierarchy (TriangleBvh::Triangle).
struct BvhTriangle {
  Vec3f a, b, c;
};

}  // namespace geods::bvh
template <>
struct geods::is_bytewise<geods::bvh::BvhTriangle> : std::true_type {};
namespace geods::bvh {

class TriangleBvh {
 public:
  /// The triangles of `mesh`, copied in leaf order.
  using Triangle = BvhTriangle;

  /// An empty hierarchy (every ray misses).
  TriangleBvh() = default;

  /// Builds over the mesh's triangles (deterministic for any thread count).
  /// Throws geods::Error for invalid meshes (see TriMesh::require_valid) and bad
  /// options. Triangles of zero area are kept: rays never hit them
  /// (has_zero_area, core/triangle.hpp), the other queries see them.
  static TriangleBvh build(const TriMesh& mesh, const BuildOptions& options = {});

  /// Archive kind and layout version of save() (2: zero-area triangles'
  /// group lanes hold NaN corners, bvh/ray_triangle4.hpp).
  static constexpr const char* kArchiveKind = "bvh.TriangleBvh";
  static constexpr std::uint32_t kArchiveVersion = 2;
  /// Writes the hierarchy (options, nodes, volumes, triangles, wide nodes) to
  /// `path`; throws geods::Error naming the file if it cannot be written.
  void save(const std::filesystem::path& path) const;
  /// Maps a file written by save(): the arrays are read in place. Checks the
  /// archive (kind, version, sizes, checksums) and then validate(), so a
  /// truncated, corrupt or foreign file gives geods::Error naming the file.
  /// O(size of the file) once; the mesh it was built over is not needed.
  static TriangleBvh load(const std::filesystem::path& path);
  /// The same sections added to / read from an archive of another kind that
  /// embeds a hierarchy (ray::BvhAccelerator).
  void add_sections(ArchiveWriter& out) const;
  static TriangleBvh from_sections(const Archive& in);

  /// Closest hit with t in [ray.tmin, ray.tmax]; prim = RayHit::no_hit on a miss.
  RayHit intersect(const Ray3f& ray) const;
  /// Whether any triangle is hit with t in [ray.tmin, ray.tmax].
  bool occluded(const Ray3f& ray) const;
  /// Packets of up to 8 or 16 rays traversed together (ray_packet.hpp;
  /// src/bvh/ray_packet.cpp): hits[i] (bit i of occluded's mask) is exactly
  /// what intersect(rays[i]) (occluded(rays[i])) answers, for every active i.
  /// With AABBs and arity 4 or 8 (the wide layout), else one ray at a time.
  HitPacket intersect(const RayPacket& packet) const;
  std::uint32_t occluded(const RayPacket& packet) const;
  HitPacket16 intersect(const RayPacket16& packet) const;
  std::uint32_t occluded(const RayPacket16& packet) const;
  /// Every ray, in packets of packet_size (8 or 16) consecutive rays (give
  /// coherent rays in neighbouring order: pixels of 4 x 2 or 4 x 4 tiles),
  /// the packets in parallel;
  /// hits.size() and occluded.size() must be rays.size(), packet_size 8 or
  /// 16 (geods::Error otherwise).
  void intersect_packets(std::span<const Ray3f> rays, std::span<RayHit> hits, int packet_size = kPacketSize) const;
  void occluded_packets(std::span<const Ray3f> rays, std::span<std::uint8_t> occluded,
                        int packet_size = kPacketSize) const;
  /// Closest point of the mesh to p, if closer than max_distance.
  ClosestPoint closest_point(const Vec3f& p, float max_distance = std::numeric_limits<float>::infinity()) const;
  /// Whether p is inside the mesh, which should be closed. Parity of the
  /// crossings of rays in fixed generic directions; a ray that passes through
  /// an edge or a vertex (a barycentric coordinate exactly 0) or starts on a
  /// triangle is not trusted; the answer is the majority of the first three
  /// trusted rays. Points on the surface (within 1e-6 of the mesh's size)
  /// count as inside.
  bool contains(const Vec3f& p) const;
  /// Triangles that intersect the closed box (exact triangle-box test), sorted.
  std::vector<std::uint32_t> cull_box(const AABB3f& box) const;
  /// Triangles not entirely on the negative side of one of the planes (normals
  /// point into the frustum; the usual conservative frustum culling), sorted.
  std::vector<std::uint32_t> cull_frustum(std::span<const Plane3f> planes) const;

  BvhStats stats() const;
  /// Checks the topology, that every volume holds its triangles, the wide
  /// nodes and the triangle copies; throws geods::Error naming the first problem.
  void validate() const;

  const BuildOptions& options() const { return options_; }
  const Topology& topology() const { return topology_; }
  /// One bounding volume per topology node, of the type options().bv selects.
  const VolumeArray& volumes() const { return volumes_; }
  /// Triangles in leaf order and their indices in the mesh.
  const FlatArray<Triangle>& triangles() const { return triangles_; }
  const FlatArray<std::uint32_t>& triangle_ids() const { return topology_.prim_order; }
  std::size_t num_triangles() const { return triangles_.size(); }
  /// The wide layout read by the packet traversal (ray_packet.cpp): the
  /// 4- or 8-wide nodes (empty unless AABB and that arity), the triangle
  /// groups of their leaves, and the depth that sizes traversal stacks.
  const FlatArray<WideNode<4>>& wide4_nodes() const { return wide4_; }
  const FlatArray<WideNode<8>>& wide8_nodes() const { return wide8_; }
  const FlatArray<TriangleGroup>& triangle_groups() const { return groups_; }
  int depth() const { return depth_; }

 private:
  template <typename BV>
  RayHit intersect_generic(const FlatArray<BV>& volumes, const Ray3f& ray, bool any) const;
  template <int W>
  using WideNodes = FlatArray<WideNode<W>>;  // built in huge pages (HugePageAllocator)
  // Avx: compiled into an AVX (or later) function, 8-wide masks in one movemask.
  // Any: stop at the first hit (occluded); a separate function, so that the
  // closest-hit loop carries none of the any-hit loop's state.
  template <int W, bool Any, bool Avx = false>
  RayHit intersect_wide(const WideNodes<W>& nodes, const Ray3f& ray) const;
  // The same compiled for AVX, AVX2 and AVX-512, and the choice between them
  // by simd_level() (simd_level.hpp).
  template <int W, bool Any>
  RayHit intersect_wide_avx(const WideNodes<W>& nodes, const Ray3f& ray) const;
  template <int W, bool Any>
  RayHit intersect_wide_avx2(const WideNodes<W>& nodes, const Ray3f& ray) const;
  template <int W, bool Any>
  RayHit intersect_wide_avx512(const WideNodes<W>& nodes, const Ray3f& ray) const;
  template <int W, bool Any>
  RayHit intersect_wide_best(const WideNodes<W>& nodes, const Ray3f& ray) const;
  // The portable kernel out of line: the SIMD kernels hand it the rare rays
  // they do not take (inlined, it shared their registers and stack).
  template <int W, bool Any>
  [[gnu::noinline]] RayHit intersect_wide_portable(const WideNodes<W>& nodes, const Ray3f& ray) const;
  template <typename BV>
  ClosestPoint closest_generic(const FlatArray<BV>& volumes, std::uint32_t start, const Vec3f& p,
                               float max_distance) const;
  template <typename Fn>
  void for_each_crossing(const Ray3f& ray, Fn&& fn) const;
  // Throws geods::Error for a mesh or ray origin outside the range of the float
  // ray-triangle test (core/ray_triangle.hpp); every ray query starts here.
  void check_ray(const Ray3f& ray) const { check_ray_range(ray_range_problem_, ray.origin, "TriangleBvh"); }
  template <typename Packet>
  void check_rays(const Packet& packet) const {
    for (std::uint32_t b = packet.active; b != 0; b &= b - 1) check_ray(packet.rays[__builtin_ctz(b)]);
  }
  void set_ray_range();
  // triangle(leaf-order index) for every triangle in a leaf whose volumes
  // (the root's too) all pass accept(volume), in no particular order.
  template <typename Accept, typename OnTriangle>
  void visit_unordered(Accept&& accept, OnTriangle&& triangle) const;
  template <typename BV>
  void fit_volumes();
  void fit_hull_obbs();
  void build_wide();

  BuildOptions options_;
  Topology topology_;
  int depth_ = 0;  // of topology_, sizes the traversal stacks
  VolumeArray volumes_;
  FlatArray<Triangle> triangles_;
  std::string ray_range_problem_;  // ray_range_problem of the triangles: ray queries refuse them when set
  WideNodes<4> wide4_;
  WideNodes<8> wide8_;
  // The triangles of the wide leaves in groups of 4, in leaf order (huge pages when built).
  FlatArray<TriangleGroup> groups_;
};

}  // namespace geods::bvh

