// TriangleBvh: build (topology, volumes, wide nodes) and the queries.
#include "geods/bvh/triangle_bvh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

#if defined(__SSE__)
#include <immintrin.h>
#endif

#include "geods/bvh/ray_triangle4.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/bvh/traversal.hpp"
#include "geods/core/convex_hull3.hpp"
#include "geods/core/default_init_allocator.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/triangle.hpp"
#include "geods/core/triangle_box.hpp"

namespace geods::bvh {
namespace {

template <typename BV>
BV fit_points(std::span<const Vec3f> points) {
  if constexpr (std::is_same_v<BV, AABB3f>) {
    return fit_aabb<float>(points);
  } else if constexpr (std::is_same_v<BV, Sphere3f>) {
    return fit_sphere<float>(points);
  } else if constexpr (std::is_same_v<BV, Obb3f>) {
    return fit_obb<float>(points);
  } else if constexpr (std::is_same_v<BV, Rss3f>) {
    return fit_rss<float>(points);
  } else {
    return fit_kdop<float, BV::num_axes * 2>(points);
  }
}

// A volume in double, for its measures: in float, areas and volumes of
// meshes far from unit scale overflow (a sphere's volume from a radius of
// 4e12) and made the statistics inf or NaN.
AABB<double, 3> in_double(const AABB3f& a) { return {a.lo.cast<double>(), a.hi.cast<double>()}; }
Sphere<double> in_double(const Sphere3f& a) { return {a.center.cast<double>(), double(a.radius)}; }
Obb<double> in_double(const Obb3f& a) { return {a.center.cast<double>(), a.axes.cast<double>(), a.half.cast<double>()}; }
Rss<double> in_double(const Rss3f& a) {
  return {a.center.cast<double>(), a.axes.cast<double>(), a.half.cast<double>(), double(a.radius)};
}

template <typename BV>
std::pair<double, double> measures(const BV& bv) {
  if constexpr (std::is_same_v<BV, AABB3f> || std::is_same_v<BV, Sphere3f> || std::is_same_v<BV, Obb3f> ||
                std::is_same_v<BV, Rss3f>) {
    return {volume(in_double(bv)), surface_area(in_double(bv))};
  } else {
    return kdop_measures(bv);
  }
}

// A box entered at t_near may still hold a hit at t_far (its exit, or the
// ray's tmax): the test must never reject a box the exact triangle test
// would hit, so the far end is widened by a few ulps (Ize 2013).
inline bool may_hit_before(float t_near, float t_far) { return t_near <= widen_far(t_far); }
// A bounding-volume interval that a hit may lie in.
inline bool interval_hit(std::pair<float, float> iv) { return may_hit_before(iv.first, iv.second); }

// Directions whose components are far from any simple ratio, so that rays
// from a point rarely pass exactly through edges or vertices.
const std::array<Vec3f, 7> kContainDirections = {
    Vec3f(0.5377f, 1.8339f, -2.2588f).normalized(), Vec3f(0.8622f, 0.3188f, -1.3077f).normalized(),
    Vec3f(-0.4336f, 0.3426f, 3.5784f).normalized(), Vec3f(2.7694f, -1.3499f, 3.0349f).normalized(),
    Vec3f(0.7254f, -0.0631f, 0.7147f).normalized(), Vec3f(-0.2050f, -0.1241f, 1.4897f).normalized(),
    Vec3f(1.4090f, 1.4172f, 0.6715f).normalized()};

// The triangle copies and groups are filled in parallel right after they are
// sized: not value-initialized first (on one thread), their huge pages faulted
// in by all threads.
template <typename T>
using FilledLater = std::vector<T, DefaultInitAllocator<HugePageAllocator<T>>>;

}  // namespace

// ------------------------------------------------------------------ build

TriangleBvh TriangleBvh::build(const TriMesh& mesh, const BuildOptions& options) {
  check_options(options);
  mesh.require_valid("bvh");
  Progress progress(options.progress, "bvh build", 3);
  TriangleBvh bvh;
  bvh.options_ = options;
  bvh.options_.progress = nullptr;
  const std::size_t n = mesh.num_triangles();
  std::vector<AABB3f, HugePageAllocator<AABB3f>> boxes(n);  // huge pages: fewer page faults
  parallel_for_each_index(0, n, [&](std::size_t i) {
    const auto& t = mesh.triangles[i];
    boxes[i] = triangle_bounds(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
  });
  bvh.topology_ = build_topology(boxes, options);
  bvh.depth_ = bvh.topology_.depth();
  progress.update(1);
  FilledLater<Triangle> triangles(n);
  parallel_for_each_index(0, n, [&](std::size_t i) {
    const auto& t = mesh.triangles[bvh.topology_.prim_order[i]];
    triangles[i] = {mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
  });
  bvh.triangles_ = std::move(triangles);
  bvh.set_ray_range();
  switch (options.bv) {
    case BoundingVolume::aabb: bvh.fit_volumes<AABB3f>(); break;
    case BoundingVolume::sphere: bvh.fit_volumes<Sphere3f>(); break;
    case BoundingVolume::kdop6: bvh.fit_volumes<Kdop<float, 6>>(); break;
    case BoundingVolume::kdop14: bvh.fit_volumes<Kdop<float, 14>>(); break;
    case BoundingVolume::kdop18: bvh.fit_volumes<Kdop<float, 18>>(); break;
    case BoundingVolume::kdop26: bvh.fit_volumes<Kdop<float, 26>>(); break;
    case BoundingVolume::obb: bvh.fit_volumes<Obb3f>(); break;
    case BoundingVolume::obb_hull: bvh.fit_hull_obbs(); break;
    case BoundingVolume::rss: bvh.fit_volumes<Rss3f>(); break;
  }
  progress.update(2);
  if (options.bv == BoundingVolume::aabb && options.arity >= 4 && n > 0) bvh.build_wide();
  progress.finish();
  return bvh;
}

template <typename BV>
void TriangleBvh::fit_volumes() {
  const auto& nodes = topology_.nodes;
  std::vector<BV> vols(nodes.size());
  auto points_of = [&](const TopoNode& node, std::vector<Vec3f>& pts) {
    pts.clear();
    for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i) {
      pts.push_back(triangles_[i].a);
      pts.push_back(triangles_[i].b);
      pts.push_back(triangles_[i].c);
    }
  };
  constexpr bool mergeable =
      std::is_same_v<BV, AABB3f> || !(std::is_same_v<BV, Sphere3f> || std::is_same_v<BV, Obb3f> || std::is_same_v<BV, Rss3f>);
  if constexpr (mergeable) {
    // Boxes and k-DOPs merge exactly: fit the leaves, merge upwards (children follow parents).
    parallel_for(0, nodes.size(), 1024, [&](std::size_t b, std::size_t e) {
      std::vector<Vec3f> pts;
      for (std::size_t i = b; i < e; ++i)
        if (nodes[i].leaf()) {
          points_of(nodes[i], pts);
          vols[i] = fit_points<BV>(pts);
        }
    });
    for (std::size_t i = nodes.size(); i-- > 0;) {
      if (nodes[i].leaf()) continue;
      BV v = vols[nodes[i].first_child];
      for (std::uint32_t c = 1; c < nodes[i].num_children; ++c) v = merge(v, vols[nodes[i].first_child + c]);
      vols[i] = v;
    }
  } else {
    // Spheres, OBBs and RSS are fitted to all vertices below the node: much tighter than merging.
    parallel_for(0, nodes.size(), 16, [&](std::size_t b, std::size_t e) {
      std::vector<Vec3f> pts;
      for (std::size_t i = b; i < e; ++i) {
        points_of(nodes[i], pts);
        vols[i] = fit_points<BV>(pts);
      }
    });
  }
  volumes_ = FlatArray<BV>(std::move(vols));
}

// A node's convex hull is the hull of its children's hull corners, so the
// hull-based OBBs are fitted bottom-up, level by level in parallel, each node
// to a few corners instead of every vertex below it.
void TriangleBvh::fit_hull_obbs() {
  const auto& nodes = topology_.nodes;
  std::vector<Obb3f> vols(nodes.size());
  std::vector<std::vector<Vec3f>> corners(nodes.size());
  std::vector<std::vector<std::uint32_t>> levels(1, {0});
  while (true) {
    std::vector<std::uint32_t> next;
    for (std::uint32_t i : levels.back())
      for (std::uint32_t c = 0; c < nodes[i].num_children; ++c) next.push_back(nodes[i].first_child + c);
    if (next.empty()) break;
    levels.push_back(std::move(next));
  }
  for (std::size_t l = levels.size(); l-- > 0;) {
    const auto& level = levels[l];
    parallel_for(0, level.size(), 16, [&](std::size_t b, std::size_t e) {
      std::vector<Vec3d> pts;
      for (std::size_t k = b; k < e; ++k) {
        const std::uint32_t i = level[k];
        const TopoNode& node = nodes[i];
        pts.clear();
        for (std::uint32_t t = node.prim_first; t < node.prim_first + node.prim_count && node.leaf(); ++t)
          for (const Vec3f* v : {&triangles_[t].a, &triangles_[t].b, &triangles_[t].c}) pts.push_back(v->cast<double>());
        for (std::uint32_t c = node.first_child; c < node.first_child + node.num_children; ++c) {
          for (const Vec3f& v : corners[c]) pts.push_back(v.cast<double>());
          std::vector<Vec3f>().swap(corners[c]);
        }
        const ConvexHull3 hull = convex_hull3(pts);
        for (std::uint32_t v : hull.vertices) corners[i].push_back(pts[v].cast<float>());
        vols[i] = fit_obb<float>(corners[i], ObbFit::hull);
      }
    });
  }
  volumes_ = FlatArray<Obb3f>(std::move(vols));
}

void TriangleBvh::build_wide() {
  const auto& nodes = topology_.nodes;
  const auto& boxes = std::get<FlatArray<AABB3f>>(volumes_);
  // Inner nodes: their wide node; leaves: their first triangle group.
  std::vector<std::uint32_t> wide_index(nodes.size(), 0);
  std::uint32_t inner = 0, groups = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].leaf()) {
      wide_index[i] = groups;
      groups += (nodes[i].prim_count + 3) / 4;
    } else {
      wide_index[i] = inner++;
    }
  }
  FilledLater<TriangleGroup> group_array(groups);
  parallel_for(0, nodes.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!nodes[i].leaf()) continue;
      for (std::uint32_t k = 0; k < nodes[i].prim_count; k += 4) {
        TriangleGroup& g = group_array[wide_index[i] + k / 4];
        for (std::uint32_t lane = 0; lane < 4; ++lane) {
          const std::uint32_t t = nodes[i].prim_first + std::min(k + lane, nodes[i].prim_count - 1);
          const Triangle& tri = triangles_[t];
          set_lane(g, int(lane), tri.a, tri.b, tri.c, topology_.prim_order[t]);
        }
      }
    }
  });
  groups_ = std::move(group_array);
  auto fill = [&]<int W>(WideNodes<W>& wide) {
    using Node = WideNode<W>;
    std::vector<Node, HugePageAllocator<Node>> out;
    auto set_child = [&](Node& w, int slot, std::uint32_t c) {
      for (int a = 0; a < 3; ++a) {
        w.bounds[2 * a][slot] = boxes[c].lo[a];
        w.bounds[2 * a + 1][slot] = boxes[c].hi[a];
      }
      w.child[slot] = wide_index[c];
      w.count[slot] = nodes[c].leaf() ? (nodes[c].prim_count + 3) / 4 : 0;
    };
    auto empty_node = [] {
      Node w;
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < W; ++i) {
          w.bounds[2 * a][i] = std::numeric_limits<float>::infinity();
          w.bounds[2 * a + 1][i] = -std::numeric_limits<float>::infinity();
        }
      for (int i = 0; i < W; ++i) w.child[i] = Node::kEmpty, w.count[i] = 0;
      return w;
    };
    out.assign(std::max<std::uint32_t>(inner, 1), empty_node());
    if (nodes[0].leaf()) {  // a single leaf: one wide node holding it
      set_child(out[0], 0, 0);
    } else {
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (nodes[i].leaf()) continue;
        for (std::uint32_t c = 0; c < nodes[i].num_children; ++c)
          set_child(out[wide_index[i]], int(c), nodes[i].first_child + c);
      }
    }
    wide = std::move(out);
  };
  if (options_.arity == 8) {
    fill(wide8_);
  } else {
    fill(wide4_);
  }
}

// ------------------------------------------------------------------ save, load

namespace {

// The volume type of each BoundingVolume, for code that picks it at run time.
template <typename Fn>
void with_volume_type(BoundingVolume bv, Fn&& fn) {
  switch (bv) {
    case BoundingVolume::aabb: return fn(AABB3f{});
    case BoundingVolume::sphere: return fn(Sphere3f{});
    case BoundingVolume::kdop6: return fn(Kdop<float, 6>{});
    case BoundingVolume::kdop14: return fn(Kdop<float, 14>{});
    case BoundingVolume::kdop18: return fn(Kdop<float, 18>{});
    case BoundingVolume::kdop26: return fn(Kdop<float, 26>{});
    case BoundingVolume::obb:
    case BoundingVolume::obb_hull: return fn(Obb3f{});
    case BoundingVolume::rss: return fn(Rss3f{});
  }
}

}  // namespace

void TriangleBvh::add_sections(ArchiveWriter& out) const {
  out.add_value("builder", std::uint32_t(options_.builder));
  out.add_value("bv", std::uint32_t(options_.bv));
  out.add_value("leaf_size", std::int32_t(options_.leaf_size));
  out.add_value("arity", std::int32_t(options_.arity));
  out.add_value("sah_bins", std::int32_t(options_.sah_bins));
  out.add("nodes", topology_.nodes);
  out.add("triangle_ids", topology_.prim_order);
  std::visit([&](const auto& volumes) { out.add("volumes", volumes); }, volumes_);
  out.add("triangles", triangles_);
  if (!wide4_.empty()) out.add("wide4", wide4_);
  if (!wide8_.empty()) out.add("wide8", wide8_);
  out.add("groups", groups_);
}

void TriangleBvh::save(const std::filesystem::path& path) const {
  ArchiveWriter out(kArchiveKind, kArchiveVersion);
  add_sections(out);
  out.write(path);
}

TriangleBvh TriangleBvh::from_sections(const Archive& in) {
  TriangleBvh bvh;
  const auto builder = in.value<std::uint32_t>("builder");
  const auto bv = in.value<std::uint32_t>("bv");
  if (builder > std::uint32_t(Builder::boxtree)) throw in.error("unknown bvh builder " + std::to_string(builder));
  if (bv > std::uint32_t(BoundingVolume::rss)) throw in.error("unknown bounding volume " + std::to_string(bv));
  bvh.options_.builder = Builder(builder);
  bvh.options_.bv = BoundingVolume(bv);
  bvh.options_.leaf_size = in.value<std::int32_t>("leaf_size");
  bvh.options_.arity = in.value<std::int32_t>("arity");
  bvh.options_.sah_bins = in.value<std::int32_t>("sah_bins");
  in.check([&] { check_options(bvh.options_); });
  bvh.topology_.nodes = in.array<TopoNode>("nodes");
  const std::size_t nodes = bvh.topology_.nodes.size();
  bvh.topology_.prim_order = in.array<std::uint32_t>("triangle_ids");
  bvh.triangles_ = in.array<Triangle>("triangles", bvh.topology_.prim_order.size());
  bvh.set_ray_range();
  // The volume type the file says it holds; a section of another type is refused by its element size.
  with_volume_type(bvh.options_.bv, [&]<typename BV>(BV) { bvh.volumes_ = in.array<BV>("volumes", nodes); });
  const bool wide = bvh.options_.bv == BoundingVolume::aabb && bvh.options_.arity >= 4 && nodes > 0;
  if (wide && bvh.options_.arity == 8) bvh.wide8_ = in.array<WideNode<8>>("wide8");
  if (wide && bvh.options_.arity == 4) bvh.wide4_ = in.array<WideNode<4>>("wide4");
  bvh.groups_ = in.array<TriangleGroup>("groups");
  in.check([&] { bvh.validate(); });  // before anything walks the nodes
  bvh.depth_ = bvh.topology_.depth();
  return bvh;
}

TriangleBvh TriangleBvh::load(const std::filesystem::path& path) {
  return from_sections(Archive::open(path, kArchiveKind, kArchiveVersion));
}

// ------------------------------------------------------------------ rays

namespace {

// A child of a wide node waiting to be visited: an inner node (count 0, its
// WideNode) or a leaf (its first TriangleGroup and group count), keyed by the
// distance at which the ray enters its box.
struct WideEntry {
  std::uint32_t child, count;
  float key;
};

template <int W>
struct SimdTypes;
template <>
struct SimdTypes<4> {
  typedef float vf __attribute__((vector_size(16)));
};
template <>
struct SimdTypes<8> {
  typedef float vf __attribute__((vector_size(32)));
};

// Every lane x (a broadcast; filling the lanes one by one in a loop made
// GCC assemble the vectors lane by lane through the stack).
// (Written through a reference: a 32-byte vector passed by value has another
// ABI with AVX than without.)
template <typename V>
GEODS_BVH_INLINE void splat(V& v, float x) {
  typedef float v4 __attribute__((vector_size(16)));
  const v4 s = {x, x, x, x};
  if constexpr (sizeof(V) == 16) {
    v = s;
  } else {
    static_assert(sizeof(V) == 32);
    v = __builtin_shufflevector(s, s, 0, 0, 0, 0, 0, 0, 0, 0);
  }
}

// Bit i set where lane i of a comparison result is true.
template <typename Mask>
inline unsigned lane_bits(Mask m) {
#if defined(__AVX__)
  if constexpr (sizeof(Mask) == 32) return unsigned(_mm256_movemask_ps(reinterpret_cast<__m256>(m)));
#endif
#if defined(__SSE__)
  if constexpr (sizeof(Mask) == 16) return unsigned(_mm_movemask_ps(reinterpret_cast<__m128>(m)));
#endif
#if defined(__SSE__)
  if constexpr (sizeof(Mask) == 32) {  // two SSE halves (one AVX instruction where the compiler may use AVX)
    __m128 half[2];
    std::memcpy(half, &m, sizeof half);
    return unsigned(_mm_movemask_ps(half[0])) | unsigned(_mm_movemask_ps(half[1])) << 4;
  }
#endif
  unsigned bits = 0;
  for (int i = 0; i < int(sizeof(Mask) / 4); ++i) bits |= unsigned(m[i] & 1) << i;
  return bits;
}

#if defined(__x86_64__) && defined(__GNUC__)
// lane_bits of an 8-wide mask in one instruction, for code compiled for AVX
// or later (inlined there; intersect_wide<W, true> is only called from such code).
template <typename Mask>
__attribute__((target("avx"))) inline unsigned lane_bits_avx(const Mask& m) {
  static_assert(sizeof(Mask) == 32);
  __m256 v;
  std::memcpy(&v, &m, sizeof v);
  return unsigned(_mm256_movemask_ps(v));
}
// splat of an 8-wide vector in one vbroadcastss, for the same code (splat's
// generic form takes three instructions: GCC builds the 4-lane vector first).
template <typename V>
__attribute__((target("avx"))) inline void splat_avx(V& v, float x) {
  static_assert(sizeof(V) == 32);
  const __m256 r = _mm256_set1_ps(x);
  std::memcpy(&v, &r, sizeof v);
}
#endif

}  // namespace

// The traversal compiled once more per instruction set (simd_level.hpp), the
// whole call tree inlined into it (flatten), and the choice between them at
// run time. No FMA: these levels do the same IEEE operations as the portable
// code (this file is compiled with -ffp-contract=off, so that AVX-512's FMA
// instructions are not used to contract a * b + c), so the hits are identical.
#if defined(__x86_64__) && defined(__GNUC__)
#define GEODS_BVH_SIMD_DISPATCH 1
template <int W, bool Any>
__attribute__((target("avx"), flatten)) RayHit TriangleBvh::intersect_wide_avx(const WideNodes<W>& nodes,
                                                                               const Ray3f& ray) const {
  return intersect_wide<W, Any, true>(nodes, ray);
}
template <int W, bool Any>
__attribute__((target("avx2,bmi,bmi2,lzcnt,popcnt"), flatten)) RayHit TriangleBvh::intersect_wide_avx2(
    const WideNodes<W>& nodes, const Ray3f& ray) const {
  return intersect_wide<W, Any, true>(nodes, ray);
}
template <int W, bool Any>
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2,lzcnt,popcnt"), flatten)) RayHit
TriangleBvh::intersect_wide_avx512(const WideNodes<W>& nodes, const Ray3f& ray) const {
  return intersect_wide<W, Any, true>(nodes, ray);
}
#endif

template <int W, bool Any>
RayHit TriangleBvh::intersect_wide_best(const WideNodes<W>& nodes, const Ray3f& ray) const {
#if defined(GEODS_BVH_SIMD_DISPATCH)
  switch (simd_level()) {
    case SimdLevel::avx512: return intersect_wide_avx512<W, Any>(nodes, ray);
    case SimdLevel::avx2: return intersect_wide_avx2<W, Any>(nodes, ray);
    case SimdLevel::avx: return intersect_wide_avx<W, Any>(nodes, ray);
    case SimdLevel::portable: break;
  }
#endif
  return intersect_wide<W, Any>(nodes, ray);
}

template <int W, bool Any>
RayHit TriangleBvh::intersect_wide_portable(const WideNodes<W>& nodes, const Ray3f& ray) const {
  return intersect_wide<W, Any>(nodes, ray);
}

template <int W, bool Any, bool Avx>
RayHit TriangleBvh::intersect_wide(const WideNodes<W>& nodes, const Ray3f& ray) const {
  using vf = typename SimdTypes<W>::vf;
  RayHit hit;
  if (nodes.empty()) return hit;
  const RayTriangle4Test test(ray);
  // A zero direction component gives an infinite inverse; the 0 * inf NaN of
  // an origin on a slab plane is then skipped by the NaN-ignoring min/max
  // below, so a ray inside a (possibly flat) slab keeps the whole line. The
  // near bound of each axis is chosen by the sign.
  // The far bounds are scaled by inv_far = inv (1 + kRayBoxSlack): the
  // widening of Ize (2013) that keeps a box hit rounding would lose, folded
  // into the inverse so that it costs no operation per node (one rounding of
  // inv x (1 + slack) in place of one of t x (1 + slack): the same bound; near
  // and far share the rounding of inv itself).
  constexpr float kWiden = 1.0f + kRayBoxSlack;
  auto broadcast = [](vf& v, float x) GEODS_BVH_INLINE_LAMBDA {
#if defined(GEODS_BVH_SIMD_DISPATCH)
    if constexpr (Avx && W == 8) return splat_avx(v, x);
#endif
    splat(v, x);
  };
  // The three inverses in one division, and the finiteness of the origin and
  // of them in one comparison (4 lanes, the last one 1 / 1).
  typedef float v4 __attribute__((vector_size(16)));
  const v4 origin4 = {ray.origin[0], ray.origin[1], ray.origin[2], 0.0f};
  const v4 inv4 = v4{1.0f, 1.0f, 1.0f, 1.0f} / v4{ray.direction[0], ray.direction[1], ray.direction[2], 1.0f};
  const v4 inv_far4 = inv4 * kWiden;
  vf org[3], inv[3], inv_far[3];
  std::size_t near_offset[3];  // byte offset of the near bound's row in WideNode::bounds; the far row's is ^ sizeof(vf)
  for (int a = 0; a < 3; ++a) {
    near_offset[a] = (2 * a + (inv4[a] < 0 ? 1 : 0)) * sizeof(vf);
    broadcast(org[a], origin4[a]);
    broadcast(inv[a], inv4[a]);
    broadcast(inv_far[a], inv_far4[a]);
  }
  // Plain pointers: through the containers GCC reloads them at every node.
  const WideNode<W>* const node_at = nodes.data();
  const TriangleGroup* const group_at = groups_.data();
  float tmax = ray.tmax;
  float tmax_widened = widen_far(tmax);  // kept with tmax: may_hit_before(key, tmax) is key <= tmax_widened
  const float tmin = ray.tmin;
  vf tmin_v, tmax_far;  // tmax_far: tmax (1 + kRayBoxSlack), the widened far bound of every box, kept with tmax
  broadcast(tmin_v, tmin);
  broadcast(tmax_far, tmax * kWiden);
  // The usual case takes the fast box test: no NaN among the slab distances
  // (a finite origin, finite nonzero inverse directions, tmin and tmax not
  // NaN; a zero inverse, of an infinite direction, makes NaN of the empty
  // slots' infinite bounds),
  // so the four-way max and min are two levels of a tree instead of a chain
  // (the same values and mask, a shorter dependency chain from a node's
  // bounds to its mask); and tmin >= 0, so the widening by inv_far may
  // scale: it narrows a negative exit distance, but a box left behind the
  // origin holds no hit then. Lines and rays with tmin < 0 take the chain
  // with the widening t + |t| kRayBoxSlack of may_hit_before.
  // (x - x is 0 for a finite x, NaN for inf and NaN: one sum per axis tests
  // both without a branch each.)
  const v4 non_finite = (origin4 - origin4) + (inv_far4 - inv_far4);
  const bool fast_box_test =
      (lane_bits((non_finite == v4{}) & (inv4 != v4{})) == 0xF) & (tmin >= 0) & (tmax == tmax);
  if constexpr (!Avx) {
    // A direction with an infinite or NaN component (a zero or NaN inverse)
    // hits nothing, as in the scalar test; RayTriangle4Test takes the
    // direction to be finite. The SIMD kernels send such rays here: they
    // fail the fast test.
    if (lane_bits((inv4 == v4{}) | (inv4 != inv4)) != 0) return hit;
  }
  if constexpr (Avx) {
    // The SIMD kernels keep only the fast test in their loop (fewer values
    // live across it, no branch per node); the other rays take the portable
    // kernel, whose hits are the same, bit for bit.
    if (!fast_box_test) [[unlikely]]
      return intersect_wide_portable<W, Any>(nodes, ray);
  }
  TraversalStack<WideEntry> stack(traversal_stack_size(depth_, W));
  // Start fetching what a child needs, every cache line of it (a node: 2 or
  // 4 lines; a leaf: its groups of 160 bytes, which straddle lines); the cache
  // misses on nodes and triangles dominate incoherent rays. A leaf's lines are
  // fetched without a loop over its size, whose exit mispredicted about once
  // per ray: the 3 lines a group spans (groups start at multiples of 32
  // bytes), then the next 3 for a leaf of more than one group, the same 3
  // again for a leaf of one (a second prefetch of a line costs no traffic;
  // clamping each address to the leaf cost 4 instructions a line). The groups
  // of larger leaves past the second are left to the hardware prefetcher.
  auto prefetch = [&](const WideEntry& e) GEODS_BVH_INLINE_LAMBDA {
    if (e.count == 0) {
      const char* p = reinterpret_cast<const char*>(&node_at[e.child]);
      for (std::size_t k = 0; k < sizeof(WideNode<W>); k += 64) __builtin_prefetch(p + k);
      return;
    }
    static_assert(sizeof(TriangleGroup) <= 3 * 64 - 32 && alignof(TriangleGroup) >= 32);
    const char* first = reinterpret_cast<const char*>(
        reinterpret_cast<std::uintptr_t>(&group_at[e.child]) & ~std::uintptr_t(63));
    // (A mask, not ?:: GCC turned the choice into a cmov for each line.)
    const char* second = first + (-std::uintptr_t(e.count > 1) & (3 * 64));
    for (int k = 0; k < 3; ++k) __builtin_prefetch(first + 64 * k);
    for (int k = 0; k < 3; ++k) __builtin_prefetch(second + 64 * k);
  };
  auto mask_bits = [&](const auto& m) GEODS_BVH_INLINE_LAMBDA {
#if defined(GEODS_BVH_SIMD_DISPATCH)
    if constexpr (Avx && sizeof(m) == 32) return lane_bits_avx(m);
#endif
    return lane_bits(m);
  };
  // The entry and exit distances of the ray at the slabs of axis a of the W
  // children, the exit's computed with far_inv (inv_far: widened).
  auto slab = [&](const WideNode<W>& node, int a, const vf& far_inv, vf& t0, vf& t1) GEODS_BVH_INLINE_LAMBDA {
    const char* rows = reinterpret_cast<const char*>(node.bounds);
    vf lo, hi;
    std::memcpy(&lo, rows + near_offset[a], sizeof(vf));
    std::memcpy(&hi, rows + (near_offset[a] ^ sizeof(vf)), sizeof(vf));
    t0 = (lo - org[a]) * inv[a];
    t1 = (hi - org[a]) * far_inv;
  };
  // The children whose boxes the ray enters before tmax, all W at once.
  auto children = [&](const WideEntry& e, float* keys) GEODS_BVH_INLINE_LAMBDA {
    const WideNode<W>& node = node_at[e.child];
    if (Avx || fast_box_test) [[likely]] {
      vf t0x, t1x, t0y, t1y, t0z, t1z;
      slab(node, 0, inv_far[0], t0x, t1x);
      slab(node, 1, inv_far[1], t0y, t1y);
      slab(node, 2, inv_far[2], t0z, t1z);
      const vf n01 = t0x > t0y ? t0x : t0y;
      const vf n2 = t0z > tmin_v ? t0z : tmin_v;
      const vf tn = n01 > n2 ? n01 : n2;
      const vf f01 = t1x < t1y ? t1x : t1y;
      const vf f2 = t1z < tmax_far ? t1z : tmax_far;
      const vf tf = f01 < f2 ? f01 : f2;
      std::memcpy(keys, &tn, sizeof tn);
      return mask_bits(tn <= tf);
    }
    vf tn = tmin_v, tf;
    broadcast(tf, tmax);
    for (int a = 0; a < 3; ++a) {
      vf t0, t1;
      slab(node, a, inv[a], t0, t1);
      // Written so that a NaN t0 or t1 leaves the interval unchanged.
      tn = t0 > tn ? t0 : tn;
      tf = t1 < tf ? t1 : tf;
    }
    std::memcpy(keys, &tn, sizeof tn);
    // An empty slot's slab distances are all NaN for a NaN origin or a ray
    // with no finite nonzero inverse, and the chain keeps the interval then:
    // such slots are dropped by their child index instead.
    static_assert(WideNode<W>::kEmpty == ~std::uint32_t(0));
    using vi = decltype(tn < tf);
    vi child;
    std::memcpy(&child, node.child, sizeof child);
    return mask_bits((tn <= widen_far(tf)) & (child != ~vi{}));
  };
  auto child = [&](const WideEntry& e, int i, float t) GEODS_BVH_INLINE_LAMBDA {
    const WideEntry c{node_at[e.child].child[i], node_at[e.child].count[i], t};
    prefetch(c);
    return c;
  };
  // Two groups at a time, 8 lanes wide: a leaf of the default size (8
  // triangles, at most 2 groups) in one test, without a loop whose exit
  // mispredicted about once a ray; a last group alone takes lanes 0-3 only.
  auto leaf = [&](const WideEntry& e) GEODS_BVH_INLINE_LAMBDA {
    const std::uint32_t end = e.child + e.count;
    for (std::uint32_t g = e.child; g < end; g += 2) {
      // (Arithmetic, not ?:: GCC branched on it, mispredicting half a time a ray.)
      const std::uint32_t pair = std::uint32_t(g + 1 < end);
      RayTriangle4Test::vf8 t, u, v;
      const int mask = test.intersect(group_at[g], group_at[g + pair], int(0x0F | (0xF0 & -pair)), tmin, tmax, t, u, v,
                                      [&](const auto& m) GEODS_BVH_INLINE_LAMBDA { return mask_bits(m); });
      if (mask == 0) continue;
      // The nearest lane, ties to the last one: what testing the triangles
      // one after the other, each against the shrinking tmax, would keep.
      // Usually a single lane: no data-dependent branch per lane then.
      int best = __builtin_ctz(unsigned(mask));
      if (mask & (mask - 1)) {
        for (int i = best + 1; i < 8; ++i)
          if ((mask >> i & 1) && t[i] <= t[best]) best = i;
      }
      hit = {t[best], group_at[g + (best >> 2)].index[best & 3], u[best], v[best]};
      if constexpr (Any) return false;  // the traversal ends here: no bound to tighten
      tmax = t[best];
      tmax_widened = widen_far(tmax);
      broadcast(tmax_far, tmax * kWiden);
    }
    return true;
  };
  const auto is_leaf = [](const WideEntry& e) GEODS_BVH_INLINE_LAMBDA { return e.count != 0; };
  const auto still_needed = [&](const WideEntry& e) GEODS_BVH_INLINE_LAMBDA { return e.key <= tmax_widened; };
  // Any hit ends the traversal, so the order of the children does not matter.
  traverse<W, !Any>(WideEntry{0, 0, tmin}, stack, is_leaf, children, child, leaf, still_needed);
  return hit;
}

template <typename BV>
RayHit TriangleBvh::intersect_generic(const FlatArray<BV>& volumes, const Ray3f& ray, bool any) const {
  RayHit hit;
  const RayTriangleTest<float> test(ray);
  const Vec3f inv = ray.direction.cwiseInverse();
  Ray3f clipped = ray;
  TraversalStack<NodeRef> stack(traversal_stack_size(depth_, options_.arity));
  traverse_topology<true>(
      topology_, 0, stack,
      [&](std::uint32_t node, float& t) GEODS_BVH_INLINE_LAMBDA {
        const auto iv = ray_interval(volumes[node], clipped, inv);
        t = iv.first;
        return interval_hit(iv) && may_hit_before(t, clipped.tmax);
      },
      [&](const TopoNode& node) GEODS_BVH_INLINE_LAMBDA {
        for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i) {
          const Triangle& tri = triangles_[i];
          float t, u, v;
          if (test.intersect(tri.a, tri.b, tri.c, ray.tmin, clipped.tmax, t, u, v)) {
            clipped.tmax = t;
            hit = {t, topology_.prim_order[i], u, v};
            if (any) return false;
          }
        }
        return true;
      },
      [&](float t) GEODS_BVH_INLINE_LAMBDA { return may_hit_before(t, clipped.tmax); });
  return hit;
}

void TriangleBvh::set_ray_range() {
  const AABB3f bounds = parallel_bounds<AABB3f>(triangles_.size(), [&](AABB3f& box, std::size_t i) {
    box.extend(triangles_[i].a);
    box.extend(triangles_[i].b);
    box.extend(triangles_[i].c);
  });
  ray_range_problem_ = ray_range_problem(bounds, "TriangleBvh");
}

RayHit TriangleBvh::intersect(const Ray3f& ray) const {
  check_ray(ray);
  if (!wide4_.empty()) return intersect_wide_best<4, false>(wide4_, ray);
  if (!wide8_.empty()) return intersect_wide_best<8, false>(wide8_, ray);
  return std::visit([&](const auto& vols) { return intersect_generic(vols, ray, false); }, volumes_);
}

bool TriangleBvh::occluded(const Ray3f& ray) const {
  check_ray(ray);
  if (!wide4_.empty()) return intersect_wide_best<4, true>(wide4_, ray).hit();
  if (!wide8_.empty()) return intersect_wide_best<8, true>(wide8_, ray).hit();
  return std::visit([&](const auto& vols) { return intersect_generic(vols, ray, true).hit(); }, volumes_);
}

// ------------------------------------------------------------------ closest point, containment

template <typename BV>
ClosestPoint TriangleBvh::closest_generic(const FlatArray<BV>& volumes, std::uint32_t start, const Vec3f& p,
                                          float max_distance) const {
  ClosestPoint best;
  float best_d2 = max_distance * max_distance;
  TraversalStack<NodeRef> stack(traversal_stack_size(depth_, options_.arity));
  traverse_topology<true>(
      topology_, start, stack,
      [&](std::uint32_t node, float& d2) GEODS_BVH_INLINE_LAMBDA {
        d2 = squared_distance(volumes[node], p);
        return d2 <= best_d2;
      },
      [&](const TopoNode& node) GEODS_BVH_INLINE_LAMBDA {
        for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i) {
          const Triangle& tri = triangles_[i];
          const Vec3f q = closest_point_on_triangle(p, tri.a, tri.b, tri.c);
          const float d2 = (q - p).squaredNorm();
          if (d2 < best_d2 || (d2 == best_d2 && best.prim == RayHit::no_hit)) {
            best_d2 = d2;
            best.point = q;
            best.prim = topology_.prim_order[i];
          }
        }
      },
      [&](float d2) GEODS_BVH_INLINE_LAMBDA { return d2 <= best_d2; });
  if (best.prim != RayHit::no_hit) best.distance = std::sqrt(best_d2);
  return best;
}

ClosestPoint TriangleBvh::closest_point(const Vec3f& p, float max_distance) const {
  if (!p.allFinite()) throw Error("bvh closest_point: the query point is not finite");
  return std::visit([&](const auto& vols) { return closest_generic(vols, 0, p, max_distance); }, volumes_);
}

template <typename Fn>
void TriangleBvh::for_each_crossing(const Ray3f& ray, Fn&& fn) const {
  const RayTriangleTest<float> test(ray);
  const Vec3f inv = ray.direction.cwiseInverse();
  visit_unordered(
      [&](const auto& volume) { return interval_hit(ray_interval(volume, ray, inv)); },
      [&](std::uint32_t i) {
        float t, u, v;
        if (test.intersect(triangles_[i].a, triangles_[i].b, triangles_[i].c, ray.tmin, ray.tmax, t, u, v)) fn(t, u, v);
      });
}

bool TriangleBvh::contains(const Vec3f& p) const {
  if (!p.allFinite()) throw Error("bvh contains: the query point is not finite");
  if (triangles_.empty()) return false;
  // On the surface (up to 1e-6 of the mesh size): inside.
  const float size = std::visit([](const auto& v) { return bounds(v[0]).extent().maxCoeff(); }, volumes_);
  if (closest_point(p, std::max(size, 1e-30f) * 1e-6f).prim != RayHit::no_hit) return true;
  constexpr float kEdge = 1e-5f;  // a crossing this close to an edge makes the ray untrusted
  int votes_in = 0, trusted = 0, first_parity = -1;
  for (const Vec3f& d : kContainDirections) {
    Ray3f ray;
    ray.origin = p;
    ray.direction = d;
    int crossings = 0;
    bool on_surface = false, near_edge = false;
    for_each_crossing(ray, [&](float t, float u, float v) {
      ++crossings;
      if (t == 0.0f) on_surface = true;
      if (u < kEdge || v < kEdge || 1.0f - u - v < kEdge) near_edge = true;
    });
    if (on_surface) return true;
    if (first_parity < 0) first_parity = crossings % 2;
    if (near_edge) continue;
    votes_in += crossings % 2;
    if (++trusted == 3) break;
  }
  if (trusted == 0) return first_parity == 1;
  return 2 * votes_in > trusted;
}

// ------------------------------------------------------------------ culling

template <typename Accept, typename OnTriangle>
void TriangleBvh::visit_unordered(Accept&& accept, OnTriangle&& triangle) const {
  std::visit(
      [&](const auto& volumes) {
        TraversalStack<NodeRef> stack(traversal_stack_size(depth_, options_.arity));
        traverse_topology<false>(
            topology_, 0, stack, [&](std::uint32_t node, float&) { return accept(volumes[node]); },
            [&](const TopoNode& node) {
              for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i) triangle(i);
            },
            [](float) { return true; });
      },
      volumes_);
}

std::vector<std::uint32_t> TriangleBvh::cull_box(const AABB3f& box) const {
  std::vector<std::uint32_t> out;
  if (box.empty()) return out;
  visit_unordered([&](const auto& volume) { return bounds(volume).overlaps(box); },
                  [&](std::uint32_t i) {
                    if (triangle_box_overlap(triangles_[i].a, triangles_[i].b, triangles_[i].c, box))
                      out.push_back(topology_.prim_order[i]);
                  });
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::uint32_t> TriangleBvh::cull_frustum(std::span<const Plane3f> planes) const {
  std::vector<std::uint32_t> out;
  std::vector<Plane3f> outward;
  for (const Plane3f& p : planes) outward.push_back(p.flipped());
  visit_unordered(
      [&](const auto& volume) {
        bool culled = false;
        for (const Plane3f& p : outward) culled = culled || above(volume, p);
        return !culled;
      },
      [&](std::uint32_t i) {
        const Triangle& t = triangles_[i];
        bool outside = false;
        for (const Plane3f& p : planes)
          outside = outside || (p.signed_distance(t.a) < 0 && p.signed_distance(t.b) < 0 && p.signed_distance(t.c) < 0);
        if (!outside) out.push_back(topology_.prim_order[i]);
      });
  std::sort(out.begin(), out.end());
  return out;
}

// ------------------------------------------------------------------ stats, validate

BvhStats TriangleBvh::stats() const {
  BvhStats s;
  const auto& nodes = topology_.nodes;
  s.triangles = triangles_.size();
  s.nodes = nodes.size();
  for (const auto& n : nodes) s.leaves += n.leaf();
  s.depth = depth_;
  s.bytes = nodes.size() * sizeof(TopoNode) + topology_.prim_order.size() * sizeof(std::uint32_t) +
            triangles_.size() * sizeof(Triangle) + wide4_.size() * sizeof(WideNode<4>) +
            wide8_.size() * sizeof(WideNode<8>) + groups_.size() * sizeof(TriangleGroup);
  if (nodes.empty()) return s;
  std::visit(
      [&](const auto& volumes) {
        using BV = typename std::decay_t<decltype(volumes)>::value_type;
        s.bytes += volumes.size() * sizeof(BV);
        std::vector<std::pair<double, double>> m(nodes.size());
        parallel_for_each_index(0, nodes.size(), [&](std::size_t i) { m[i] = measures(volumes[i]); }, 256);
        double cost = 0, tight = 0;
        std::size_t inner = 0;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
          if (nodes[i].leaf()) {
            cost += m[i].second * nodes[i].prim_count;
            continue;
          }
          cost += m[i].second;
          double children = 0;
          for (std::uint32_t c = 0; c < nodes[i].num_children; ++c) children += m[nodes[i].first_child + c].first;
          if (children > 0) {
            tight += m[i].first / children;
            ++inner;
          }
        }
        s.sah_cost = m[0].second > 0 ? cost / m[0].second : 0;
        s.tightness_volume = inner ? tight / double(inner) : 0;
        // Definition 3 on the top three levels.
        std::vector<int> level(nodes.size(), 0);
        std::vector<std::uint32_t> top;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
          if (level[i] <= 2) top.push_back(std::uint32_t(i));
          for (std::uint32_t c = 0; c < nodes[i].num_children; ++c) level[nodes[i].first_child + c] = level[i] + 1;
        }
        std::vector<double> ratio(top.size(), -1);
        parallel_for_each_index(0, top.size(), [&](std::size_t k) {
          const std::uint32_t id = top[k];
          const TopoNode& node = nodes[id];
          double diam = 0;
          for (const auto& dir : kdop_all_directions) {
            const Vec3f d{float(dir[0]), float(dir[1]), float(dir[2])};
            float lo = std::numeric_limits<float>::infinity(), hi = -lo;
            for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i)
              for (const Vec3f* v : {&triangles_[i].a, &triangles_[i].b, &triangles_[i].c}) {
                lo = std::min(lo, d.dot(*v));
                hi = std::max(hi, d.dot(*v));
              }
            diam = std::max(diam, double(hi - lo) / double(d.norm()));
          }
          const AABB3f box = bounds(volumes[id]);
          double h = -1;
          for (int x = 0; x < 5; ++x)
            for (int y = 0; y < 5; ++y)
              for (int z = 0; z < 5; ++z) {
                const Vec3f q = box.lo + Vec3f((x + 0.5f) / 5, (y + 0.5f) / 5, (z + 0.5f) / 5).cwiseProduct(box.extent());
                if (!bvh::contains(volumes[id], q)) continue;
                h = std::max(h, double(closest_generic(volumes, id, q, std::numeric_limits<float>::infinity()).distance));
              }
          if (h >= 0 && diam > 0) ratio[k] = h / diam;
        }, 1);
        double sum = 0;
        int counted = 0;
        for (double r : ratio)
          if (r >= 0) sum += r, ++counted;
        s.tightness_hausdorff = counted ? sum / counted : 0;
      },
      volumes_);
  return s;
}

void TriangleBvh::validate() const {
  const auto& nodes = topology_.nodes;
  const std::size_t n = triangles_.size();
  auto fail = [](const std::string& what) { throw Error("bvh validate: " + what); };
  if (topology_.prim_order.size() != n) fail("triangle id count differs from the triangle count");
  if (n == 0) {
    if (!nodes.empty()) fail("nodes without triangles");
    return;
  }
  std::vector<char> seen(n, 0);
  for (std::uint32_t id : topology_.prim_order) {
    if (id >= n || seen[id]) fail("triangle ids are not a permutation");
    seen[id] = 1;
  }
  if (nodes.empty() || nodes[0].prim_first != 0 || nodes[0].prim_count != n) fail("the root does not cover every triangle");
  std::vector<char> reached(nodes.size(), 0);
  reached[0] = 1;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const TopoNode& node = nodes[i];
    const std::string at = "node " + std::to_string(i) + ": ";
    if (!reached[i]) fail(at + "not reachable from the root");
    if (node.prim_count == 0) fail(at + "covers no triangle");
    if (node.leaf()) {
      if (node.prim_count > std::uint32_t(options_.leaf_size)) fail(at + "leaf larger than leaf_size");
      continue;
    }
    if (node.num_children < 2 || node.num_children > std::uint32_t(options_.arity)) fail(at + "bad child count");
    if (node.first_child <= i || node.first_child + node.num_children > nodes.size()) fail(at + "bad child index");
    std::uint32_t next = node.prim_first;
    for (std::uint32_t c = 0; c < node.num_children; ++c) {
      const TopoNode& child = nodes[node.first_child + c];
      if (reached[node.first_child + c]) fail(at + "child with two parents");
      reached[node.first_child + c] = 1;
      if (child.prim_first != next) fail(at + "children do not partition its triangle range");
      next += child.prim_count;
    }
    if (next != node.prim_first + node.prim_count) fail(at + "children do not partition its triangle range");
  }
  std::visit(
      [&](const auto& volumes) {
        if (volumes.size() != nodes.size()) fail("one bounding volume per node expected");
        for (std::size_t i = 0; i < nodes.size(); ++i)
          for (std::uint32_t t = nodes[i].prim_first; t < nodes[i].prim_first + nodes[i].prim_count; ++t)
            for (const Vec3f* v : {&triangles_[t].a, &triangles_[t].b, &triangles_[t].c})
              if (!bvh::contains(volumes[i], *v))
                fail("node " + std::to_string(i) + ": a vertex of triangle " + std::to_string(topology_.prim_order[t]) +
                     " lies outside its bounding volume");
      },
      volumes_);
  const bool wide = options_.bv == BoundingVolume::aabb && options_.arity >= 4 && n > 0;
  if (wide != (!wide4_.empty() || !wide8_.empty())) fail("wide nodes missing or unexpected");
  auto check_wide = [&](const auto& wnodes) {
    // Every triangle must be reachable exactly once through the wide nodes,
    // every wide node once, no deeper than the traversal stack is sized for.
    std::vector<char> covered(n, 0), visited(wnodes.size(), 0);
    std::vector<std::uint32_t> leaf_position(n);  // groups name mesh triangles; triangles_ is in leaf order
    for (std::uint32_t i = 0; i < n; ++i) leaf_position[topology_.prim_order[i]] = i;
    std::vector<std::pair<std::uint32_t, int>> stack{{0, 0}};  // (wide node, its depth)
    const int max_depth = topology_.depth();
    while (!stack.empty()) {
      const auto [index, level] = stack.back();
      stack.pop_back();
      if (visited[index]) fail("wide node " + std::to_string(index) + " reached twice");
      visited[index] = 1;
      if (level > max_depth) fail("wide nodes deeper than the hierarchy");
      const auto& w = wnodes[index];
      for (std::size_t s = 0; s < std::size(w.child); ++s) {
        if (w.child[s] == std::decay_t<decltype(w)>::kEmpty) {
          // An empty slot must stay unhittable: lo = +inf, hi = -inf.
          bool unhittable = w.count[s] == 0;
          for (int a = 0; a < 3; ++a)
            unhittable = unhittable && w.bounds[2 * a][s] == std::numeric_limits<float>::infinity() &&
                         w.bounds[2 * a + 1][s] == -std::numeric_limits<float>::infinity();
          if (!unhittable) fail("wide node " + std::to_string(index) + ": an empty slot can be hit");
          continue;
        }
        const AABB3f box({w.bounds[0][s], w.bounds[2][s], w.bounds[4][s]}, {w.bounds[1][s], w.bounds[3][s], w.bounds[5][s]});
        if (w.count[s] == 0) {
          if (w.child[s] >= wnodes.size()) fail("wide node child out of range");
          stack.push_back({w.child[s], level + 1});
          continue;
        }
        if (w.child[s] + std::size_t(w.count[s]) > groups_.size()) fail("wide leaf groups out of range");
        for (std::uint32_t g = w.child[s]; g < w.child[s] + w.count[s]; ++g) {
          const TriangleGroup& group = groups_[g];
          for (int lane = 0; lane < 4; ++lane) {
            const std::uint32_t t = group.index[lane];
            if (t >= n) fail("triangle group index out of range");
            // Unused lanes repeat the group's last triangle.
            if (lane > 0 && t == group.index[lane - 1]) continue;
            if (covered[t]) fail("wide leaves do not cover each triangle once");
            covered[t] = 1;
            const Triangle& tri = triangles_[leaf_position[t]];
            if (!lane_holds(group, lane, tri.a, tri.b, tri.c)) fail("a triangle group differs from its triangle");
            if (!box.contains(tri.a) || !box.contains(tri.b) || !box.contains(tri.c))
              fail("a wide leaf box does not hold its triangle");
          }
        }
      }
    }
    if (std::count(covered.begin(), covered.end(), 1) != std::ptrdiff_t(n)) fail("wide leaves miss triangles");
  };
  if (!wide4_.empty()) check_wide(wide4_);
  if (!wide8_.empty()) check_wide(wide8_);
}

}  // namespace geods::bvh
