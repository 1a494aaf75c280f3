// The packet traversal of TriangleBvh (ray_packet.hpp): up to 8 or 16 rays
// through the wide AABB layout together, on the one depth-first loop of
// traversal.hpp; one kernel over the packet's lanes (P) and the node's (W).
// Compiled once more for AVX, AVX2 and AVX-512 and chosen at run time by
// simd_level() (core/simd_level.hpp), like the single-ray traversal; this
// file is compiled with -ffp-contract=off, so every level does the same IEEE
// operations as the portable code and as the single-ray traversal.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <type_traits>

#include "geods/bvh/traversal.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/simd_level.hpp"

#if defined(__SSE__)
#include <xmmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define GEODS_PACKET_SIMD_DISPATCH 1
#endif

namespace geods::bvh {

namespace {

// N-wide vectors: over the rays of a packet (P = 8, 16) or the children of a node (W = 4, 8).
template <int N>
struct Lanes {
  typedef float vf __attribute__((vector_size(4 * N)));
  typedef std::int32_t vi __attribute__((vector_size(4 * N)));
};

#if defined(GEODS_PACKET_SIMD_DISPATCH)
// One movemask per register; inlined only into the AVX (AVX-512) kernels (their flatten).
__attribute__((target("avx"))) inline unsigned lane_bits_avx(Lanes<8>::vi m) {
  return unsigned(_mm256_movemask_ps(reinterpret_cast<__m256>(m)));
}
__attribute__((target("avx512f,avx512dq"))) inline unsigned lane_bits_avx512(Lanes<16>::vi m) {
  return unsigned(_mm512_movepi32_mask(reinterpret_cast<__m512i>(m)));
}
#endif

// Bit i set where lane i of a comparison result is true (L: the kernel's level).
template <SimdLevel L, typename M>
GEODS_BVH_INLINE unsigned lane_bits(M m) {
  constexpr int n = int(sizeof(M) / 4);
#if defined(GEODS_PACKET_SIMD_DISPATCH)
  if constexpr (n == 16 && L == SimdLevel::avx512) {
    return lane_bits_avx512(m);
  } else if constexpr (n >= 8 && L != SimdLevel::portable) {
    Lanes<8>::vi half[n / 8];
    std::memcpy(half, &m, sizeof half);
    unsigned bits = 0;
    for (int h = 0; h < n / 8; ++h) bits |= lane_bits_avx(half[h]) << 8 * h;
    return bits;
  }
#endif
#if defined(__SSE__)
  __m128 quarter[n / 4];
  std::memcpy(quarter, &m, sizeof quarter);
  unsigned bits = 0;
  for (int q = 0; q < n / 4; ++q) bits |= unsigned(_mm_movemask_ps(quarter[q])) << 4 * q;
  return bits;
#else
  unsigned bits = 0;
  for (int i = 0; i < n; ++i) bits |= unsigned(m[i] & 1) << i;
  return bits;
#endif
}

#if defined(GEODS_PACKET_SIMD_DISPATCH)
template <int Predicate>
__attribute__((target("avx512f"))) inline unsigned compare_bits_avx512(Lanes<16>::vf a, Lanes<16>::vf b) {
  return _mm512_cmp_ps_mask(reinterpret_cast<__m512>(a), reinterpret_cast<__m512>(b), Predicate);
}
#endif

// lane_bits of a < b, a <= b or a == b; 16 lanes with AVX-512 compare straight
// into a mask register (GCC turns the comparison into a vector and back).
enum class Cmp { lt, le, eq };
template <SimdLevel L, Cmp C, typename V>
GEODS_BVH_INLINE unsigned compare_bits(V a, V b) {
#if defined(GEODS_PACKET_SIMD_DISPATCH)
  if constexpr (sizeof(V) == 64 && L == SimdLevel::avx512)
    return compare_bits_avx512<C == Cmp::lt ? _CMP_LT_OS : C == Cmp::le ? _CMP_LE_OS : _CMP_EQ_OQ>(a, b);
#endif
  if constexpr (C == Cmp::lt) return lane_bits<L>(a < b);
  if constexpr (C == Cmp::le) return lane_bits<L>(a <= b);
  return lane_bits<L>(a == b);
}

// (A shuffle of lane 0 compiles to one broadcast; an initializer list or a
// lane-by-lane loop to inserts, vector + scalar to an addition of zero too.)
template <int N>
GEODS_BVH_INLINE typename Lanes<N>::vf splat(float x) {
  const typename Lanes<N>::vf v = {x};
  if constexpr (N == 16) {
    return __builtin_shufflevector(v, v, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
  } else if constexpr (N == 8) {
    return __builtin_shufflevector(v, v, 0, 0, 0, 0, 0, 0, 0, 0);
  } else {
    static_assert(N == 4);
    return __builtin_shufflevector(v, v, 0, 0, 0, 0);
  }
}

// Lane i's bit of `bits` as a vector mask (all ones where set).
template <int N>
GEODS_BVH_INLINE typename Lanes<N>::vi lane_mask(std::uint32_t bits) {
  typename Lanes<N>::vi one;
  for (int i = 0; i < N; ++i) one[i] = 1 << i;
  return ((typename Lanes<N>::vi{} + std::int32_t(bits)) & one) != 0;
}

// The least (greatest) lane of x.
template <typename V>
GEODS_BVH_INLINE float lane_min(V x) {
  if constexpr (sizeof(V) == 64) {
    const auto lo = __builtin_shufflevector(x, x, 0, 1, 2, 3, 4, 5, 6, 7);
    const auto hi = __builtin_shufflevector(x, x, 8, 9, 10, 11, 12, 13, 14, 15);
    return lane_min(lo < hi ? lo : hi);
  } else {
    static_assert(sizeof(V) == 32);
    x = x < __builtin_shufflevector(x, x, 4, 5, 6, 7, 0, 1, 2, 3) ? x : __builtin_shufflevector(x, x, 4, 5, 6, 7, 0, 1, 2, 3);
    x = x < __builtin_shufflevector(x, x, 2, 3, 0, 1, 6, 7, 4, 5) ? x : __builtin_shufflevector(x, x, 2, 3, 0, 1, 6, 7, 4, 5);
    return x[0] < x[1] ? x[0] : x[1];
  }
}
template <typename V>
GEODS_BVH_INLINE float lane_max(V x) {
  return -lane_min(-x);
}

// A child waiting to be visited (an inner WideNode, count 0, or a leaf's
// groups), with the lanes that entered its box and a lower bound of their
// entries into it, the key the children are ordered by.
struct PacketEntry {
  std::uint32_t child, count;
  float key;
  std::uint32_t mask;
};

#if defined(GEODS_PACKET_SIMD_DISPATCH)
// The 16 rays side by side (origin, direction, tmin, tmax: 8 floats a ray):
// the 8 x 8 transpose of AVX (unpack, shuffle, 128-bit lanes) on two halves
// at once, the rows holding rays j and j + 4 (j < 4), 8 + j and 12 + j
// (one gather per attribute cost more than the scalar loads it replaced).
static_assert(sizeof(Ray3f) == 8 * sizeof(float), "a ray is 8 floats");
__attribute__((target("avx512f,avx512dq"))) inline void transpose_rays_avx512(const Ray3f* rays,
                                                                              Lanes<16>::vf (&attr)[8]) {
  using v8 = Lanes<8>::vf;
  using v16 = Lanes<16>::vf;
  v16 row[8], t[8], s[8];
  for (int j = 0; j < 8; ++j) {
    const int lo = j < 4 ? j : j + 4;
    v8 a, b;
    std::memcpy(&a, &rays[lo], sizeof a);
    std::memcpy(&b, &rays[lo + 4], sizeof b);
    row[j] = __builtin_shufflevector(a, b, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  }
  for (int j = 0; j < 8; j += 2) {  // unpacklo, unpackhi
    t[j] = __builtin_shufflevector(row[j], row[j + 1], 0, 16, 1, 17, 4, 20, 5, 21, 8, 24, 9, 25, 12, 28, 13, 29);
    t[j + 1] = __builtin_shufflevector(row[j], row[j + 1], 2, 18, 3, 19, 6, 22, 7, 23, 10, 26, 11, 27, 14, 30, 15, 31);
  }
  for (int j = 0; j < 8; j += 4) {  // shuffle 0x44, 0xee
    for (int h = 0; h < 2; ++h) {
      s[j + 2 * h] = __builtin_shufflevector(t[j + h], t[j + h + 2], 0, 1, 16, 17, 4, 5, 20, 21, 8, 9, 24, 25, 12, 13, 28, 29);
      s[j + 2 * h + 1] = __builtin_shufflevector(t[j + h], t[j + h + 2], 2, 3, 18, 19, 6, 7, 22, 23, 10, 11, 26, 27, 14, 15, 30, 31);
    }
  }
  for (int a = 0; a < 4; ++a) {  // 128-bit lanes 0, 2 and 1, 3 of each
    attr[a] = __builtin_shufflevector(s[a], s[a + 4], 0, 1, 2, 3, 8, 9, 10, 11, 16, 17, 18, 19, 24, 25, 26, 27);
    attr[a + 4] = __builtin_shufflevector(s[a], s[a + 4], 4, 5, 6, 7, 12, 13, 14, 15, 20, 21, 22, 23, 28, 29, 30, 31);
  }
}
#endif

// The traversal of the active lanes of `packet`; `any`: occlusion (a lane
// stops at its first hit). The caller shoots the lanes in `alone` alone:
// rays the packet does not take (a non-finite or zero direction, a
// non-finite origin, a NaN interval; a single ray left), and rays that found
// two different triangles at their closest t.
template <int W, int P, SimdLevel L>
GEODS_BVH_INLINE void packet_traverse(const FlatArray<WideNode<W>>& nodes, const FlatArray<TriangleGroup>& groups,
                                      int depth, const RayPacketN<P>& packet, std::uint32_t active, bool any,
                                      HitPacketN<P>& out, std::uint32_t& done, std::uint32_t& alone) {
  using vf = typename Lanes<P>::vf;
  using vi = typename Lanes<P>::vi;
  // The rays side by side.
  vf org[3], dir[3], tmin_v;
  vf hit_t;  // the closest hit so far (ray.tmax before one): the lane's tmax
#if defined(GEODS_PACKET_SIMD_DISPATCH)
  if constexpr (P == 16 && L == SimdLevel::avx512) {
    vf attr[8];
    transpose_rays_avx512(packet.rays, attr);
    for (int a = 0; a < 3; ++a) org[a] = attr[a], dir[a] = attr[3 + a];
    tmin_v = attr[6];
    hit_t = attr[7];
  } else
#endif
  {
    for (int i = 0; i < P; ++i) {
      const Ray3f& r = packet.rays[i];
      for (int a = 0; a < 3; ++a) org[a][i] = r.origin[a], dir[a][i] = r.direction[a];
      tmin_v[i] = r.tmin;
      hit_t[i] = r.tmax;
    }
  }
  {
    // x - x is 0 for finite x, NaN for inf and NaN: one sum tests all six coordinates.
    vf finite = splat<P>(0.0f);
    for (int a = 0; a < 3; ++a) finite += (org[a] - org[a]) + (dir[a] - dir[a]);
    const vf zero = splat<P>(0.0f);
    const auto eq = [](vf a, vf b) GEODS_BVH_INLINE_LAMBDA { return compare_bits<L, Cmp::eq>(a, b); };
    const std::uint32_t zero_dir = eq(dir[0], zero) & eq(dir[1], zero) & eq(dir[2], zero);
    const std::uint32_t taken = active & eq(finite, zero) & ~zero_dir & eq(tmin_v, tmin_v) & eq(hit_t, hit_t);
    alone |= active & ~taken;
    active = taken;
  }
  if (__builtin_popcount(active) < 2) {  // one ray is cheaper alone
    alone |= active;
    return;
  }
  // Lanes not shot repeat the first active ray.
  for (std::uint32_t b = ~active & ((1u << P) - 1); b != 0; b &= b - 1) {
    const int i = __builtin_ctz(b), first = __builtin_ctz(active);
    for (int a = 0; a < 3; ++a) org[a][i] = org[a][first], dir[a][i] = dir[a][first];
    tmin_v[i] = tmin_v[first];
    hit_t[i] = hit_t[first];
  }
  vf inv[3];
  vi neg[3];
  for (int a = 0; a < 3; ++a) {
    inv[a] = splat<P>(1.0f) / dir[a];
    neg[a] = inv[a] < splat<P>(0.0f);
  }
  vi hit_prim = vi{} - 1;  // RayHit::no_hit
  vf hit_u = splat<P>(0.0f), hit_v = splat<P>(0.0f);
  // The watertight test's axes (RayTriangleTest): the largest direction
  // component is z, x and y follow it, swapped for a negative z. When every
  // lane has the same axes (coherent packets), a leaf tests each triangle
  // against all lanes at once; else each lane tests groups of 4 (RayTriangle4Test).
  vf adir[3];
  for (int a = 0; a < 3; ++a) adir[a] = dir[a] < splat<P>(0.0f) ? -dir[a] : dir[a];
  // (Comparisons are combined as bit masks: GCC scalarizes & and | of
  // 16-lane comparisons inlined into AVX-512 code.)
  const vi z1 = adir[1] > adir[0];
  const unsigned z1_bits = lane_bits<L>(z1), z2_bits = lane_bits<L>(adir[2] > (z1 ? adir[1] : adir[0]));
  const unsigned kz_bits[2] = {z1_bits & ~z2_bits & active, z2_bits & active};
  unsigned negative[3];
  for (int a = 0; a < 3; ++a) negative[a] = lane_bits<L>(dir[a] < splat<P>(0.0f));
  const unsigned negz =
      ((negative[2] & z2_bits) | (negative[1] & z1_bits & ~z2_bits) | (negative[0] & ~z1_bits & ~z2_bits)) & active;
  const bool same_axes = (kz_bits[0] == 0 || kz_bits[0] == active) && (kz_bits[1] == 0 || kz_bits[1] == active) &&
                         (negz == 0 || negz == active);
  int kz = kz_bits[1] ? 2 : kz_bits[0] ? 1 : 0, kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (negz) std::swap(kx, ky);
  const vf sh_x = dir[kx] / dir[kz], sh_y = dir[ky] / dir[kz], sh_z = splat<P>(1.0f) / dir[kz];
  alignas(64) unsigned char test_storage[P][sizeof(RayTriangle4Test)];
  RayTriangle4Test* tests = reinterpret_cast<RayTriangle4Test*>(test_storage);
  std::uint32_t built = 0;  // lanes whose tests[] is set up (on first use)
  // The packet's bounds for the frustum test (interval arithmetic over the
  // lanes): per axis the range of the origins and of the inverse directions,
  // used where every lane's inverse direction is finite and of the same sign;
  // there the near and far bound rows of a node are the same for every lane.
  const vf inf = splat<P>(std::numeric_limits<float>::infinity());
  const vi active_v = lane_mask<P>(active);
  using vw = typename Lanes<W>::vf;
  bool one_sign[3], in_frustum[3];
  int near_row[3], far_row[3];
  vw near_o[3], far_o[3], i_lo[3], i_hi[3];
  for (int a = 0; a < 3; ++a) {
    const float o_lo = lane_min(org[a]), o_hi = lane_max(org[a]), inv_lo = lane_min(inv[a]), inv_hi = lane_max(inv[a]);
    const unsigned negatives = lane_bits<L>(neg[a]) & active;
    one_sign[a] = negatives == 0 || negatives == active;
    in_frustum[a] = one_sign[a] && std::isfinite(inv_lo) && std::isfinite(inv_hi);
    const bool positive = negatives == 0;
    near_row[a] = positive ? 2 * a : 2 * a + 1;  // entering at lo - origin: least at the largest origin
    far_row[a] = positive ? 2 * a + 1 : 2 * a;
    near_o[a] = splat<W>(positive ? o_hi : o_lo);
    far_o[a] = splat<W>(positive ? o_lo : o_hi);
    i_lo[a] = splat<W>(inv_lo), i_hi[a] = splat<W>(inv_hi);
  }
  const bool full_frustum = in_frustum[0] && in_frustum[1] && in_frustum[2];  // its entry distances are the keys
  const float tmin_lo = lane_min(tmin_v);
  // The greatest tmax of the lanes still running: the frustum's far end.
  float tmax_hi = lane_max(active_v ? hit_t : -inf);
  TraversalStack<PacketEntry> stack(traversal_stack_size(depth, W));
  // An exit distance tf widened by kRayBoxSlack: scaled by 1 + kRayBoxSlack
  // where no lane starts behind its origin (tmin >= 0: a box whose scaled,
  // so narrowed, negative exit is missed holds no hit then), else
  // tf + |tf| kRayBoxSlack, as the single ray's may_hit_before.
  const bool scaled_widening = tmin_lo >= 0;
  auto widen_exit = [&](auto tf) GEODS_BVH_INLINE_LAMBDA {
    if (scaled_widening) [[likely]]
      return tf * splat<sizeof(tf) / sizeof(float)>(1.0f + kRayBoxSlack);
    return widen_far(tf);
  };
  // The lanes of entry e that may still hit something in it: the nearest
  // entry into its box is no later than their tmax allows (may_hit_before
  // of the single ray). Lanes that entered later are dropped by the tests below it.
  auto live = [&](const PacketEntry& e) GEODS_BVH_INLINE_LAMBDA {
    return e.mask & ~done & compare_bits<L, Cmp::le>(splat<P>(e.key), widen_far(hit_t));
  };
  // The children that some lane may enter, all W at once: a lane's entry
  // and exit distances along an axis are products of (bound - origin) and the
  // inverse direction, and rounding is monotone, so the extreme products of
  // the packet's ranges bound every lane's (finite inverses: no NaN). A child
  // this rejects, every lane's own slab test rejects too.
  auto frustum = [&](const WideNode<W>& node, float* near_out) GEODS_BVH_INLINE_LAMBDA {
    vw tn = splat<W>(tmin_lo), tf = splat<W>(tmax_hi);
    for (int a = 0; a < 3; ++a) {
      if (!in_frustum[a]) continue;
      vw n, f;
      std::memcpy(&n, node.bounds[near_row[a]], sizeof n);
      std::memcpy(&f, node.bounds[far_row[a]], sizeof f);
      n -= near_o[a];
      f -= far_o[a];
      const vw near_lo = n * i_lo[a], near_hi = n * i_hi[a], far_lo = f * i_lo[a], far_hi = f * i_hi[a];
      const vw near = near_lo < near_hi ? near_lo : near_hi, far = far_lo > far_hi ? far_lo : far_hi;
      tn = near > tn ? near : tn;
      tf = far < tf ? far : tf;
    }
    std::memcpy(near_out, &tn, sizeof tn);
    return lane_bits<L>(tn <= widen_exit(tf));
  };
  // Per child of the node being opened: the lanes that enter it. With all
  // three axes in the frustum, its entry distance (a lower bound of every
  // lane's) is the child's key; else the lanes' nearest entry.
  std::uint32_t child_mask[W];
  auto children = [&](const PacketEntry& e, float* keys) GEODS_BVH_INLINE_LAMBDA {
    const std::uint32_t lanes = e.mask & ~done;
    const WideNode<W>& node = nodes[e.child];
    unsigned candidates = frustum(node, keys);
    unsigned bits = 0;
    for (; candidates != 0; candidates &= candidates - 1) {
      const int c = __builtin_ctz(candidates);
      if (node.count[c] == 0 && node.child[c] == WideNode<W>::kEmpty) continue;
      vf tn = tmin_v, tf = hit_t;
      for (int a = 0; a < 3; ++a) {
        // The single ray's slab test, lane by lane: the near bound by the
        // sign of the inverse direction (one row for all lanes where they
        // share it, else a blend), NaNs (0 * inf) leave the interval.
        vf near, far;
        if (one_sign[a]) {
          near = (splat<P>(node.bounds[near_row[a]][c]) - org[a]) * inv[a];
          far = (splat<P>(node.bounds[far_row[a]][c]) - org[a]) * inv[a];
        } else {
          const vf t_lo = (splat<P>(node.bounds[2 * a][c]) - org[a]) * inv[a];
          const vf t_hi = (splat<P>(node.bounds[2 * a + 1][c]) - org[a]) * inv[a];
          near = neg[a] ? t_hi : t_lo;
          far = neg[a] ? t_lo : t_hi;
        }
        tn = near > tn ? near : tn;
        tf = far < tf ? far : tf;
      }
      const std::uint32_t m = lanes & compare_bits<L, Cmp::le>(tn, widen_exit(tf));
      if (m == 0) continue;
      child_mask[c] = m;
      if (!full_frustum) keys[c] = lane_min(lane_mask<P>(m) ? tn : inf);
      bits |= 1u << c;
    }
    return bits;
  };
  auto child = [&](const PacketEntry& e, int c, float key) GEODS_BVH_INLINE_LAMBDA {
    const WideNode<W>& node = nodes[e.child];
    const PacketEntry r{node.child[c], node.count[c], key, child_mask[c]};
    if (r.count == 0) {
      const char* p = reinterpret_cast<const char*>(&nodes[r.child]);
      for (std::size_t k = 0; k < sizeof(WideNode<W>); k += 64) __builtin_prefetch(p + k);
    } else {
      const char* p = reinterpret_cast<const char*>(&groups[r.child]);
      for (std::size_t k = 0; k < sizeof(TriangleGroup) * r.count; k += 64) __builtin_prefetch(p + k);
    }
    return r;
  };
  // A hit of the lanes in `hits` at t (at or before their tmax): their
  // closest so far; a second triangle at a lane's closest t makes it
  // ambiguous (shot again alone), a closer one clears that.
  auto record = [&](std::uint32_t hits, vf t, vi prim, vf u, vf v) GEODS_BVH_INLINE_LAMBDA {
    const vi m = lane_mask<P>(hits);
    const std::uint32_t had = hits & lane_bits<L>(hit_prim != (vi{} - 1));
    alone &= ~(had & compare_bits<L, Cmp::lt>(t, hit_t));
    alone |= had & compare_bits<L, Cmp::eq>(t, hit_t) & lane_bits<L>(prim != hit_prim);
    hit_t = m ? t : hit_t;
    hit_prim = m ? prim : hit_prim;
    hit_u = m ? u : hit_u;
    hit_v = m ? v : hit_v;
    if (any) done |= hits;
  };
  // Every lane sheared along the same axes: one triangle against all lanes
  // at once, each lane doing the scalar test's operations in its order. The
  // edge tests' masks: 8 lanes combine vector masks (one movemask), 16 lanes
  // bit masks (GCC scalarizes & and | of 16-lane comparisons in AVX-512 code).
  const auto edge_bits = [](vi m) GEODS_BVH_INLINE_LAMBDA { return lane_bits<L>(m); };
  using EdgeMask = std::conditional_t<P == 16, decltype(edge_bits), SameMask>;
  const auto bits_of = [](auto m) GEODS_BVH_INLINE_LAMBDA {
    if constexpr (std::is_same_v<decltype(m), vi>) {
      return lane_bits<L>(m);
    } else {
      return m;
    }
  };
  auto leaf_rays = [&](const PacketEntry& e, std::uint32_t lanes) GEODS_BVH_INLINE_LAMBDA {
    const vf ox = org[kx], oy = org[ky], oz = org[kz];
    for (std::uint32_t g = e.child; g < e.child + e.count && lanes != 0; ++g) {
      const TriangleGroup& group = groups[g];
      for (int k = 0; k < 4 && lanes != 0; ++k) {
        if (k > 0 && group.index[k] == group.index[k - 1]) break;  // unused lanes repeat the last triangle
        vf px[3], py[3], pz[3];
        for (int c = 0; c < 3; ++c) {
          pz[c] = splat<P>(group.corner[c][kz][k]) - oz;
          px[c] = (splat<P>(group.corner[c][kx][k]) - ox) - sh_x * pz[c];
          py[c] = (splat<P>(group.corner[c][ky][k]) - oy) - sh_y * pz[c];
        }
        const auto ed = sheared_edges(px, py, EdgeMask{});
        const std::uint32_t edge = bits_of(ed.on_edge) & lanes;
        if ((bits_of(ed.inside) & lanes) == 0 && edge == 0) continue;
        const vf scaled_t = ed.eu * (sh_z * pz[0]) + ed.ev * (sh_z * pz[1]) + ed.ew * (sh_z * pz[2]);
        const vf inv_det = splat<P>(1.0f) / ed.det;
        vf t = scaled_t * inv_det, u = ed.ev * inv_det, v = ed.ew * inv_det;
        std::uint32_t hits;
        if constexpr (P == 16) {
          hits = ed.inside & compare_bits<L, Cmp::le>(tmin_v, t) & compare_bits<L, Cmp::le>(t, hit_t) & lanes;
        } else {
          hits = lane_bits<L>(ed.inside & (t >= tmin_v) & (t <= hit_t)) & lanes;
        }
        for (std::uint32_t b = edge; b != 0; b &= b - 1) {  // the scalar test's double-precision path
          const int i = __builtin_ctz(b);
          const Vec3f a(group.corner[0][0][k], group.corner[0][1][k], group.corner[0][2][k]);
          const Vec3f bb(group.corner[1][0][k], group.corner[1][1][k], group.corner[1][2][k]);
          const Vec3f cc(group.corner[2][0][k], group.corner[2][1][k], group.corner[2][2][k]);
          float ht, hu, hv;
          if (RayTriangleTest<float>(packet.rays[i]).intersect(a, bb, cc, tmin_v[i], hit_t[i], ht, hu, hv)) {
            t[i] = ht, u[i] = hu, v[i] = hv;
            hits |= 1u << i;
          }
        }
        if (hits == 0) continue;
        record(hits, t, vi{} + std::int32_t(group.index[k]), u, v);
        lanes &= ~done;
      }
    }
  };
  // Otherwise each lane tests the groups 4 triangles at a time.
  auto leaf_lanes = [&](const PacketEntry& e, std::uint32_t lanes) GEODS_BVH_INLINE_LAMBDA {
    for (std::uint32_t b = lanes & ~built; b != 0; b &= b - 1) new (&tests[__builtin_ctz(b)]) RayTriangle4Test(packet.rays[__builtin_ctz(b)]);
    built |= lanes;
    for (std::uint32_t g = e.child; g < e.child + e.count && lanes != 0; ++g) {
      const TriangleGroup& group = groups[g];
      for (std::uint32_t b = lanes; b != 0; b &= b - 1) {
        const int i = __builtin_ctz(b);
        RayTriangle4Test::vf t, u, v;
        const int mask = tests[i].intersect(group, tmin_v[i], hit_t[i], t, u, v);
        if (mask == 0) continue;
        // The group's nearest lane, ties to the last one, as the single ray keeps it.
        int best = -1;
        for (int k = 0; k < 4; ++k)
          if ((mask >> k & 1) && (best < 0 || t[k] <= t[best])) best = k;
        const std::uint32_t prim = group.index[best];
        bool tie = false;
        for (int k = 0; k < 4; ++k) tie |= (mask >> k & 1) && t[k] == t[best] && group.index[k] != prim;
        record(1u << i, splat<P>(t[best]), vi{} + std::int32_t(prim), splat<P>(u[best]), splat<P>(v[best]));
        if (tie) alone |= 1u << i;
      }
      lanes &= ~done;
    }
  };
  auto leaf = [&](const PacketEntry& e) GEODS_BVH_INLINE_LAMBDA {
    const std::uint32_t lanes = live(e);
    if (lanes == 0) return true;
    // With AVX a triangle against all lanes costs about what a group of 4
    // costs one lane: with fewer than 3 lanes in the leaf, each lane tests
    // the groups (16 lanes too: 2 and 6 measured no faster). Without AVX
    // the 8 lanes take two 4-wide operations, and each lane tests the groups
    // (portable 100k closest: 0.17-0.19 s of CPU against 0.21-0.26 s).
    if (L != SimdLevel::portable && same_axes && __builtin_popcount(lanes) >= 3) {
      leaf_rays(e, lanes);
    } else {
      leaf_lanes(e, lanes);
    }
    tmax_hi = lane_max(lane_mask<P>(active & ~done) ? hit_t : -inf);
    return (active & ~done) != 0;
  };
  const auto is_leaf = [](const PacketEntry& e) GEODS_BVH_INLINE_LAMBDA { return e.count != 0; };
  const auto still_needed = [&](const PacketEntry& e) GEODS_BVH_INLINE_LAMBDA { return live(e) != 0; };
  const PacketEntry root{0, 0, tmin_lo, active};
  if (any) {
    traverse<W, false>(root, stack, is_leaf, children, child, leaf, still_needed);
  } else {
    traverse<W, true>(root, stack, is_leaf, children, child, leaf, still_needed);
  }
  for (std::uint32_t b = active & lane_bits<L>(hit_prim != (vi{} - 1)); b != 0; b &= b - 1) {
    const int i = __builtin_ctz(b);
    out.hits[i] = {hit_t[i], std::uint32_t(hit_prim[i]), hit_u[i], hit_v[i]};
  }
}

// The kernel at each level (ray_packet.hpp: where the CPU runs no AVX-512, a
// packet of 16 is traced as two of 8).
template <int W, int P>
void packet_portable(const FlatArray<WideNode<W>>& nodes, const FlatArray<TriangleGroup>& groups, int depth,
    const RayPacketN<P>& packet, std::uint32_t active, bool any, HitPacketN<P>& out, std::uint32_t& done,
    std::uint32_t& alone) {
  packet_traverse<W, P, SimdLevel::portable>(nodes, groups, depth, packet, active, any, out, done, alone);
}

#if defined(GEODS_PACKET_SIMD_DISPATCH)
template <int W, int P>
__attribute__((target("avx"), flatten)) void packet_avx(
    const FlatArray<WideNode<W>>& nodes, const FlatArray<TriangleGroup>& groups, int depth,
    const RayPacketN<P>& packet, std::uint32_t active, bool any, HitPacketN<P>& out, std::uint32_t& done,
    std::uint32_t& alone) {
  packet_traverse<W, P, SimdLevel::avx>(nodes, groups, depth, packet, active, any, out, done, alone);
}
template <int W, int P>
__attribute__((target("avx2,bmi,bmi2,lzcnt,popcnt"), flatten)) void packet_avx2(
    const FlatArray<WideNode<W>>& nodes, const FlatArray<TriangleGroup>& groups, int depth,
    const RayPacketN<P>& packet, std::uint32_t active, bool any, HitPacketN<P>& out, std::uint32_t& done,
    std::uint32_t& alone) {
  packet_traverse<W, P, SimdLevel::avx2>(nodes, groups, depth, packet, active, any, out, done, alone);
}
template <int W, int P>
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2,lzcnt,popcnt"), flatten)) void packet_avx512(
    const FlatArray<WideNode<W>>& nodes, const FlatArray<TriangleGroup>& groups, int depth,
    const RayPacketN<P>& packet, std::uint32_t active, bool any, HitPacketN<P>& out, std::uint32_t& done,
    std::uint32_t& alone) {
  packet_traverse<W, P, SimdLevel::avx512>(nodes, groups, depth, packet, active, any, out, done, alone);
}
#endif

template <int W, int P>
void packet_best(const FlatArray<WideNode<W>>& nodes, const FlatArray<TriangleGroup>& groups, int depth,
    const RayPacketN<P>& packet, std::uint32_t active, bool any, HitPacketN<P>& out, std::uint32_t& done,
    std::uint32_t& alone) {
#if defined(GEODS_PACKET_SIMD_DISPATCH)
  if constexpr (P == 16) {  // only with AVX-512 (sixteen_wide)
    packet_avx512<W, P>(nodes, groups, depth, packet, active, any, out, done, alone);
  } else {
    switch (simd_level()) {
      case SimdLevel::avx512: return packet_avx512<W, P>(nodes, groups, depth, packet, active, any, out, done, alone);
      case SimdLevel::avx2: return packet_avx2<W, P>(nodes, groups, depth, packet, active, any, out, done, alone);
      case SimdLevel::avx: return packet_avx<W, P>(nodes, groups, depth, packet, active, any, out, done, alone);
      case SimdLevel::portable: break;
    }
    packet_portable<W, P>(nodes, groups, depth, packet, active, any, out, done, alone);
  }
#else
  packet_portable<W, P>(nodes, groups, depth, packet, active, any, out, done, alone);
#endif
}

// The lanes the packet traversal leaves to the single-ray query: all of them
// without a wide layout.
template <int P>
std::uint32_t trace_packet(const TriangleBvh& bvh, const RayPacketN<P>& packet, bool any, HitPacketN<P>& out,
                           std::uint32_t& done) {
  const std::uint32_t active = packet.active & ((1u << P) - 1);
  std::uint32_t alone = 0;
  if (!bvh.wide8_nodes().empty()) {
    packet_best<8, P>(bvh.wide8_nodes(), bvh.triangle_groups(), bvh.depth(), packet, active, any, out, done, alone);
  } else if (!bvh.wide4_nodes().empty()) {
    packet_best<4, P>(bvh.wide4_nodes(), bvh.triangle_groups(), bvh.depth(), packet, active, any, out, done, alone);
  } else {
    alone = active;
  }
  return alone;
}

template <int P>
HitPacketN<P> intersect_packet(const TriangleBvh& bvh, const RayPacketN<P>& packet) {
  HitPacketN<P> out;
  std::uint32_t done = 0;
  // Also rays with two triangles at their closest t: the single ray's order decides.
  for (std::uint32_t b = trace_packet(bvh, packet, false, out, done); b != 0; b &= b - 1) {
    const int i = __builtin_ctz(b);
    out.hits[i] = bvh.intersect(packet.rays[i]);
  }
  return out;
}

template <int P>
std::uint32_t occluded_packet(const TriangleBvh& bvh, const RayPacketN<P>& packet) {
  HitPacketN<P> out;
  std::uint32_t done = 0;
  const std::uint32_t alone = trace_packet(bvh, packet, true, out, done) & ~done;
  for (std::uint32_t b = alone; b != 0; b &= b - 1) {
    const int i = __builtin_ctz(b);
    if (bvh.occluded(packet.rays[i])) done |= 1u << i;
  }
  return done;
}

// Packets of 16 where the kernel runs 16 lanes wide (AVX-512), else as two of 8.
bool sixteen_wide() {
#if defined(GEODS_PACKET_SIMD_DISPATCH)
  return simd_level() == SimdLevel::avx512;
#else
  return false;
#endif
}
RayPacket half(const RayPacket16& packet, int h) {
  RayPacket r;
  std::copy_n(packet.rays + 8 * h, 8, r.rays);
  r.active = packet.active >> 8 * h & 0xffu;
  return r;
}

// Every ray in packets of P consecutive ones, the packets in parallel.
template <int P>
void intersect_all(const TriangleBvh& bvh, std::span<const Ray3f> rays, std::span<RayHit> hits) {
  parallel_for_each_index(0, (rays.size() + P - 1) / P, [&](std::size_t p) {
    const std::size_t first = p * P;
    RayPacketN<P> packet;
    const std::size_t n = std::min<std::size_t>(P, rays.size() - first);
    for (std::size_t i = 0; i < n; ++i) packet.rays[i] = rays[first + i];
    packet.active = (1u << n) - 1;
    const HitPacketN<P> out = bvh.intersect(packet);
    for (std::size_t i = 0; i < n; ++i) hits[first + i] = out.hits[i];
  }, 32);
}

template <int P>
void occluded_all(const TriangleBvh& bvh, std::span<const Ray3f> rays, std::span<std::uint8_t> occluded_out) {
  parallel_for_each_index(0, (rays.size() + P - 1) / P, [&](std::size_t p) {
    const std::size_t first = p * P;
    RayPacketN<P> packet;
    const std::size_t n = std::min<std::size_t>(P, rays.size() - first);
    for (std::size_t i = 0; i < n; ++i) packet.rays[i] = rays[first + i];
    packet.active = (1u << n) - 1;
    const std::uint32_t mask = bvh.occluded(packet);
    for (std::size_t i = 0; i < n; ++i) occluded_out[first + i] = std::uint8_t(mask >> i & 1);
  }, 32);
}

void check_packet_size(int packet_size, const char* what) {
  if (packet_size != 8 && packet_size != 16) throw Error(std::string(what) + ": packet_size must be 8 or 16");
}

}  // namespace

HitPacket TriangleBvh::intersect(const RayPacket& packet) const {
  check_rays(packet);
  return intersect_packet(*this, packet);
}

std::uint32_t TriangleBvh::occluded(const RayPacket& packet) const {
  check_rays(packet);
  return occluded_packet(*this, packet);
}

HitPacket16 TriangleBvh::intersect(const RayPacket16& packet) const {
  check_rays(packet);
  if (sixteen_wide()) return intersect_packet(*this, packet);
  HitPacket16 out;
  for (int h = 0; h < 2; ++h) std::copy_n(intersect(half(packet, h)).hits, 8, out.hits + 8 * h);
  return out;
}

std::uint32_t TriangleBvh::occluded(const RayPacket16& packet) const {
  check_rays(packet);
  if (sixteen_wide()) return occluded_packet(*this, packet);
  return occluded(half(packet, 0)) | occluded(half(packet, 1)) << 8;
}

void TriangleBvh::intersect_packets(std::span<const Ray3f> rays, std::span<RayHit> hits, int packet_size) const {
  if (hits.size() != rays.size()) throw Error("TriangleBvh::intersect_packets: one hit per ray expected");
  check_packet_size(packet_size, "TriangleBvh::intersect_packets");
  if (packet_size == 16) {
    intersect_all<16>(*this, rays, hits);
  } else {
    intersect_all<8>(*this, rays, hits);
  }
}

void TriangleBvh::occluded_packets(std::span<const Ray3f> rays, std::span<std::uint8_t> occluded_out,
                                   int packet_size) const {
  if (occluded_out.size() != rays.size()) throw Error("TriangleBvh::occluded_packets: one answer per ray expected");
  check_packet_size(packet_size, "TriangleBvh::occluded_packets");
  if (packet_size == 16) {
    occluded_all<16>(*this, rays, occluded_out);
  } else {
    occluded_all<8>(*this, rays, occluded_out);
  }
}

}  // namespace geods::bvh
