#pragma once
// Four triangles side by side (structure of arrays, Embree's "triangle4"
// idea) and the watertight test of core/ray_triangle.hpp on all four at once
// with 4-wide GCC/Clang vector extensions (SSE on x86, plain scalar code where
// there is no SIMD), or on two groups at once with 8-wide ones (AVX code: the
// wide traversal's AVX kernels test a leaf's two groups so). Every lane
// performs the scalar test's operations in the same order, and a lane whose
// edge function rounds to zero is handed to the scalar test itself (its
// double-precision recomputation), so t, u, v and the hit decision are
// bit-identical to RayTriangleTest<float>.
#include <cstdint>
#include <limits>

#include "geods/core/ray_triangle.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#elif defined(__SSE__)
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

/// The watertight test's edge functions of a triangle whose corners, relative to
/// the ray's origin in its sheared frame, are (px, py): RayTriangleTest's
/// operations in its order, for any vector of lanes (the triangles of a group
/// against one ray here, one triangle against the rays of a packet in
/// ray_packet.cpp). `inside`: lanes hit unless t is out of range; `on_edge`:
/// lanes for the scalar test's double-precision path. As vector masks, or as
/// bit masks with a `bits` that turns each comparison into one (packets of
/// 16: GCC scalarizes & and | of 16-lane comparisons inlined into AVX-512 code).
// (Always inlined, as the 8-lane test below: its vectors cross no call, so no ABI concern.)
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
  const auto mixed = (bits(e.eu < zero) | bits(e.ev < zero) | bits(e.ew < zero)) &
                     (bits(e.eu > zero) | bits(e.ev > zero) | bits(e.ew > zero));
  e.det = e.eu + e.ev + e.ew;
  // det - det is 0 exactly for a finite det (NaN for inf and NaN).
  e.inside = ~mixed & ~e.on_edge & bits(e.det != zero) & bits(e.det - e.det == zero);
  return e;
}

// The lane vectors of RayTriangleGroupTest<N>.
template <int N>
struct GroupLanes;  // (GCC drops vector_size on a typedef that depends on a template parameter)
template <>
struct GroupLanes<4> {
  typedef float vf __attribute__((vector_size(16)));
  typedef std::int32_t vi __attribute__((vector_size(16)));
};
template <>
struct GroupLanes<8> {
  typedef float vf __attribute__((vector_size(32)));
  typedef std::int32_t vi __attribute__((vector_size(32)));
};

/// The watertight test of one ray against the triangles of N / 4 triangle
/// groups at once: N = 4 (SSE) or 8 (two groups in one AVX register, for
/// code compiled for AVX: the traversal's AVX kernels). Lanes 4 to 7 are the
/// second group's. With N = 8 a single group can also be tested alone (4 lanes).
template <int N>
class RayTriangleGroupTest {
  static_assert(N == 4 || N == 8, "groups of 4 triangles, one or two at a time");
  template <int M>
  using lanes = typename GroupLanes<M>::vf;
  template <int M>
  using lane_mask = typename GroupLanes<M>::vi;

 public:
  using v4 = lanes<4>;
  using vf = lanes<N>;

  explicit RayTriangleGroupTest(const Ray3f& ray) : scalar_(ray) {
    const int k[3] = {scalar_.axis_x(), scalar_.axis_y(), scalar_.axis_z()};
    for (int a = 0; a < 3; ++a) {
      axis_[a] = k[a];
      splat(origin_[a], scalar_.origin()[k[a]]);
    }
    splat(shear_x_, scalar_.shear_x());
    splat(shear_y_, scalar_.shear_y());
    splat(shear_z_, scalar_.shear_z());
  }

  /// Bit i set: lane i's triangle is hit with t in [tmin, tmax], its t and
  /// barycentrics in t[i], u[i], v[i] (other lanes hold garbage).
  [[gnu::always_inline]] int intersect(const TriangleGroup& g, float tmin, float tmax, v4& t, v4& u, v4& v) const {
    const TriangleGroup* groups[1] = {&g};
    return intersect_lanes<4>(groups, tmin, tmax, t, u, v);
  }
  /// The same for the 8 triangles of `first` (lanes 0-3) and `second` (4-7).
  [[gnu::always_inline]] int intersect(const TriangleGroup& first, const TriangleGroup& second, float tmin, float tmax,
                                       vf& t, vf& u, vf& v) const
    requires(N == 8)
  {
    const TriangleGroup* groups[2] = {&first, &second};
    return intersect_lanes<8>(groups, tmin, tmax, t, u, v);
  }

 private:
  template <int M>
  [[gnu::always_inline]] int intersect_lanes(const TriangleGroup* const (&groups)[M / 4], float tmin, float tmax,
                                             lanes<M>& t, lanes<M>& u, lanes<M>& v) const {
    using V = lanes<M>;
    V origin[3], shear_x, shear_y, shear_z;
    for (int a = 0; a < 3; ++a) first_lanes(origin[a], origin_[a]);
    first_lanes(shear_x, shear_x_);
    first_lanes(shear_y, shear_y_);
    first_lanes(shear_z, shear_z_);
    // Corner k relative to the origin, in the sheared frame (x, y; z unscaled).
    V px[3], py[3], pz[3];
    for (int c = 0; c < 3; ++c) {
      V x, y, z;
      load(x, groups, c, axis_[0]);
      load(y, groups, c, axis_[1]);
      load(z, groups, c, axis_[2]);
      pz[c] = z - origin[2];
      px[c] = (x - origin[0]) - shear_x * pz[c];
      py[c] = (y - origin[1]) - shear_y * pz[c];
    }
    const ShearedEdges<V> e = sheared_edges(px, py);
    const int edge_mask = movemask(e.on_edge);
    // Most groups a ray reaches are missed: skip the division then.
    if (movemask(e.inside) == 0 && edge_mask == 0) return 0;
    const V scaled_t = e.eu * (shear_z * pz[0]) + e.ev * (shear_z * pz[1]) + e.ew * (shear_z * pz[2]);
    V one, lo, hi;
    splat(one, 1.0f);
    splat(lo, tmin);
    splat(hi, tmax);
    const V inv_det = one / e.det;
    t = scaled_t * inv_det;
    u = e.ev * inv_det;
    v = e.ew * inv_det;
    int mask = movemask(e.inside & (t >= lo) & (t <= hi));
    if (edge_mask != 0) [[unlikely]] {
      for (int i = 0; i < M; ++i) {
        if (!(edge_mask >> i & 1)) continue;
        float hit_t, hit_u, hit_v;
        const TriangleGroup& g = *groups[i / 4];
        if (scalar_.intersect(corner(g, 0, i % 4), corner(g, 1, i % 4), corner(g, 2, i % 4), tmin, tmax, hit_t, hit_u,
                              hit_v)) {
          t[i] = hit_t, u[i] = hit_u, v[i] = hit_v;
          mask |= 1 << i;
        }
      }
    }
    return mask;
  }

  // (Vectors written through references: an 8-lane vector passed by value
  // has another ABI with AVX than without.)
  template <typename V>
  [[gnu::always_inline]] static void splat(V& out, float x) {
    const v4 s = {x, x, x, x};  // one broadcast (a lane-by-lane fill went through the stack)
    if constexpr (sizeof(V) == sizeof(v4)) {
      out = s;
    } else {
      out = __builtin_shufflevector(s, s, 0, 1, 2, 3, 0, 1, 2, 3);
    }
  }
  // The first M lanes of a member (free: the low half of an AVX register).
  template <typename V>
  [[gnu::always_inline]] static void first_lanes(V& out, const vf& x) {
    if constexpr (sizeof(V) == sizeof(vf)) {
      out = x;
    } else {
      out = __builtin_shufflevector(x, x, 0, 1, 2, 3);
    }
  }
  // Row a of corner c of every group, side by side.
  template <typename V, int G>
  [[gnu::always_inline]] static void load(V& out, const TriangleGroup* const (&groups)[G], int c, int a) {
    v4 row[G];
    for (int k = 0; k < G; ++k) __builtin_memcpy(&row[k], groups[k]->corner[c][a], sizeof(v4));
    if constexpr (G == 1) {
      out = row[0];
    } else {
      out = __builtin_shufflevector(row[0], row[1], 0, 1, 2, 3, 4, 5, 6, 7);
    }
  }
  template <typename M>
  [[gnu::always_inline]] static int movemask(const M& m) {
    constexpr int n = int(sizeof(M) / 4);
#if defined(__SSE__)
    if constexpr (n == 4) return _mm_movemask_ps(reinterpret_cast<__m128>(m));
#endif
#if defined(__x86_64__) && defined(__GNUC__)
    if constexpr (n == 8) return movemask_avx(m);
#endif
    int bits = 0;
    for (int i = 0; i < n; ++i) bits |= (m[i] & 1) << i;
    return bits;
  }
#if defined(__x86_64__) && defined(__GNUC__)
  // One instruction; inlined into the AVX kernels that use N = 8 (their flatten).
  __attribute__((target("avx"))) static int movemask_avx(const lane_mask<8>& m) {
    __m256 r;
    __builtin_memcpy(&r, &m, sizeof r);
    return _mm256_movemask_ps(r);
  }
#endif
  static Vec3f corner(const TriangleGroup& g, int k, int lane) {
    return {g.corner[k][0][lane], g.corner[k][1][lane], g.corner[k][2][lane]};
  }

  RayTriangleTest<float> scalar_;
  int axis_[3];
  vf origin_[3];  // origin coordinate along kx, ky, kz
  vf shear_x_, shear_y_, shear_z_;
};
#pragma GCC diagnostic pop

using RayTriangle4Test = RayTriangleGroupTest<4>;
using RayTriangle8Test = RayTriangleGroupTest<8>;

}  // namespace geods::bvh
