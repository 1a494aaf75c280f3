#pragma once
// Four triangles side by side (structure of arrays, Embree's "triangle4"
// idea) and the watertight test of core/ray_triangle.hpp on all four at once
// with 4-wide GCC/Clang vector extensions (SSE on x86, plain scalar code where
// there is no SIMD). Every lane performs the scalar test's operations in the
// same order, and a lane whose edge function rounds to zero is handed to the
// scalar test itself (its double-precision recomputation), so t, u, v and the
// hit decision are bit-identical to RayTriangleTest<float>.
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "geods/bvh/traversal.hpp"  // GEODS_BVH_INLINE_LAMBDA
#include "geods/core/ray_triangle.hpp"

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace geods::bvh {

struct alignas(32) TriangleGroup {  // 160 bytes
  /// corner[k][a][i]: coordinate a of corner k (a, b, c) of lane i's triangle.
  float corner[3][3][4];
  /// Index of each lane's triangle (TriangleBvh: in the mesh). A group holds
  /// 1 to 4 triangles; unused lanes repeat the last one (same result, same index).
  std::uint32_t index[4];
};

/// Puts triangle (a, b, c), number `index`, in lane `lane` of g. A triangle
/// of zero area gets NaN corners: no lane test ever hits it, as the scalar
/// test never does (has_zero_area), without a per-ray cost.
inline void set_lane(TriangleGroup& g, int lane, const Vec3f& a, const Vec3f& b, const Vec3f& c,
                     std::uint32_t index) {
  const bool zero = has_zero_area(a, b, c);
  const Vec3f* corners[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k)
    for (int x = 0; x < 3; ++x) g.corner[k][x][lane] = zero ? std::numeric_limits<float>::quiet_NaN() : (*corners[k])[x];
  g.index[lane] = index;
}

/// Whether lane `lane` of g holds (a, b, c) as set_lane puts it there (bit
/// for bit: a zero-area triangle's NaN corners included).
inline bool lane_holds(const TriangleGroup& g, int lane, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  TriangleGroup expected{};
  set_lane(expected, lane, a, b, c, g.index[lane]);
  for (int k = 0; k < 3; ++k)
    for (int x = 0; x < 3; ++x)
      if (std::bit_cast<std::uint32_t>(g.corner[k][x][lane]) != std::bit_cast<std::uint32_t>(expected.corner[k][x][lane]))
        return false;
  return true;
}

/// The watertight test's edge functions of a triangle whose corners, relative to
/// the ray's origin in its sheared frame, are (px, py): RayTriangleTest's
/// operations in its order, for any vector of lanes (the triangles of a group
/// against one ray here, one triangle against the rays of a packet in
/// ray_packet.cpp). `inside`: lanes hit unless t is out of range; `on_edge`:
/// lanes for the scalar test's double-precision path. As vector masks, or as
/// bit masks with a `bits` that turns each comparison into one (packets of
/// 16: GCC scalarizes & and | of 16-lane comparisons inlined into AVX-512 code).
// (Always inlined: the wide vectors below cross no call, so no ABI concern.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
struct SameMask {
  template <typename M>
  [[gnu::always_inline]] M operator()(M m) const {
    return m;
  }
};
template <typename VF, typename Mask = decltype(VF{} < VF{})>
struct ShearedEdges {
  VF eu, ev, ew, det;
  Mask on_edge, inside;
};
template <typename VF, typename Bits = SameMask>
[[gnu::always_inline]] inline auto sheared_edges(const VF (&px)[3], const VF (&py)[3], Bits bits = {}) {
  ShearedEdges<VF, decltype(bits(VF{} < VF{}))> e;
  e.eu = px[2] * py[1] - py[2] * px[1];
  e.ev = px[0] * py[2] - py[0] * px[2];
  e.ew = px[1] * py[0] - py[1] * px[0];
  const VF zero{};
  e.on_edge = bits(e.eu == zero) | bits(e.ev == zero) | bits(e.ew == zero);
  // Signs mixed: the sign bits differ. (Decides as the scalar test's < 0 and
  // > 0 wherever it matters: a zero is on_edge, a NaN makes det NaN.)
  using VI = decltype(VF{} < VF{});
  const VI eu = __builtin_bit_cast(VI, e.eu);
  const auto mixed = bits(((eu ^ __builtin_bit_cast(VI, e.ev)) | (eu ^ __builtin_bit_cast(VI, e.ew))) < VI{});
  e.det = e.eu + e.ev + e.ew;
  // det - det is 0 exactly for a finite det (NaN for inf and NaN). (det of
  // three nonzero values of one sign is not 0.)
  e.inside = ~mixed & ~e.on_edge & bits(e.det - e.det == zero);
  return e;
}
class RayTriangle4Test {
 public:
  typedef float vf __attribute__((vector_size(16)));
  typedef std::int32_t vi __attribute__((vector_size(16)));
  typedef float vf8 __attribute__((vector_size(32)));

  /// `ray` must outlive the test (the on-edge lanes read it).
  explicit RayTriangle4Test(const Ray3f& ray) : ray_(&ray) {
    const RayTriangleTest<float> scalar(ray);
    const int k[3] = {scalar.axis_x(), scalar.axis_y(), scalar.axis_z()};
    for (int a = 0; a < 3; ++a) {
      axis_offset_[a] = k[a] * std::ptrdiff_t(sizeof(vf));
      origin_[a] = vf{} + ray.origin[k[a]];
    }
    shear_x_ = vf{} + scalar.shear_x();
    shear_y_ = vf{} + scalar.shear_y();
    // The scalar test's shear_z for a finite direction (the only kind the
    // traversals test triangles with), computed here: with the scalar test's
    // check for an infinite one inlined, GCC scheduled the AVX-512 kernel
    // worse (4-5 % slower on 100k incoherent rays, paired with Embree).
    shear_z_ = vf{} + 1.0f / ray.direction[k[2]];
  }

  /// Bit i set: lane i's triangle is hit with t in [tmin, tmax], its t and
  /// barycentrics in t[i], u[i], v[i] (other lanes hold garbage).
  /// (Always inlined: the traversals' flatten alone left it out of line in some of them.)
  [[gnu::always_inline]] int intersect(const TriangleGroup& g, float tmin, float tmax, vf& t, vf& u, vf& v) const {
    const char* base = reinterpret_cast<const char*>(&g);
    return test<vf>(
        [&](std::size_t offset) GEODS_BVH_INLINE_LAMBDA { return load(base + offset); }, 0xF, tmin, tmax, t, u, v,
        [](vi m) GEODS_BVH_INLINE_LAMBDA { return movemask(m); },
        [&](int) GEODS_BVH_INLINE_LAMBDA -> const TriangleGroup& { return g; });
  }

  /// intersect for the triangles of two groups at once, 8 wide (one AVX
  /// operation a step where the caller is compiled for it): lanes 0-3 are
  /// g0's, lanes 4-7 g1's, and only the lanes set in `lanes` are tested.
  /// bits(m): the bit mask of an 8-lane comparison (one vmovmskps with AVX).
  template <typename Bits>
  [[gnu::always_inline]] int intersect(const TriangleGroup& g0, const TriangleGroup& g1, int lanes, float tmin,
                                       float tmax, vf8& t, vf8& u, vf8& v, Bits bits) const {
    const char* base0 = reinterpret_cast<const char*>(&g0);
    const char* base1 = reinterpret_cast<const char*>(&g1);
    return test<vf8>(
        [&](std::size_t offset) GEODS_BVH_INLINE_LAMBDA {
          return __builtin_shufflevector(load(base0 + offset), load(base1 + offset), 0, 1, 2, 3, 4, 5, 6, 7);
        },
        lanes, tmin, tmax, t, u, v, bits,
        [&](int lane) GEODS_BVH_INLINE_LAMBDA -> const TriangleGroup& { return lane < 4 ? g0 : g1; });
  }

 private:
  // The test on the lanes of V (4 or 8): load(offset) gives the row at that
  // byte offset of the group(s), group(i) the group of lane i (lane i % 4 in it).
  template <typename V, typename Load, typename Bits, typename Group>
  [[gnu::always_inline]] int test(Load load, int lanes, float tmin, float tmax, V& t, V& u, V& v, Bits bits,
                                  Group group) const {
    // Corner k relative to the origin, in the sheared frame (x, y; z unscaled).
    V px[3], py[3], pz[3];
    for (int c = 0; c < 3; ++c) {
      const std::size_t corner = c * sizeof(TriangleGroup::corner[c]);
      pz[c] = load(corner + axis_offset_[2]) - lanes_of<V>(origin_[2]);
      px[c] = (load(corner + axis_offset_[0]) - lanes_of<V>(origin_[0])) - lanes_of<V>(shear_x_) * pz[c];
      py[c] = (load(corner + axis_offset_[1]) - lanes_of<V>(origin_[1])) - lanes_of<V>(shear_y_) * pz[c];
    }
    const ShearedEdges<V> e = sheared_edges(px, py);
    const int edge_mask = bits(e.on_edge) & lanes;
    // Most groups a ray reaches are missed: skip the division then.
    if ((bits(e.inside) & lanes) == 0 && edge_mask == 0) return 0;
    const V shear_z = lanes_of<V>(shear_z_);
    const V scaled_t = e.eu * (shear_z * pz[0]) + e.ev * (shear_z * pz[1]) + e.ew * (shear_z * pz[2]);
    const V inv_det = 1.0f / e.det;
    t = scaled_t * inv_det;
    u = e.ev * inv_det;
    v = e.ew * inv_det;
    int mask = bits(e.inside & (t >= tmin) & (t <= tmax)) & lanes;
    if (edge_mask != 0) [[unlikely]] {
      const RayTriangleTest<float> scalar(*ray_);
      for (int i = 0; i < int(sizeof(V) / sizeof(float)); ++i) {
        if (!(edge_mask >> i & 1)) continue;
        const TriangleGroup& g = group(i);
        float hit_t, hit_u, hit_v;
        if (scalar.intersect(corner(g, 0, i % 4), corner(g, 1, i % 4), corner(g, 2, i % 4), tmin, tmax, hit_t, hit_u,
                             hit_v)) {
          t[i] = hit_t, u[i] = hit_u, v[i] = hit_v;
          mask |= 1 << i;
        }
      }
    }
    return mask;
  }
  // A splat of 4 lanes as V: itself, or twice (one vbroadcastf128).
  template <typename V>
  [[gnu::always_inline]] static V lanes_of(const vf& x) {
    if constexpr (sizeof(V) == sizeof(vf)) {
      return x;
    } else {
      return __builtin_shufflevector(x, x, 0, 1, 2, 3, 0, 1, 2, 3);
    }
  }
  static vf load(const char* p) {
    vf r;
    __builtin_memcpy(&r, p, sizeof r);
    return r;
  }
  static int movemask(vi m) {
#if defined(__SSE__)
    return _mm_movemask_ps(reinterpret_cast<__m128>(m));
#else
    return (m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8);
#endif
  }
  static Vec3f corner(const TriangleGroup& g, int k, int lane) {
    return {g.corner[k][0][lane], g.corner[k][1][lane], g.corner[k][2][lane]};
  }

  // The ray, for the scalar test of on-edge lanes: built there, where it is
  // rare, rather than kept (GCC kept its fields in memory, stored per ray).
  const Ray3f* ray_;
  std::ptrdiff_t axis_offset_[3];  // byte offset of the kx, ky, kz rows in a corner (3 registers, not one per corner)
  vf origin_[3];                  // origin coordinate along kx, ky, kz, in every lane
  vf shear_x_, shear_y_, shear_z_;
};
#pragma GCC diagnostic pop

}  // namespace geods::bvh
