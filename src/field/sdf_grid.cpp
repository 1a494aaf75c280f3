#include "geods/field/sdf_grid.hpp"

#include <unistd.h>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <type_traits>

#include <fmt/format.h>

#include "../core/prefault.hpp"
#include "geods/bvh/traversal.hpp"
#include "geods/core/error.hpp"
#include "geods/core/huge_page_array.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/simd_level.hpp"

namespace geods::field {
namespace {

constexpr std::size_t kTile = 8;   // samples along a tile's side
constexpr std::size_t kBlock = 4;  // samples along a block's side (within a tile)
constexpr std::size_t kBlocks = (kTile / kBlock) * (kTile / kBlock) * (kTile / kBlock);  // per tile
constexpr float kInf = std::numeric_limits<float>::infinity();

using bvh::BvhTriangle;

// A box of samples [lo, hi) of the grid, its 8 corners (sample positions) and centre.
struct SampleBox {
  std::array<std::size_t, 3> lo, hi;
  std::array<Vec3f, 8> corners;
  Vec3f centre;
  float radius;  // half the diagonal

  SampleBox(const Grid3Geometry& grid, std::array<std::size_t, 3> l, std::array<std::size_t, 3> h) : lo(l), hi(h) {
    const Vec3f a = grid.position(lo[0], lo[1], lo[2]), b = grid.position(hi[0] - 1, hi[1] - 1, hi[2] - 1);
    for (int k = 0; k < 8; ++k) corners[k] = Vec3f(k & 1 ? b.x() : a.x(), k & 2 ? b.y() : a.y(), k & 4 ? b.z() : a.z());
    centre = 0.5f * (a + b);
    radius = 0.5f * (b - a).norm();
  }
  std::size_t samples() const { return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
};

// The closest face of a list to a point.
struct Closest {
  float d2 = kInf;
  std::uint32_t leaf = kNoIndex;  // leaf-order index
  std::size_t slot = 0;           // position in the list
  TriangleRegion region = TriangleRegion::face;
  Vec3f point = Vec3f::Zero();
};

// Triangles prepared for squared distances to many points, one array per
// quantity (structure of arrays) so that the loop over them vectorizes: the
// corner a, the edges ab and ac, the unit normal n, the terms of the
// projection's barycentric coordinates, the reciprocal squared lengths (0 for a
// degenerate edge, which then never claims a point) and has_face (1, or 0 for a
// degenerate face). (A unit normal: the plane distance squared as (n . q)^2 /
// |n|^2 with the cross product n, of degree 6 in the coordinates, overflowed
// from differences of about 2^21 and underflowed below about 2^-21.)
struct Packed {
  // k0..k7: in a block's list, the squared distances from the block's 8 corners.
  enum Field { ax, ay, az, bx, by, bz, cx, cy, cz, nx, ny, nz, d00, d01, d11, inv_den, has_face, inv_ab, inv_ac, inv_bc,
               k0, k1, k2, k3, k4, k5, k6, k7, kFields };
  using Arrays = std::array<std::vector<float>, kFields>;
  Arrays f;
  std::vector<std::uint32_t> leaf;  // leaf-order triangle of each entry
  std::vector<std::int32_t> face;   // its face index (padded as the arrays)
  std::vector<float> floor;         // a block's list: per group of 8, a bound below every distance in the block
  std::size_t size = 0;

  void clear() { size = 0; }
  // Room for n entries, rounded up to whole vectors (the tail is never read as a result).
  void reserve(std::size_t n) {
    const std::size_t padded = (n + 15) & ~std::size_t(15);
    if (f[0].size() < padded) {
      for (auto& a : f) a.resize(padded, 0.0f);
      face.resize(padded, 0);
      leaf.resize(padded, 0);
    }
  }
};

// d2[i] = squared distance from p to entry i of t, for i < t.size rounded up
// to 16: the face's plane distance where p projects inside it, else the
// nearest of the three edges. Eight entries at a time, without branches
// (GCC vector extensions: AVX2 where the CPU has it, picked at run time,
// else two SSE halves).
using V8 = float __attribute__((vector_size(32)));

__attribute__((always_inline)) inline V8 load8(const float* p) {
  V8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// The same into v: for the target_clones functions' own loops, where clang
// refuses a vector returned by value in the default (no AVX) clone.
__attribute__((always_inline)) inline void load8(const float* p, V8& v) { std::memcpy(&v, p, sizeof v); }

// Entries [i, i + 8) of t.
// Vectors by reference in and out: passed or returned by value in the default
// (no AVX) clone they change the ABI, which clang refuses.
__attribute__((always_inline)) inline void distance8(const Packed::Arrays& f, std::size_t i, const V8& px, const V8& py,
                                                    const V8& pz, V8& out) {
  const V8 zero = V8{}, one = V8{} + 1.0f;
  const auto clamp01 = [&](const V8& t) {
    const V8 s = t < zero ? zero : t;
    return s > one ? one : s;
  };
  const auto at = [&](int k) { return load8(f[k].data() + i); };
  const V8 bx = at(Packed::bx), by = at(Packed::by), bz = at(Packed::bz);
  const V8 cx = at(Packed::cx), cy = at(Packed::cy), cz = at(Packed::cz);
  const V8 qx = px - at(Packed::ax), qy = py - at(Packed::ay), qz = pz - at(Packed::az);  // p - a
  const V8 e1 = bx * qx + by * qy + bz * qz;  // ab . (p - a)
  const V8 e2 = cx * qx + cy * qy + cz * qz;  // ac . (p - a)
  const V8 d01 = at(Packed::d01), inv_den = at(Packed::inv_den), has_face = at(Packed::has_face);
  const V8 v = (at(Packed::d11) * e1 - d01 * e2) * inv_den;
  const V8 w = (at(Packed::d00) * e2 - d01 * e1) * inv_den;
  const V8 h = at(Packed::nx) * qx + at(Packed::ny) * qy + at(Packed::nz) * qz;
  const V8 face = h * h;
  const auto inside = (v >= zero) & (w >= zero) & (v + w <= one) & (has_face > zero);
  // Edge ab from a, edge ac from a, edge bc from b.
  V8 s = clamp01(e1 * at(Packed::inv_ab));
  V8 rx = qx - s * bx, ry = qy - s * by, rz = qz - s * bz;
  const V8 dab = rx * rx + ry * ry + rz * rz;
  s = clamp01(e2 * at(Packed::inv_ac));
  rx = qx - s * cx, ry = qy - s * cy, rz = qz - s * cz;
  const V8 dac = rx * rx + ry * ry + rz * rz;
  const V8 ux = qx - bx, uy = qy - by, uz = qz - bz;  // p - b
  const V8 wx = cx - bx, wy = cy - by, wz = cz - bz;  // bc
  s = clamp01((ux * wx + uy * wy + uz * wz) * at(Packed::inv_bc));
  rx = ux - s * wx, ry = uy - s * wy, rz = uz - s * wz;
  const V8 dbc = rx * rx + ry * ry + rz * rz;
  V8 edge = dab < dac ? dab : dac;
  edge = dbc < edge ? dbc : edge;
  out = inside ? face : edge;
}

using I8 = std::int32_t __attribute__((vector_size(32)));

// The entries that pass a box's corner test (structure of arrays): their
// positions in the tested list, their squared distances from the 8 corners
// and the smallest of those (key).
struct Kept {
  std::vector<std::uint32_t> index;
  std::vector<float> key;
  std::array<std::vector<float>, 8> k;
  std::size_t size = 0;
  // Empty, with room for n entries and a vector's overhang.
  void reset(std::size_t n) {
    size = 0;
    if (index.size() >= n + 16) return;
    index.resize(n + 16), key.resize(n + 16);
    for (auto& a : k) a.resize(n + 16);
  }
};

// The entries of t within bound2[0][k] of some corner k, appended to `kept`,
// eight entries at a time; with sets > 1, only those that are also within
// bound2[j][k] of some corner k for every j < sets.
__attribute__((target_clones("avx2", "default"))) void corner_test(const Packed& t, const std::array<Vec3f, 8>& corners,
                                                                  const std::array<float, 8>* bound2, int sets,
                                                                  Kept& kept) {
  const I8 size = I8{} + std::int32_t(t.size), lanes = I8{0, 1, 2, 3, 4, 5, 6, 7};
  kept.reset(t.size);
  for (std::size_t i = 0; i < t.size; i += 8) {
    V8 d[8];
    I8 pass = I8{};
    for (int k = 0; k < 8; ++k) {
      distance8(t.f, i, V8{} + corners[k].x(), V8{} + corners[k].y(), V8{} + corners[k].z(), d[k]);
      pass |= d[k] <= bound2[0][k];
    }
    for (int j = 1; j < sets; ++j) {
      I8 also = I8{};
      for (int k = 0; k < 8; ++k) also |= d[k] <= bound2[j][k];
      pass &= also;
    }
    pass &= (lanes + std::int32_t(i)) < size;
    for (int l = 0; l < 8; ++l) {
      if (!pass[l]) continue;
      const std::size_t e = kept.size++;
      kept.index[e] = std::uint32_t(i + std::size_t(l));
      float key = d[0][l];
      for (int k = 0; k < 8; ++k) kept.k[k][e] = d[k][l], key = std::min(key, d[k][l]);
      kept.key[e] = key;
    }
  }
}

// Each block's candidates in a tile's list: their positions (the first
// count[b] of list[b]), or with AVX-512, per 16 entries, the mask of those
// that are (mask[b][i / 16]).
struct Survivors {
  std::array<std::vector<std::uint32_t>, kBlocks> list;
  std::array<std::vector<std::uint16_t>, kBlocks> mask;
  std::array<std::size_t, kBlocks> count{};
  // Empty, with room for n each and a vector's overhang.
  void reset(std::size_t blocks, std::size_t n) {
    for (std::size_t b = 0; b < blocks; ++b) {
      count[b] = 0;
      if (list[b].size() < n + 16) list[b].resize(n + 16), mask[b].resize(n / 16 + 1);
    }
  }
  std::span<const std::uint32_t> operator[](std::size_t b) const { return {list[b].data(), count[b]}; }
};

// The corners of a tile's blocks as a lattice of the tile's box: along
// each axis two positions per block (its first and last samples), their
// trilinear weights in the tile, and at each lattice point the spread of
// the tile's corners about it (rounded up, plus the rounding slack); with
// each block's corners as lattice indices and its squared distance bounds.
struct Lattice {
  std::array<int, 3> n{};                    // positions along each axis (2 per block)
  std::array<std::array<float, 4>, 3> w{};   // their weights
  std::array<float, 64> spread{};            // at lattice point ix + 4 (iy + 4 iz)
  std::size_t blocks = 0;
  std::array<std::array<int, 8>, kBlocks> corner{};
  std::array<std::array<float, 8>, kBlocks> bound2{};
};

// For every entry of t (a tile's list, with its squared distances from the
// tile's corners k0..k7), the blocks where it may pass the corner test:
// by the concavity of dist^2(p, f) - |p|^2, dist^2(c, f) at a block corner
// c is at least the trilinear interpolation of the tile-corner values less
// the spread, so an entry whose bound exceeds the block's bound2 at each of
// the block's corners fails the test there and is not listed. One pass over
// t serves all the blocks (the interpolation is shared along the lattice's
// rows); out[b] receives the indices of block b's survivors, in order.
__attribute__((target_clones("avx2", "default"))) void lattice_filter(const Packed& t, const Lattice& lat,
                                                                     Survivors& out) {
  const I8 size = I8{} + std::int32_t(t.size), lanes = I8{0, 1, 2, 3, 4, 5, 6, 7};
  const int nx = lat.n[0], ny = lat.n[1], nz = lat.n[2];
  out.reset(lat.blocks, t.size);
  for (std::size_t i = 0; i < t.size; i += 8) {
    V8 x[4][4], y[2][4][4], lb[64];
    for (int e = 0; e < 4; ++e) {
      V8 lo, hi;
      load8(t.f[Packed::k0 + 2 * e].data() + i, lo);
      load8(t.f[Packed::k0 + 2 * e + 1].data() + i, hi);
      for (int a = 0; a < nx; ++a) x[e][a] = lo + lat.w[0][a] * (hi - lo);
    }
    for (int z = 0; z < 2; ++z)
      for (int b = 0; b < ny; ++b)
        for (int a = 0; a < nx; ++a) y[z][b][a] = x[2 * z][a] + lat.w[1][b] * (x[2 * z + 1][a] - x[2 * z][a]);
    for (int c = 0; c < nz; ++c)
      for (int b = 0; b < ny; ++b)
        for (int a = 0; a < nx; ++a) {
          const int l = a + 4 * (b + 4 * c);
          lb[l] = (y[0][b][a] + lat.w[2][c] * (y[1][b][a] - y[0][b][a])) * (1 - 1e-4f) - lat.spread[l];
        }
    const I8 valid = (lanes + std::int32_t(i)) < size;
    for (std::size_t b = 0; b < lat.blocks; ++b) {
      I8 pass = I8{};
      for (int k = 0; k < 8; ++k) pass |= lb[lat.corner[b][k]] <= lat.bound2[b][k];
      pass &= valid;
      for (int l = 0; l < 8; ++l)
        if (pass[l]) out.list[b][out.count[b]++] = std::uint32_t(i + std::size_t(l));
    }
  }
}


// The smallest of 8 lanes, in three halving steps.
// (__builtin_shufflevector: GCC 12 and clang both have it; the fuzz build is clang.)
__attribute__((always_inline)) inline float min8(const V8& in) {
  V8 v = in;
  V8 w = __builtin_shufflevector(v, v, 4, 5, 6, 7, 0, 1, 2, 3);
  v = v < w ? v : w;
  w = __builtin_shufflevector(v, v, 2, 3, 0, 1, 6, 7, 4, 5);
  v = v < w ? v : w;
  w = __builtin_shufflevector(v, v, 1, 0, 3, 2, 5, 4, 7, 6);
  v = v < w ? v : w;
  return v[0];
}

// Where a sample sits in its block: its trilinear weights (the fractions of
// the block's extent along x, y, z) and the spread sum_k w_k |v_k - p|^2 of
// the corners about it.
struct InBlock {
  float wx, wy, wz, spread;
};

// Of the search's lanes (each lane's best squared distance, face and entry),
// the entry of the smallest distance, ties to the smallest face; d2 = its distance.
inline std::size_t best_lane(const float* best, const std::int32_t* face_of, const std::int32_t* entry, int lanes,
                             float& d2) {
  std::size_t index = 0;
  d2 = kInf;
  std::int32_t face = std::numeric_limits<std::int32_t>::max();
  for (int l = 0; l < lanes; ++l)
    if (best[l] < d2 || (best[l] == d2 && face_of[l] < face)) d2 = best[l], face = face_of[l], index = std::size_t(entry[l]);
  return index;
}

// Per lane, the nearest of the entries seen so far (ties to the smallest face):
// its squared distance, face and entry.
struct Best8 {
  V8 d2 = V8{} + kInf;
  I8 face = I8{} + std::numeric_limits<std::int32_t>::max(), at = I8{};
  // Entries `lane` at squared distances r (inf for the padding), from t.face.
  __attribute__((always_inline)) void update(const V8& r, const I8& lane, const std::int32_t* faces) {
    I8 f;
    std::memcpy(&f, faces, sizeof f);
    const auto closer = (r < d2) | ((r == d2) & (f < face));
    d2 = closer ? r : d2;
    face = closer ? f : face;
    at = closer ? lane : at;
  }
  // The nearest entry of all lanes; `nearest_d2` = its squared distance.
  __attribute__((always_inline)) std::size_t result(float& nearest_d2) const {
    float bd[8];
    std::int32_t bf[8], ba[8];
    std::memcpy(bd, &d2, sizeof bd);
    std::memcpy(bf, &face, sizeof bf);
    std::memcpy(ba, &at, sizeof ba);
    return best_lane(bd, bf, ba, 8, nearest_d2);
  }
};

// For each corner c of a block's list (k<c>: the squared distances from the
// block's corner c), the entry of the smallest distance, ties to the smallest
// face (the lexicographic minimum of (distance, face): one entry whatever the
// order of the search, so the same at every SIMD level).
__attribute__((target_clones("avx2", "default"))) void corner_nearest(const Packed& t, std::array<std::size_t, 8>& index, std::array<float, 8>& dist2) {
  const I8 size = I8{} + std::int32_t(t.size), lanes = I8{0, 1, 2, 3, 4, 5, 6, 7};
  for (int c = 0; c < 8; ++c) {
    Best8 best;
    const float* k = t.f[Packed::k0 + c].data();
    for (std::size_t i = 0; i < t.size; i += 8) {
      const I8 lane = lanes + std::int32_t(i);
      V8 r;
      load8(k + i, r);
      best.update(lane < size ? r : V8{} + kInf, lane, t.face.data() + i);
    }
    index[c] = best.result(dist2[c]);
  }
}

// The entry of t nearest to p and its squared distance; of equally near
// ones, the one of the smallest face index. t is a block's list with the
// squared distances from the block's corners (k0..k7): by concavity,
// dist^2(p, f) >= sum_k w_k dist^2(v_k, f) - sum_k w_k |v_k - p|^2 (the
// trilinear interpolation of the corner values, less the spread), so a group
// of 8 entries whose bounds all exceed the best distance so far is skipped
// without computing its distances. The group `seed` (that of a neighbour's
// nearest: within the neighbour's distance + the spacing) is searched first.
// `slack` covers the float rounding of the bound. Without `in_block` (a
// tile's list, without corner distances) every group is searched.
__attribute__((target_clones("avx2", "default"))) std::size_t nearest(const Packed& t, const Vec3f& p,
                                                                       const InBlock* in_block, float slack,
                                                                       std::size_t seed, float& d2) {
  const float* floor = in_block && !t.floor.empty() ? t.floor.data() : nullptr;
  const InBlock at_p = in_block ? *in_block : InBlock{};
  const V8 px = V8{} + p.x(), py = V8{} + p.y(), pz = V8{} + p.z();
  const V8 wx = V8{} + at_p.wx, wy = V8{} + at_p.wy, wz = V8{} + at_p.wz;
  Best8 best;
  const I8 size = I8{} + std::int32_t(t.size), lanes = I8{0, 1, 2, 3, 4, 5, 6, 7};
  float reach2 = kInf;  // the best squared distance so far
  const auto group = [&](std::size_t c) __attribute__((always_inline)) {  // inlined: compiled for the clone's target
    const std::size_t i = 8 * c;
    const I8 lane = lanes + std::int32_t(i);
    V8 r;
    distance8(t.f, i, px, py, pz, r);
    r = lane < size ? r : V8{} + kInf;  // the padding
    best.update(r, lane, t.face.data() + i);
    reach2 = std::min(reach2, min8(r));
  };
  const auto lower = [&](std::size_t c) __attribute__((always_inline)) {  // the smallest bound of group c
    const std::size_t i = 8 * c;
    const auto k = [&](int n) { return load8(t.f[Packed::k0 + n].data() + i); };
    const V8 x0 = k(0) + wx * (k(1) - k(0)), x1 = k(2) + wx * (k(3) - k(2));
    const V8 x2 = k(4) + wx * (k(5) - k(4)), x3 = k(6) + wx * (k(7) - k(6));
    const V8 y0 = x0 + wy * (x1 - x0), y1 = x2 + wy * (x3 - x2);
    const V8 z = y0 + wz * (y1 - y0);
    return min8(z) * (1 - 1e-4f) - at_p.spread - slack;
  };
  const std::size_t groups = (t.size + 7) / 8;
  if (seed >= groups) seed = 0;
  group(seed);
  for (std::size_t c = 0; c < groups; ++c) {
    if (floor && floor[c] > reach2 * (1 + 1e-4f)) break;  // the groups are sorted by their floors
    if (c == seed || (in_block && lower(c) > reach2 * (1 + 1e-4f))) continue;
    group(c);
  }
  return best.result(d2);
}

// The same kernels sixteen entries at a time with AVX-512 (chosen at run time
// by core/simd_level.hpp). They perform the same IEEE operations in the same
// order as the eight-wide ones above (this file is compiled with
// -ffp-contract=off, so no FMA contraction), hence the same distances; the
// search prunes pairs of groups instead of groups, which drops only entries
// that cannot be nearest, so the results are identical.
#if defined(__x86_64__) && defined(__GNUC__)
#define GEODS_SDF_AVX512 1
#define GEODS_AVX512_FN __attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2,popcnt")))
#define GEODS_AVX512_INLINE __attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2,popcnt"), always_inline)) inline
// GCC 12 warns about the undefined pass-through operand inside its own
// intrinsics (_mm512_min_ps, _mm512_max_ps, _mm512_reduce_min_ps) once they are inlined.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
namespace avx512 {

GEODS_AVX512_INLINE __m512 at(const Packed::Arrays& f, int k, std::size_t i) { return _mm512_loadu_ps(f[k].data() + i); }

GEODS_AVX512_INLINE __m512 clamp01(__m512 t) {  // 1 < max(0, t) ? 1 : ..., as the eight-wide selects
  return _mm512_min_ps(_mm512_set1_ps(1.0f), _mm512_max_ps(_mm512_setzero_ps(), t));
}
GEODS_AVX512_INLINE __m512 dot(__m512 a, __m512 b, __m512 c, __m512 x, __m512 y, __m512 z) {
  return _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(a, x), _mm512_mul_ps(b, y)), _mm512_mul_ps(c, z));
}
GEODS_AVX512_INLINE __m512 sq(__m512 x, __m512 y, __m512 z) { return dot(x, y, z, x, y, z); }
GEODS_AVX512_INLINE __m512 lerp(__m512 a, __m512 b, __m512 w) {
  return _mm512_add_ps(a, _mm512_mul_ps(w, _mm512_sub_ps(b, a)));
}

// Squared distances from p to entries [i, i + 16) of f (as distance8).
GEODS_AVX512_INLINE __m512 distance16(const Packed::Arrays& f, std::size_t i, __m512 px, __m512 py, __m512 pz) {
  const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
  const __m512 bx = at(f, Packed::bx, i), by = at(f, Packed::by, i), bz = at(f, Packed::bz, i);
  const __m512 cx = at(f, Packed::cx, i), cy = at(f, Packed::cy, i), cz = at(f, Packed::cz, i);
  const __m512 qx = _mm512_sub_ps(px, at(f, Packed::ax, i)), qy = _mm512_sub_ps(py, at(f, Packed::ay, i)),
               qz = _mm512_sub_ps(pz, at(f, Packed::az, i));
  const __m512 e1 = dot(bx, by, bz, qx, qy, qz);
  const __m512 e2 = dot(cx, cy, cz, qx, qy, qz);
  const __m512 d01 = at(f, Packed::d01, i), inv_den = at(f, Packed::inv_den, i), has_face = at(f, Packed::has_face, i);
  const __m512 v = _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(at(f, Packed::d11, i), e1), _mm512_mul_ps(d01, e2)), inv_den);
  const __m512 w = _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(at(f, Packed::d00, i), e2), _mm512_mul_ps(d01, e1)), inv_den);
  const __m512 h = dot(at(f, Packed::nx, i), at(f, Packed::ny, i), at(f, Packed::nz, i), qx, qy, qz);
  const __m512 face = _mm512_mul_ps(h, h);
  const __mmask16 inside = _mm512_cmp_ps_mask(v, zero, _CMP_GE_OQ) & _mm512_cmp_ps_mask(w, zero, _CMP_GE_OQ) &
                           _mm512_cmp_ps_mask(_mm512_add_ps(v, w), one, _CMP_LE_OQ) &
                           _mm512_cmp_ps_mask(has_face, zero, _CMP_GT_OQ);
  __m512 s = clamp01(_mm512_mul_ps(e1, at(f, Packed::inv_ab, i)));
  const __m512 dab = sq(_mm512_sub_ps(qx, _mm512_mul_ps(s, bx)), _mm512_sub_ps(qy, _mm512_mul_ps(s, by)),
                        _mm512_sub_ps(qz, _mm512_mul_ps(s, bz)));
  s = clamp01(_mm512_mul_ps(e2, at(f, Packed::inv_ac, i)));
  const __m512 dac = sq(_mm512_sub_ps(qx, _mm512_mul_ps(s, cx)), _mm512_sub_ps(qy, _mm512_mul_ps(s, cy)),
                        _mm512_sub_ps(qz, _mm512_mul_ps(s, cz)));
  const __m512 ux = _mm512_sub_ps(qx, bx), uy = _mm512_sub_ps(qy, by), uz = _mm512_sub_ps(qz, bz);
  const __m512 wx = _mm512_sub_ps(cx, bx), wy = _mm512_sub_ps(cy, by), wz = _mm512_sub_ps(cz, bz);
  s = clamp01(_mm512_mul_ps(dot(ux, uy, uz, wx, wy, wz), at(f, Packed::inv_bc, i)));
  const __m512 dbc = sq(_mm512_sub_ps(ux, _mm512_mul_ps(s, wx)), _mm512_sub_ps(uy, _mm512_mul_ps(s, wy)),
                        _mm512_sub_ps(uz, _mm512_mul_ps(s, wz)));
  // dab < dac ? dab : dac, then dbc < edge ? dbc : edge.
  const __m512 edge = _mm512_min_ps(dbc, _mm512_min_ps(dab, dac));
  return _mm512_mask_blend_ps(inside, edge, face);
}

GEODS_AVX512_INLINE __mmask16 valid(std::size_t i, std::size_t size) {
  return i + 16 <= size ? __mmask16(0xffff) : i >= size ? __mmask16(0) : __mmask16((1u << (size - i)) - 1);
}

// The entries of t that pass the corner test (as the eight-wide
// corner_test()), in order, into out: their quantities, faces, leaves and
// squared distances from the 8 corners (k0..k7), by compress stores (copies
// by position, gathers, cost four times more).
GEODS_AVX512_FN void corner_copy(const Packed& t, const std::array<Vec3f, 8>& corners, const std::array<float, 8>* bound2,
                                 int sets, Packed& out) {
  out.clear();
  out.reserve(t.size);
  std::size_t e = 0;
  for (std::size_t i = 0; i < t.size; i += 16) {
    __m512 dv[8];
    __mmask16 pass = 0;
    for (int k = 0; k < 8; ++k) {
      dv[k] = distance16(t.f, i, _mm512_set1_ps(corners[k].x()), _mm512_set1_ps(corners[k].y()),
                         _mm512_set1_ps(corners[k].z()));
      pass |= _mm512_cmp_ps_mask(dv[k], _mm512_set1_ps(bound2[0][k]), _CMP_LE_OQ);
    }
    for (int j = 1; j < sets; ++j) {
      __mmask16 also = 0;
      for (int k = 0; k < 8; ++k) also |= _mm512_cmp_ps_mask(dv[k], _mm512_set1_ps(bound2[j][k]), _CMP_LE_OQ);
      pass &= also;
    }
    pass &= valid(i, t.size);
    if (!pass) continue;
    for (int k = 0; k < Packed::k0; ++k) _mm512_mask_compressstoreu_ps(out.f[k].data() + e, pass, at(t.f, k, i));
    for (int k = 0; k < 8; ++k) _mm512_mask_compressstoreu_ps(out.f[Packed::k0 + k].data() + e, pass, dv[k]);
    _mm512_mask_compressstoreu_epi32(out.face.data() + e, pass, _mm512_loadu_si512(t.face.data() + i));
    _mm512_mask_compressstoreu_epi32(out.leaf.data() + e, pass, _mm512_loadu_si512(t.leaf.data() + i));
    e += std::size_t(__builtin_popcount(pass));
  }
  out.size = e;
  out.floor.clear();
}

GEODS_AVX512_FN void lattice_filter(const Packed& t, const Lattice& lat,
                                    Survivors& out) {
  const int nx = lat.n[0], ny = lat.n[1], nz = lat.n[2];
  out.reset(lat.blocks, t.size);
  const __m512 shrink = _mm512_set1_ps(1 - 1e-4f);
  for (std::size_t i = 0; i < t.size; i += 16) {
    __m512 x[4][4], y[2][4][4], lb[64];
    for (int e = 0; e < 4; ++e) {
      const __m512 lo = at(t.f, Packed::k0 + 2 * e, i), hi = at(t.f, Packed::k0 + 2 * e + 1, i);
      const __m512 dif = _mm512_sub_ps(hi, lo);
      for (int a = 0; a < nx; ++a) x[e][a] = _mm512_add_ps(lo, _mm512_mul_ps(_mm512_set1_ps(lat.w[0][a]), dif));
    }
    for (int z = 0; z < 2; ++z)
      for (int b = 0; b < ny; ++b)
        for (int a = 0; a < nx; ++a)
          y[z][b][a] = _mm512_add_ps(x[2 * z][a], _mm512_mul_ps(_mm512_set1_ps(lat.w[1][b]),
                                                                _mm512_sub_ps(x[2 * z + 1][a], x[2 * z][a])));
    for (int c = 0; c < nz; ++c)
      for (int b = 0; b < ny; ++b)
        for (int a = 0; a < nx; ++a) {
          const int l = a + 4 * (b + 4 * c);
          lb[l] = _mm512_sub_ps(
              _mm512_mul_ps(_mm512_add_ps(y[0][b][a], _mm512_mul_ps(_mm512_set1_ps(lat.w[2][c]),
                                                                    _mm512_sub_ps(y[1][b][a], y[0][b][a]))),
                            shrink),
              _mm512_set1_ps(lat.spread[l]));
        }
    const __mmask16 ok = valid(i, t.size);
    for (std::size_t b = 0; b < lat.blocks; ++b) {
      __mmask16 pass = 0;
      for (int k = 0; k < 8; ++k)
        pass |= _mm512_cmp_ps_mask(lb[lat.corner[b][k]], _mm512_set1_ps(lat.bound2[b][k]), _CMP_LE_OQ);
      pass &= ok;
      out.mask[b][i / 16] = pass;
      out.count[b] += std::size_t(__builtin_popcount(pass));
    }
  }
}

// out = the entries of `in` set in `mask` (one mask per 16 entries), in
// order: their first k0 quantities, faces and leaves, by compress stores.
GEODS_AVX512_FN void select(const Packed& in, const std::vector<std::uint16_t>& mask, Packed& out) {
  out.clear();
  out.reserve(in.size);
  std::size_t e = 0;
  for (std::size_t i = 0; i < in.size; i += 16) {
    const __mmask16 m = mask[i / 16];
    if (!m) continue;
    for (int k = 0; k < Packed::k0; ++k) _mm512_mask_compressstoreu_ps(out.f[k].data() + e, m, at(in.f, k, i));
    _mm512_mask_compressstoreu_epi32(out.face.data() + e, m, _mm512_loadu_si512(in.face.data() + i));
    _mm512_mask_compressstoreu_epi32(out.leaf.data() + e, m, _mm512_loadu_si512(in.leaf.data() + i));
    e += std::size_t(__builtin_popcount(m));
  }
  out.size = e;
}

// best_lane() of sixteen lanes by vector reductions (the scalar loop's
// data-dependent branches cost a quarter of a search): the smallest distance,
// of its lanes the smallest face, of those the first lane. The lanes hold no
// NaN (they change only on ordered comparisons), so some lane is chosen.
GEODS_AVX512_INLINE std::size_t best_lane16(__m512 best, __m512i face, __m512i entry, float& d2) {
  const float least = _mm512_reduce_min_ps(best);
  const __mmask16 at_least = _mm512_cmp_ps_mask(best, _mm512_set1_ps(least), _CMP_EQ_OQ);
  const std::int32_t first_face = _mm512_mask_reduce_min_epi32(at_least, face);
  const __mmask16 chosen = at_least & _mm512_cmpeq_epi32_mask(face, _mm512_set1_epi32(first_face));
  d2 = least;
  alignas(64) std::int32_t ba[16];
  _mm512_store_si512(ba, entry);
  return std::size_t(ba[__builtin_ctz(chosen)]);
}

// As corner_nearest() above, sixteen entries at a time, the 8 corners side by side (their
// chains of comparisons are independent: interleaved, they do not wait for each other).
GEODS_AVX512_FN void corner_nearest(const Packed& t, std::array<std::size_t, 8>& index, std::array<float, 8>& dist2) {
  const __m512i lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  __m512 best[8];
  __m512i at[8], best_face[8];
  for (int c = 0; c < 8; ++c)
    best[c] = _mm512_set1_ps(kInf), at[c] = _mm512_setzero_si512(),
    best_face[c] = _mm512_set1_epi32(std::numeric_limits<std::int32_t>::max());
  for (std::size_t i = 0; i < t.size; i += 16) {
    const __mmask16 ok = valid(i, t.size);
    const __m512i face = _mm512_loadu_si512(t.face.data() + i);
    const __m512i entry = _mm512_add_epi32(lanes, _mm512_set1_epi32(std::int32_t(i)));
    for (int c = 0; c < 8; ++c) {
      const __m512 r = _mm512_mask_blend_ps(ok, _mm512_set1_ps(kInf), _mm512_loadu_ps(t.f[Packed::k0 + c].data() + i));
      const __mmask16 closer = _mm512_cmp_ps_mask(r, best[c], _CMP_LT_OQ) |
                               (_mm512_cmp_ps_mask(r, best[c], _CMP_EQ_OQ) & _mm512_cmplt_epi32_mask(face, best_face[c]));
      best[c] = _mm512_mask_blend_ps(closer, best[c], r);
      best_face[c] = _mm512_mask_blend_epi32(closer, best_face[c], face);
      at[c] = _mm512_mask_blend_epi32(closer, at[c], entry);
    }
  }
  for (int c = 0; c < 8; ++c) {
    float d2;
    index[std::size_t(c)] = best_lane16(best[c], best_face[c], at[c], d2);
    dist2[std::size_t(c)] = d2;
  }
}

// out[j] = src[index[j]] for j < n (32-bit values, moved as bits).
GEODS_AVX512_FN void gather(const std::uint32_t* src, const std::uint32_t* index, std::size_t n, std::uint32_t* out) {
  for (std::size_t j = 0; j < n; j += 16) {
    const __mmask16 m = valid(j, n);
    const __m512i at = _mm512_maskz_loadu_epi32(m, index + j);
    _mm512_mask_storeu_epi32(out + j, m, _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), m, at, src, 4));
  }
}

// The 16 x 16 transpose of r (o[k] lane m = r[m] lane k), of which only the first `outputs`
// rows are written: four rounds of in-lane and cross-lane shuffles.
template <int outputs>
GEODS_AVX512_INLINE void transpose16(const __m512 (&r)[16], __m512 (&o)[16]) {
  __m512 t[16], u[16];
  for (int m = 0; m < 16; m += 2) t[m] = _mm512_unpacklo_ps(r[m], r[m + 1]), t[m + 1] = _mm512_unpackhi_ps(r[m], r[m + 1]);
  // u[4 g + f]: rows 4 g .. 4 g + 3 of columns f, f + 4, f + 8, f + 12 (one per 128-bit lane).
  for (int g = 0; g < 4; ++g) {
    const __m512d a = _mm512_castps_pd(t[4 * g]), b = _mm512_castps_pd(t[4 * g + 1]);
    const __m512d c = _mm512_castps_pd(t[4 * g + 2]), d = _mm512_castps_pd(t[4 * g + 3]);
    u[4 * g] = _mm512_castpd_ps(_mm512_unpacklo_pd(a, c));
    u[4 * g + 1] = _mm512_castpd_ps(_mm512_unpackhi_pd(a, c));
    u[4 * g + 2] = _mm512_castpd_ps(_mm512_unpacklo_pd(b, d));
    u[4 * g + 3] = _mm512_castpd_ps(_mm512_unpackhi_pd(b, d));
  }
  for (int f = 0; f < 4; ++f) {
    if (f < outputs) {  // columns f and f + 8
      const __m512 v = _mm512_shuffle_f32x4(u[f], u[4 + f], 0x88), w = _mm512_shuffle_f32x4(u[8 + f], u[12 + f], 0x88);
      o[f] = _mm512_shuffle_f32x4(v, w, 0x88);
      if (f + 8 < outputs) o[f + 8] = _mm512_shuffle_f32x4(v, w, 0xdd);
    }
    if (f + 4 < outputs) {  // columns f + 4 and f + 12
      const __m512 v = _mm512_shuffle_f32x4(u[f], u[4 + f], 0xdd), w = _mm512_shuffle_f32x4(u[8 + f], u[12 + f], 0xdd);
      o[f + 4] = _mm512_shuffle_f32x4(v, w, 0x88);
      if (f + 12 < outputs) o[f + 12] = _mm512_shuffle_f32x4(v, w, 0xdd);
    }
  }
}

// out[k][j] = rows[index[j] * (k0 + 1) + k] for j < n and k < k0, and
// face[j] the bits of rows[index[j] * (k0 + 1) + k0]: the quantities and
// face of entries stored row by row (one or two cache lines per entry),
// 16 rows at a time loaded whole and transposed (gathers cost three times more).
// The rows are followed by 16 floats of padding (a row's second load reads past it);
// out and face have room for n rounded up to 16.
GEODS_AVX512_FN void gather_rows(const float* rows, const std::uint32_t* index, std::size_t n, Packed::Arrays& out,
                                 std::int32_t* face) {
  static_assert(Packed::k0 + 1 > 16 && Packed::k0 + 1 <= 32);
  constexpr int kRest = Packed::k0 + 1 - 16;  // the second load's columns
  for (std::size_t j = 0; j < n; j += 16) {
    __m512 lo[16], hi[16], o[16];
    for (int m = 0; m < 16; ++m) {
      const float* row = rows + std::size_t(j + std::size_t(m) < n ? index[j + std::size_t(m)] : index[0]) * (Packed::k0 + 1);
      lo[m] = _mm512_loadu_ps(row);
      hi[m] = _mm512_loadu_ps(row + 16);
    }
    transpose16<16>(lo, o);
    for (int k = 0; k < 16; ++k) _mm512_storeu_ps(out[k].data() + j, o[k]);
    transpose16<kRest>(hi, o);
    for (int k = 16; k < Packed::k0; ++k) _mm512_storeu_ps(out[k].data() + j, o[k - 16]);
    _mm512_storeu_ps(reinterpret_cast<float*>(face + j), o[kRest - 1]);
  }
}

// The search state of nearest() below.
struct Search {
  const Packed& t;
  __m512 px, py, pz, wx, wy, wz;
  __m512 best = _mm512_set1_ps(kInf);
  __m512i at_lane = _mm512_setzero_si512(), best_face = _mm512_set1_epi32(std::numeric_limits<std::int32_t>::max());
  float reach2 = kInf;  // the best squared distance so far

  // Entries [16 c, 16 c + 16).
  GEODS_AVX512_INLINE void pair(std::size_t c) {
    const std::size_t i = 16 * c;
    __m512 r = distance16(t.f, i, px, py, pz);
    r = _mm512_mask_blend_ps(valid(i, t.size), _mm512_set1_ps(kInf), r);  // the padding
    const __m512i face = _mm512_loadu_si512(t.face.data() + i);
    const __mmask16 closer = _mm512_cmp_ps_mask(r, best, _CMP_LT_OQ) |
                             (_mm512_cmp_ps_mask(r, best, _CMP_EQ_OQ) & _mm512_cmplt_epi32_mask(face, best_face));
    const __m512i lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    best = _mm512_mask_blend_ps(closer, best, r);
    best_face = _mm512_mask_blend_epi32(closer, best_face, face);
    at_lane = _mm512_mask_blend_epi32(closer, at_lane, _mm512_add_epi32(lanes, _mm512_set1_epi32(std::int32_t(i))));
    reach2 = std::min(reach2, _mm512_reduce_min_ps(r));
  }
  const float* row = nullptr;  // optional: row_bounds() of p's row
  // Whether every entry's bound in pair c (as lower() of nearest()) exceeds reach2.
  GEODS_AVX512_INLINE bool beyond(std::size_t c, float spread, float slack) const {
    const std::size_t i = 16 * c;
    if (row) {
      const __m512 z = lerp(_mm512_loadu_ps(row + 2 * i), _mm512_loadu_ps(row + 2 * i + 16), wx);
      const __m512 lb = _mm512_sub_ps(_mm512_sub_ps(_mm512_mul_ps(z, _mm512_set1_ps(1 - 1e-4f)), _mm512_set1_ps(spread)),
                                      _mm512_set1_ps(slack));
      return _mm512_cmp_ps_mask(lb, _mm512_set1_ps(reach2 * (1 + 1e-4f)), _CMP_GT_OQ) == __mmask16(0xffff);
    }
    const int k0 = Packed::k0;
    const __m512 x0 = lerp(at(t.f, k0, i), at(t.f, k0 + 1, i), wx), x1 = lerp(at(t.f, k0 + 2, i), at(t.f, k0 + 3, i), wx);
    const __m512 x2 = lerp(at(t.f, k0 + 4, i), at(t.f, k0 + 5, i), wx), x3 = lerp(at(t.f, k0 + 6, i), at(t.f, k0 + 7, i), wx);
    const __m512 z = lerp(lerp(x0, x1, wy), lerp(x2, x3, wy), wz);
    const __m512 lb = _mm512_sub_ps(_mm512_sub_ps(_mm512_mul_ps(z, _mm512_set1_ps(1 - 1e-4f)), _mm512_set1_ps(spread)),
                                    _mm512_set1_ps(slack));
    return _mm512_cmp_ps_mask(lb, _mm512_set1_ps(reach2 * (1 + 1e-4f)), _CMP_GT_OQ) == __mmask16(0xffff);
  }
};

// For the samples of one row along x of a block (weights wy, wz): each
// entry's corner distances interpolated along y and z at the block's two
// x-ends, so that a sample's bound is one interpolation along x (the same
// trilinear bound in another order: its rounding is covered as that of lower()).
// row[32 c + l] and row[32 c + 16 + l]: the ends of entry 16 c + l.
GEODS_AVX512_FN void row_bounds(const Packed& t, float wy, float wz, float* row) {
  const __m512 y = _mm512_set1_ps(wy), z = _mm512_set1_ps(wz);
  const int k0 = Packed::k0;
  for (std::size_t i = 0; i < t.size; i += 16) {
    const __m512 lo = lerp(lerp(at(t.f, k0, i), at(t.f, k0 + 2, i), y), lerp(at(t.f, k0 + 4, i), at(t.f, k0 + 6, i), y), z);
    const __m512 hi =
        lerp(lerp(at(t.f, k0 + 1, i), at(t.f, k0 + 3, i), y), lerp(at(t.f, k0 + 5, i), at(t.f, k0 + 7, i), y), z);
    _mm512_storeu_ps(row + 2 * i, lo);
    _mm512_storeu_ps(row + 2 * i + 16, hi);
  }
}

// As nearest() above; groups of 8 are searched and bounded two at a time.
// With `row` (row_bounds() of p's row), the bounds come from there. (The
// lists are not sorted here, see filter(): every pair is bounded.)
GEODS_AVX512_FN std::size_t nearest(const Packed& t, const Vec3f& p, const InBlock* in_block, float slack,
                                    std::size_t seed, float& d2, const float* row = nullptr) {
  const InBlock at_p = in_block ? *in_block : InBlock{};
  Search s{t,
           _mm512_set1_ps(p.x()),
           _mm512_set1_ps(p.y()),
           _mm512_set1_ps(p.z()),
           _mm512_set1_ps(at_p.wx),
           _mm512_set1_ps(at_p.wy),
           _mm512_set1_ps(at_p.wz)};
  s.row = in_block ? row : nullptr;
  const std::size_t groups = (t.size + 7) / 8, pairs = (groups + 1) / 2;
  seed /= 2;  // the pair of group `seed`
  if (seed >= pairs) seed = 0;
  s.pair(seed);
  // The pairs to search, 64 at a time: those not beyond the seed's distance, from their bounds
  // without a branch each (a branch per pair mispredicted often), then searched in order.
  for (std::size_t first = 0; first < pairs; first += 64) {
    const std::size_t n = std::min<std::size_t>(64, pairs - first);
    std::uint64_t todo = n == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1;
    if (seed >= first && seed < first + n) todo &= ~(std::uint64_t(1) << (seed - first));
    if (in_block)
      for (std::size_t c = 0; c < n; ++c) todo &= ~(std::uint64_t(s.beyond(first + c, at_p.spread, slack)) << c);
    for (; todo; todo &= todo - 1) s.pair(first + std::size_t(__builtin_ctzll(todo)));
  }
  return best_lane16(s.best, s.best_face, s.at_lane, d2);
}

}  // namespace avx512
#pragma GCC diagnostic pop
#endif

struct Scratch {
  Packed tile_list, block_list, near;
  Kept kept;
  std::vector<std::uint32_t> found;
  Survivors survivors;
  std::vector<float> row;  // avx512::row_bounds
};

class GridSolver {
 public:
  GridSolver(const MeshDistance& mesh, const Grid3Geometry& grid, const SdfGridOptions& options)
      : mesh_(mesh), grid_(grid), options_(options), tris_(mesh.triangles().data()),
        ids_(mesh.bvh().triangle_ids().data()) {
    const std::size_t n = mesh.triangles().size();
    if (n >= std::size_t(std::numeric_limits<std::int32_t>::max())) throw Error("sdf grid: too many faces");
    constexpr std::size_t kRow = Packed::k0 + 1;  // a row: the k0 quantities and the face
    // Only the rows where they serve (all_ is then never read). Not zeroed: the fill below writes
    // every entry, its threads touching the fresh pages (a serial zeroing cost more than the fill).
    if (wide_ && n > 0 && n < std::size_t(std::numeric_limits<std::int32_t>::max()) / kRow) {
      // 16 floats of padding: gather_rows() reads 32 floats from a row's start.
      rows_ = make_huge_page_array<float>(n * kRow + 16, /*touched=*/true);
    } else {
      all_.reserve(n);
      all_.size = n;
    }
    parallel_for_each_index(0, n, [&](std::size_t i) {
      const BvhTriangle& t = tris_[i];
      const Vec3f ab = t.b - t.a, ac = t.c - t.a, bc = t.c - t.b;
      const float d00 = ab.dot(ab), d01 = ab.dot(ac), d11 = ac.dot(ac), den = d00 * d11 - d01 * d01;
      // The unit normal in double: the cross product's squared length is of degree 4.
      const Vec3d nd = ab.cast<double>().cross(ac.cast<double>());
      const double nd_norm = nd.norm();
      const Vec3f n = nd_norm > 0 ? Vec3f((nd / nd_norm).cast<float>()) : Vec3f::Zero();
      const float values[Packed::kFields] = {
          t.a.x(), t.a.y(), t.a.z(), ab.x(), ab.y(), ab.z(), ac.x(), ac.y(), ac.z(), n.x(), n.y(), n.z(), d00, d01,
          d11, den > 0 ? 1 / den : 0.0f, nd_norm > 0 && den > 0 && std::isfinite(den) ? 1.0f : 0.0f, d00 > 0 ? 1 / d00 : 0.0f,
          d11 > 0 ? 1 / d11 : 0.0f, bc.squaredNorm() > 0 ? 1 / bc.squaredNorm() : 0.0f};
      const auto face = std::int32_t(ids_[i]);
      if (rows_) {
        for (int k = 0; k < Packed::k0; ++k)
          rows_[i * kRow + std::size_t(k)] = std::isfinite(values[k]) ? values[k] : 0.0f;
        std::memcpy(&rows_[i * kRow + Packed::k0], &face, sizeof(float));
      } else {
        for (int k = 0; k < Packed::kFields; ++k) all_.f[k][i] = std::isfinite(values[k]) ? values[k] : 0.0f;
        all_.leaf[i] = std::uint32_t(i);
        all_.face[i] = face;
      }
    });
    // Float rounding of distances is below this (relative to the scene's size).
    const AABB3f mb = std::visit([](const auto& v) { return bvh::bounds(v[0]); }, mesh.bvh().volumes());
    const AABB3f gb = grid.bounds();
    const float scale = std::max({mb.lo.cwiseAbs().maxCoeff(), mb.hi.cwiseAbs().maxCoeff(), gb.lo.cwiseAbs().maxCoeff(),
                                  gb.hi.cwiseAbs().maxCoeff(), 1e-30f});
    margin_ = 1e-6f * scale;
    slack_ = 4 * margin_ * scale;  // float rounding of squared distances up to the scene's size
    const float h = grid.spacing.minCoeff();
    band_ = std::isfinite(options.band) ? float(options.band) * h : kInf;
  }

  // One tile: the samples of [lo, hi) into out (and faces).
  void tile(const SampleBox& box, float* out, std::uint32_t* faces, SdfGridStats& stats) const {
    const MeshPointDistance centre = mesh_.query(box.centre, SignMethod::none);
    const std::size_t nx = box.hi[0] - box.lo[0], ny = box.hi[1] - box.lo[1];
    std::array<float, kTile * kTile * kTile> ud;  // unsigned distances (inf: outside the band)
    std::array<std::uint32_t, kTile * kTile * kTile> leaf;  // of each sample's closest (read only where ud < inf)
    ud.fill(kInf);
    const auto local = [&](std::size_t i, std::size_t j, std::size_t k) {
      return (i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - box.lo[2]));
    };
    if (!(centre.distance - box.radius > band_ + margin_)) {
      // Scratch lists of this thread, kept from tile to tile: no allocation or zeroing per tile.
      thread_local Scratch scratch;
      auto& [tile_list, block_list, near, kept, found, survivors, row] = scratch;
      gather(box, centre.closest, tile_list, near, found, kept);
      // Surface points: the closest points of the tile's centre and of the
      // blocks' centres. A face that can be nearest to a sample p of a block is
      // no farther from p than any of them, so each block's list keeps only
      // the faces that pass the corner test against every one of them.
      std::array<Vec3f, 1 + kBlocks> anchors;
      std::size_t num_anchors = 0;
      std::array<Closest, kBlocks> block_closest;
      anchors[num_anchors++] = centre.closest;
      std::array<std::size_t, 3> blocks;  // along each axis
      for (int a = 0; a < 3; ++a) blocks[a] = (box.hi[a] - box.lo[a] + kBlock - 1) / kBlock;
      const std::size_t num_blocks = blocks[0] * blocks[1] * blocks[2];
      const auto block_box = [&](std::size_t b) {
        const std::array<std::size_t, 3> lo{box.lo[0] + kBlock * (b % blocks[0]), box.lo[1] + kBlock * (b / blocks[0] % blocks[1]),
                                            box.lo[2] + kBlock * (b / (blocks[0] * blocks[1]))};
        return SampleBox(grid_, lo,
                         {std::min(lo[0] + kBlock, box.hi[0]), std::min(lo[1] + kBlock, box.hi[1]),
                          std::min(lo[2] + kBlock, box.hi[2])});
      };
      for (std::size_t b = 0; b < num_blocks; ++b) {
        const Vec3f block_centre = block_box(b).centre;
        const InBlock centre_in_tile = in_box(box, block_centre);
        block_closest[b] = closest_in(tile_list, block_centre, &centre_in_tile);
        if (block_closest[b].leaf != kNoIndex) anchors[num_anchors++] = block_closest[b].point;
      }
      // Each block's candidates: the tile's entries that may pass its corner
      // test by the interpolated bounds, then the exact test on those.
      Lattice lat;
      lat.blocks = num_blocks;
      {
        const Vec3f extent = box.corners[7] - box.corners[0];
        std::array<std::array<float, 4>, 3> part{};  // per axis, each position's term of the spread
        for (int a = 0; a < 3; ++a) {
          lat.n[a] = int(2 * blocks[a]);
          for (int m = 0; m < lat.n[a]; ++m) {
            const std::size_t at = box.lo[a] + kBlock * std::size_t(m / 2) +
                                   (m % 2 ? std::min(kBlock, box.hi[a] - box.lo[a] - kBlock * std::size_t(m / 2)) - 1 : 0);
            const float p = grid_.origin[a] + float(at) * grid_.spacing[a];
            const float w = extent[a] > 0 ? std::clamp((p - box.corners[0][a]) / extent[a], 0.0f, 1.0f) : 0.0f;
            lat.w[a][m] = w;
            part[a][m] = extent[a] * extent[a] * w * (1 - w);
          }
        }
        for (int c = 0; c < lat.n[2]; ++c)
          for (int b = 0; b < lat.n[1]; ++b)
            for (int a = 0; a < lat.n[0]; ++a)
              lat.spread[a + 4 * (b + 4 * c)] =
                  (part[0][a] + part[1][b] + part[2][c]) * (1 + 1e-4f) + margin_ * margin_ + slack_;
        for (std::size_t b = 0; b < num_blocks; ++b) {
          const std::array<std::size_t, 3> bc{b % blocks[0], b / blocks[0] % blocks[1], b / (blocks[0] * blocks[1])};
          const SampleBox block = block_box(b);
          const Closest& c = block_closest[b];
          const bool skip = std::sqrt(c.d2) - block.radius > band_ + margin_;
          lat.bound2[b] = bounds_from(block, c.point);
          for (int k = 0; k < 8; ++k) {
            lat.corner[b][k] = int(2 * bc[0] + (k & 1)) + 4 * (int(2 * bc[1] + (k >> 1 & 1)) + 4 * int(2 * bc[2] + (k >> 2 & 1)));
            if (skip) lat.bound2[b][k] = -kInf;
          }
        }
      }
#ifdef GEODS_SDF_AVX512
      if (wide_)
        avx512::lattice_filter(tile_list, lat, survivors);
      else
#endif
        lattice_filter(tile_list, lat, survivors);
      for (std::size_t b = 0; b < num_blocks; ++b) {
        const SampleBox block = block_box(b);
        const Closest& c = block_closest[b];
        if (std::sqrt(c.d2) - block.radius > band_ + margin_) continue;
#ifdef GEODS_SDF_AVX512
        if (wide_)
          avx512::select(tile_list, survivors.mask[b], near);
        else
#endif
          select(tile_list, survivors[b], near, Packed::k0);
        filter(near, block, c.point, block_list, kept, true, std::span(anchors.data(), num_anchors));
        const BlockWeights weights = block_weights(block);  // in_box of each sample
        // Each sample's search starts from the group of its neighbour's nearest face one row back
        // (else one layer back, else the sample before): not the sample just before, so that
        // consecutive searches do not wait for each other.
        std::array<std::uint32_t, kBlock * kBlock * kBlock> slot{};
        // The block's corner samples have their distances from every face of
        // the list already (k0..k7): their nearest entries in one pass.
        std::array<std::size_t, 8> corner{};
        std::array<float, 8> corner_d2{};
        if (block_list.size) {
#ifdef GEODS_SDF_AVX512
          if (wide_)
            avx512::corner_nearest(block_list, corner, corner_d2);
          else
#endif
            corner_nearest(block_list, corner, corner_d2);
        }
        if (wide_ && row.size() < 2 * block_list.f[0].size()) row.resize(2 * block_list.f[0].size());
        for (std::size_t k = block.lo[2]; k < block.hi[2]; ++k)
          for (std::size_t j = block.lo[1]; j < block.hi[1]; ++j) {
            bool row_ready = false;
            for (std::size_t i = block.lo[0]; i < block.hi[0]; ++i) {
              const Vec3f p = grid_.position(i, j, k);
              const std::size_t here = (i - block.lo[0]) + kBlock * ((j - block.lo[1]) + kBlock * (k - block.lo[2]));
              // The block's corner samples have their distances from every face
              // of the list already (k0..k7): the nearest is the smallest of them.
              const int cx = i == block.lo[0] ? 0 : i + 1 == block.hi[0] ? 1 : -1;
              const int cy = j == block.lo[1] ? 0 : j + 1 == block.hi[1] ? 2 : -1;
              const int cz = k == block.lo[2] ? 0 : k + 1 == block.hi[2] ? 4 : -1;
              Closest s;
              if (cx >= 0 && cy >= 0 && cz >= 0) {
                if (block_list.size) s = as_nearest(block_list, corner[cx + cy + cz], corner_d2[cx + cy + cz]);
              } else {
                const InBlock at_p = in_box(weights, i - block.lo[0], j - block.lo[1], k - block.lo[2]);
#ifdef GEODS_SDF_AVX512
                if (wide_ && !row_ready) avx512::row_bounds(block_list, at_p.wy, at_p.wz, row.data()), row_ready = true;
#endif
                const std::size_t from = j > block.lo[1] ? here - kBlock : k > block.lo[2] ? here - kBlock * kBlock : here - 1;
                s = closest_in(block_list, p, &at_p, slot[from] / 8, wide_ ? row.data() : nullptr, false);
              }
              slot[here] = std::uint32_t(s.slot);
              const float d = std::sqrt(s.d2);
              if (d > band_) continue;
              stats.candidates_per_sample += double(block_list.size);
              ud[local(i, j, k)] = d;
              leaf[local(i, j, k)] = s.leaf;
              ++stats.in_band;
            }
          }
      }
    } else {
      ++stats.tiles_outside;
    }
    // Signs, in scan order, each from an earlier neighbour in the tile when no surface can lie between them.
    const bool propagate = options_.sign == SignMethod::none || mesh_.closed();
    std::array<std::uint8_t, kTile * kTile * kTile> inside{};
    const float hx = grid_.spacing.x(), hy = grid_.spacing.y(), hz = grid_.spacing.z();
    for (std::size_t k = box.lo[2]; k < box.hi[2]; ++k)
      for (std::size_t j = box.lo[1]; j < box.hi[1]; ++j)
        for (std::size_t i = box.lo[0]; i < box.hi[0]; ++i) {
          const std::size_t l = local(i, j, k), g = grid_.index(i, j, k);
          const float d = ud[l];
          if (faces) faces[g] = d < kInf ? ids_[leaf[l]] : kNoIndex;
          bool in = false;
          const auto apart = [&](std::size_t n, float h) { return d + ud[n] > h * (1 + 1e-5f) + 2 * margin_; };
          if (options_.sign == SignMethod::none) {
          } else if (options_.sign == SignMethod::pseudonormal && d < kInf) {
            // The side of the closest point's feature (the samples keep only their face).
            const std::uint32_t face = ids_[leaf[l]];
            const BvhTriangle& tri = tris_[leaf[l]];
            const Vec3f p = grid_.position(i, j, k);
            TriangleRegion region;
            const Vec3f q = closest_point_on_triangle(p, tri.a, tri.b, tri.c, region);
            in = (p - q).dot(mesh_.pseudonormal(face, region)) < 0;
          } else if (propagate && i > box.lo[0] && apart(l - 1, hx)) {
            in = inside[l - 1];
          } else if (propagate && j > box.lo[1] && apart(l - nx, hy)) {
            in = inside[l - nx];
          } else if (propagate && k > box.lo[2] && apart(l - nx * ny, hz)) {
            in = inside[l - nx * ny];
          } else {
            const Vec3f p = grid_.position(i, j, k);
            if (options_.sign == SignMethod::winding) {
              in = mesh_.inside_by_winding(p);
              ++stats.winding_numbers;
            } else {
              in = mesh_.inside_by_pseudonormal(p, mesh_.query(p, SignMethod::none));
            }
          }
          inside[l] = in;
          out[g] = in ? -d : d;
        }
  }

 private:
  // Where p (inside the box) sits: its trilinear weights and the spread
  // sum_k w_k |v_k - p|^2 of the box's corners, one axis at a time (rounded up).
  InBlock in_box(const SampleBox& box, const Vec3f& p) const {
    const Vec3f extent = box.corners[7] - box.corners[0];
    float w[3], spread = 0;
    for (int a = 0; a < 3; ++a) {
      float part;
      w[a] = on_axis(box, extent, a, p[a], part);
      spread += part;
    }
    return {w[0], w[1], w[2], spread * (1 + 1e-4f) + margin_ * margin_};
  }
  // in_box's weight along axis a of a point at coordinate x, and its term of the spread.
  static float on_axis(const SampleBox& box, const Vec3f& extent, int a, float x, float& part) {
    const float w = extent[a] > 0 ? std::clamp((x - box.corners[0][a]) / extent[a], 0.0f, 1.0f) : 0.0f;
    part = extent[a] * extent[a] * w * (1 - w);
    return w;
  }
  // in_box for every sample of a block (of at most kBlock samples a side), axis by axis.
  struct BlockWeights {
    std::array<std::array<float, kBlock>, 3> w, part;
  };
  BlockWeights block_weights(const SampleBox& box) const {
    BlockWeights bw;
    const Vec3f extent = box.corners[7] - box.corners[0];
    for (int a = 0; a < 3; ++a)
      for (std::size_t m = 0; m < box.hi[a] - box.lo[a]; ++m)
        bw.w[a][m] = on_axis(box, extent, a, grid_.origin[a] + float(box.lo[a] + m) * grid_.spacing[a], bw.part[a][m]);
    return bw;
  }
  InBlock in_box(const BlockWeights& bw, std::size_t i, std::size_t j, std::size_t k) const {
    float spread = 0;  // summed in in_box's order
    spread += bw.part[0][i];
    spread += bw.part[1][j];
    spread += bw.part[2][k];
    return {bw.w[0][i], bw.w[1][j], bw.w[2][k], spread * (1 + 1e-4f) + margin_ * margin_};
  }

  // Squared distance bounds at a box's corners from a surface point q.
  std::array<float, 8> bounds_from(const SampleBox& box, const Vec3f& q) const {
    std::array<float, 8> bound2;
    for (int k = 0; k < 8; ++k) {
      const float b = (box.corners[k] - q).norm() * (1 + 1e-5f) + margin_;
      bound2[k] = b * b;
    }
    return bound2;
  }

  // The faces that may be closest to a sample of the box, q being a surface
  // point: the hierarchy's nodes pass if they are no farther than q from one
  // of the box's corners, then their triangles the same test (filter), in
  // leaf order.
  void gather(const SampleBox& box, const Vec3f& q, Packed& out, Packed& near, std::vector<std::uint32_t>& found,
              Kept& kept) const {
    const std::array<float, 8> bound2 = bounds_from(box, q);
    const bvh::Topology& topo = mesh_.bvh().topology();
    found.clear();
#if defined(__SSE2__)
    const __m128 c0 = _mm_setr_ps(box.corners[0].x(), box.corners[0].y(), box.corners[0].z(), 0.0f);
    const __m128 c7 = _mm_setr_ps(box.corners[7].x(), box.corners[7].y(), box.corners[7].z(), 0.0f);
    const __m128 bound_lo = _mm_loadu_ps(bound2.data()), bound_hi = _mm_loadu_ps(bound2.data() + 4);
#endif
    std::visit(
        [&](const auto& volumes) {
          bvh::TraversalStack<bvh::NodeRef> stack(mesh_.stack_size());
          bvh::traverse_topology<false>(
              topo, 0, stack,
              [&](std::uint32_t node, float&) {
                if constexpr (std::is_same_v<std::decay_t<decltype(volumes[node])>, AABB3f>) {
                  // The corners take two coordinates per axis: six squared
                  // gaps instead of 8 box distances (most nodes tested fail all 8).
                  const AABB3f& v = volumes[node];
#if defined(__SSE2__)
                  // The same sums in four lanes: corners 0-3, then 4-7.
                  static_assert(sizeof(AABB3f) == 6 * sizeof(float));
                  const __m128 lo = _mm_loadu_ps(v.lo.data());  // lo, hi.x
                  const __m128 hi = _mm_shuffle_ps(_mm_loadu_ps(v.lo.data() + 2), _mm_loadu_ps(v.lo.data() + 2),
                                                   _MM_SHUFFLE(3, 3, 2, 1));  // hi, hi.z
                  const auto squared_gap = [&](__m128 c) {
                    const __m128 g = _mm_max_ps(_mm_max_ps(_mm_sub_ps(lo, c), _mm_sub_ps(c, hi)), _mm_setzero_ps());
                    return _mm_mul_ps(g, g);
                  };
                  const __m128 g0 = squared_gap(c0), g7 = squared_gap(c7);
                  const __m128 xy = _mm_unpacklo_ps(g0, g7);  // x0 x7 y0 y7
                  const __m128 sum = _mm_add_ps(_mm_movelh_ps(xy, xy), _mm_shuffle_ps(xy, xy, _MM_SHUFFLE(3, 3, 2, 2)));
                  const __m128 near_lo =
                      _mm_cmple_ps(_mm_add_ps(sum, _mm_shuffle_ps(g0, g0, _MM_SHUFFLE(2, 2, 2, 2))), bound_lo);
                  const __m128 near_hi =
                      _mm_cmple_ps(_mm_add_ps(sum, _mm_shuffle_ps(g7, g7, _MM_SHUFFLE(2, 2, 2, 2))), bound_hi);
                  return _mm_movemask_ps(_mm_or_ps(near_lo, near_hi)) != 0;
#else
                  std::array<std::array<float, 2>, 3> gap;
                  for (int a = 0; a < 3; ++a)
                    for (int e = 0; e < 2; ++e) {
                      const float c = box.corners[e ? 7 : 0][a];
                      const float g = std::max({v.lo[a] - c, c - v.hi[a], 0.0f});
                      gap[a][e] = g * g;
                    }
                  bool near = false;
                  for (int k = 0; k < 8; ++k)
                    near |= gap[0][k & 1] + gap[1][k >> 1 & 1] + gap[2][k >> 2 & 1] <= bound2[k];
                  return near;
#endif
                } else {
                  for (int k = 0; k < 8; ++k)
                    if (bvh::squared_distance(volumes[node], box.corners[k]) <= bound2[k]) return true;
                  return false;
                }
              },
              [&](const bvh::TopoNode& node) {  // one resize a leaf, not a push_back (a call) a face
                const std::size_t at = found.size();
                found.resize(at + node.prim_count);
                std::iota(found.begin() + std::ptrdiff_t(at), found.end(), node.prim_first);
              },
              [](float) { return true; });
        },
        mesh_.bvh().volumes());
#ifdef GEODS_SDF_AVX512
    if (rows_) {  // from the rows: fewer cache lines than the columns of all_
      near.clear();
      near.reserve(found.size());
      avx512::gather_rows(rows_.get(), found.data(), found.size(), near.f, near.face.data());
      std::copy_n(found.data(), found.size(), near.leaf.data());  // all_'s leaves are its positions
      near.size = found.size();
    } else
#endif
      select(all_, found, near, Packed::k0);
    filter(near, box, q, out, kept, false);
  }

  // out = the entries `index` of `in` (the first `fields` quantities, faces and leaves).
  void select(const Packed& in, std::span<const std::uint32_t> index, Packed& out, int fields) const {
    out.clear();
    out.reserve(index.size());
    for (int k = 0; k < fields; ++k) copy_at(in.f[k].data(), index.data(), index.size(), out.f[k].data());
    copy_at(in.face.data(), index.data(), index.size(), out.face.data());
    copy_at(in.leaf.data(), index.data(), index.size(), out.leaf.data());
    out.size = index.size();
  }

  // out[j] = src[index[j]] for j < n.
  template <class T>
  void copy_at(const T* src, const std::uint32_t* index, std::size_t n, T* out) const {
    static_assert(sizeof(T) == 4);
#ifdef GEODS_SDF_AVX512
    if (wide_)
      return avx512::gather(reinterpret_cast<const std::uint32_t*>(src), index, n, reinterpret_cast<std::uint32_t*>(out));
#endif
    for (std::size_t j = 0; j < n; ++j) out[j] = src[index[j]];
  }

  // The entries of `in` that pass the corner test of `box` with the surface
  // point q, with their squared distances from the 8 corners (k0..k7);
  // `sorted`: ordered by the smallest of them, with each group's floor, a
  // bound below the squared distance from any point of the box to any of
  // the group's faces (by the concavity above: at least the smallest corner
  // distance less the largest spread). With AVX-512 always in `in`'s order
  // (the hierarchy's leaf order, spatially coherent), written by compress
  // stores: the sort's copies by position (gathers) cost more than its order
  // saves in the searches.
  void filter(const Packed& in, const SampleBox& box, const Vec3f& q, Packed& out, Kept& kept,
              bool sorted, std::span<const Vec3f> more = {}) const {
    std::array<std::array<float, 8>, 2 + kBlocks> sets;
    const int num_sets = 1 + int(std::min<std::size_t>(more.size(), sets.size() - 1));
    sets[0] = bounds_from(box, q);
    for (int j = 1; j < num_sets; ++j) sets[j] = bounds_from(box, more[j - 1]);
#ifdef GEODS_SDF_AVX512
    if (wide_) return avx512::corner_copy(in, box.corners, sets.data(), num_sets, out);
#endif
    corner_test(in, box.corners, sets.data(), num_sets, kept);
    // The order of the entries: `sorted`, nearly by key, by a counting sort
    // into buckets of equal key ranges (in index order within a bucket: kept
    // is in index order); the order changes only how soon a search may stop,
    // never its result (the nearest entry, ties to the smallest face).
    const std::size_t n = kept.size;
    thread_local std::vector<std::uint32_t> order, from;
    thread_local std::vector<std::uint8_t> bucket;
    order.resize(n);
    from.resize(n);
    if (sorted && n > 8) {
      constexpr int kBuckets = 64;
      float lo = kInf, hi = 0;
      for (std::size_t j = 0; j < n; ++j) lo = std::min(lo, kept.key[j]), hi = std::max(hi, kept.key[j]);
      const float scale = hi > lo ? float(kBuckets) / (hi - lo) : 0.0f;
      std::array<std::uint32_t, kBuckets + 1> start{};
      bucket.resize(n);
      for (std::size_t j = 0; j < n; ++j) {
        const float x = (kept.key[j] - lo) * scale;  // NaN (0 * inf) or below 1: the first bucket
        const int b = x >= 1 ? int(std::min(x, float(kBuckets - 1))) : 0;
        bucket[j] = std::uint8_t(b);
        ++start[std::size_t(b) + 1];
      }
      for (int b = 0; b < kBuckets; ++b) start[std::size_t(b) + 1] += start[std::size_t(b)];
      for (std::size_t j = 0; j < n; ++j) order[start[bucket[j]]++] = std::uint32_t(j);
    } else {
      for (std::size_t j = 0; j < n; ++j) order[j] = std::uint32_t(j);
    }
    for (std::size_t j = 0; j < n; ++j) from[j] = kept.index[order[j]];
    out.clear();
    out.reserve(n);
    for (int k = 0; k < Packed::k0; ++k) copy_at(in.f[k].data(), from.data(), n, out.f[k].data());
    for (int k = 0; k < 8; ++k) {
      if (sorted) {
        copy_at(kept.k[k].data(), order.data(), n, out.f[Packed::k0 + k].data());
      } else {  // kept's own order: a plain copy
        std::copy_n(kept.k[k].data(), n, out.f[Packed::k0 + k].data());
      }
    }
    copy_at(in.face.data(), from.data(), n, out.face.data());
    copy_at(in.leaf.data(), from.data(), n, out.leaf.data());
    out.size = n;
    out.floor.clear();
    if (!sorted) return;
    // Each group's floor: below the keys of its entries and of all later
    // ones (nondecreasing, so a search stops at the first that exceeds its best).
    const Vec3f extent = box.corners[7] - box.corners[0];
    const float spread = 0.25f * extent.squaredNorm() * (1 + 1e-4f) + margin_ * margin_;
    const std::size_t groups = (n + 7) / 8;
    out.floor.resize(groups);
    float least = kInf;
    for (std::size_t c = groups; c-- > 0;) {
      for (std::size_t j = 8 * c; j < std::min(n, 8 * c + 8); ++j) least = std::min(least, kept.key[order[j]]);
      out.floor[c] = least * (1 - 1e-4f) - spread - slack_;
    }
  }

  // The closest entry of `list` to p (ties: the smallest face index), with
  // its exact closest point and region (`point`), else only its face and the
  // search's squared distance.
  // With `at_p`, the list is a block's (with corner distances) and p is in the block.
  Closest closest_in(const Packed& list, const Vec3f& p, const InBlock* at_p = nullptr, std::size_t seed = 0,
                     const float* row = nullptr, bool point = true) const {
    if (list.size == 0) return Closest{};
    float nearest_d2;
#ifdef GEODS_SDF_AVX512
    const std::size_t i = wide_ ? avx512::nearest(list, p, at_p, slack_, seed, nearest_d2, row)
                                : nearest(list, p, at_p, slack_, seed, nearest_d2);
#else
    const std::size_t i = nearest(list, p, at_p, slack_, seed, nearest_d2);
#endif
    return point ? entry(list, p, i) : as_nearest(list, i, nearest_d2);
  }

  // Entry i of the list as a sample's closest, at the search's squared
  // distance d2 (the same IEEE operations at every SIMD level), without its
  // closest point.
  static Closest as_nearest(const Packed& list, std::size_t i, float d2) {
    Closest best;
    best.leaf = list.leaf[i];
    best.slot = i;
    best.d2 = d2;
    return best;
  }

  // Entry i of the list as p's closest: its exact closest point and region.
  Closest entry(const Packed& list, const Vec3f& p, std::size_t i) const {
    Closest best;
    const BvhTriangle& tri = tris_[list.leaf[i]];
    best.leaf = list.leaf[i];
    best.slot = i;
    best.point = closest_point_on_triangle(p, tri.a, tri.b, tri.c, best.region);
    best.d2 = (best.point - p).squaredNorm();
    return best;
  }

  const MeshDistance& mesh_;
  const Grid3Geometry& grid_;
  const SdfGridOptions& options_;
  const BvhTriangle* tris_;
  const std::uint32_t* ids_;
  bool wide_ = simd_level() == SimdLevel::avx512;  // the AVX-512 kernels
  Packed all_;                          // every triangle, in leaf order (without rows_)
  HugePageArray<float> rows_;  // with AVX-512: the first k0 quantities and face, entry by entry
  float margin_ = 0;
  float slack_ = 0;
  float band_ = kInf;
};

}  // namespace

Grid3Geometry sdf_grid_geometry(const AABB3f& box, std::size_t res, double spacing, double padding) {
  if (box.empty() || !box.lo.allFinite() || !box.hi.allFinite())
    throw Error("sdf grid: the box to sample is empty or not finite");
  if (!std::isfinite(padding) || padding < 0) throw Error(fmt::format("sdf grid: padding must be >= 0, got {}", padding));
  const Vec3d ext = (box.hi - box.lo).cast<double>();
  const double longest = ext.maxCoeff();
  double h = spacing;
  if (spacing == 0) {
    if (double(res) <= 2 * padding)
      throw Error(fmt::format("sdf grid: {} samples leave nothing inside a padding of {} on each side", res, padding));
    if (!(longest > 0)) throw Error("sdf grid: the box has no extent; give a spacing instead of a resolution");
    h = longest / (double(res) - 2 * padding);
  }
  if (!std::isfinite(h) || !(h > 0)) throw Error(fmt::format("sdf grid: spacing must be finite and > 0, got {}", h));
  Grid3Geometry g;
  const Vec3d centre = 0.5 * (box.lo + box.hi).cast<double>();
  double samples = 1;
  for (int a = 0; a < 3; ++a) {
    const double n = std::max(1.0, std::ceil((ext[a] + 2 * padding * h) / h - 1e-6));
    if (n > double(1u << 30)) throw Error(fmt::format("sdf grid: {} samples along an axis is too many", n));
    samples *= n;
    g.dims[a] = std::size_t(n);
    g.origin[a] = float(centre[a] - 0.5 * n * h + 0.5 * h);
  }
  if (samples > double(std::size_t(1) << 40))
    throw Error(fmt::format("sdf grid: {} samples is too many", samples));
  g.spacing = Vec3f::Constant(float(h));
  return g;
}

SdfMethod parse_sdf_method(std::string_view name) {
  for (const SdfMethod m : {SdfMethod::exact, SdfMethod::propagation})
    if (name == to_string(m)) return m;
  throw Error("sdf grid: unknown method '" + std::string(name) + "' (exact or propagation)");
}

std::string_view to_string(SdfMethod method) { return method == SdfMethod::exact ? "exact" : "propagation"; }

namespace {

// §6.1.1's vector propagation: the exact shell, then two scans passing
// closest points to neighbours (see SdfMethod::propagation).
void propagate(const MeshDistance& mesh, const Grid3Geometry& grid, const SdfGridOptions& options, SdfGrid& result) {
  constexpr double kShell = 1.7321;  // samples: the 3^3 neighbourhood of the surface
  SdfGridOptions shell_options;
  shell_options.sign = SignMethod::none;
  shell_options.band = kShell;
  shell_options.faces = true;
  SdfGrid shell = sdf_grid(mesh, grid, shell_options);
  const std::size_t n = shell.distance.size();
  const auto& tris = mesh.triangles();
  std::vector<std::uint32_t> leaf_of(tris.size());
  for (std::uint32_t i = 0; i < tris.size(); ++i) leaf_of[mesh.face_of(i)] = i;
  std::vector<Vec3f> q(n, Vec3f::Constant(kInf));
  std::vector<std::uint32_t>& face = shell.faces;
  std::vector<float>& d2 = shell.distance.data;
  parallel_for_each_index(0, n, [&](std::size_t s) {
    if (face[s] == kNoIndex) return d2[s] = kInf, void();
    const Vec3f p = grid.position(s % grid.dims[0], s / grid.dims[0] % grid.dims[1], s / (grid.dims[0] * grid.dims[1]));
    const bvh::BvhTriangle& t = tris[leaf_of[face[s]]];
    q[s] = closest_point_on_triangle(p, t.a, t.b, t.c);
    d2[s] = (q[s] - p).squaredNorm();
  }, 4096);
  // The 13 neighbours before a sample in the forward scan (z, y, x increasing).
  struct Step {
    int dx, dy, dz;
  };
  std::vector<Step> steps;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dz < 0 || (dz == 0 && (dy < 0 || (dy == 0 && dx < 0)))) steps.push_back({dx, dy, dz});
  // Named copies, not a structured binding: the lambda below captures them (clang 14 cannot).
  const std::size_t nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  const auto scan = [&](int sign) {
    for (std::size_t kk = 0; kk < nz; ++kk)
      for (std::size_t jj = 0; jj < ny; ++jj)
        for (std::size_t ii = 0; ii < nx; ++ii) {
          const std::size_t i = sign > 0 ? ii : nx - 1 - ii, j = sign > 0 ? jj : ny - 1 - jj,
                            k = sign > 0 ? kk : nz - 1 - kk;
          const std::size_t s = grid.index(i, j, k);
          const Vec3f p = grid.position(i, j, k);
          for (const Step& st : steps) {
            const long a = long(i) + sign * st.dx, b = long(j) + sign * st.dy, c = long(k) + sign * st.dz;
            if (a < 0 || b < 0 || c < 0 || a >= long(nx) || b >= long(ny) || c >= long(nz)) continue;
            const std::size_t m = grid.index(std::size_t(a), std::size_t(b), std::size_t(c));
            if (face[m] == kNoIndex) continue;
            const float e = (q[m] - p).squaredNorm();
            if (e < d2[s]) d2[s] = e, q[s] = q[m], face[s] = face[m];
          }
        }
  };
  scan(1);
  scan(-1);
  // Each sample: the exact distance to its face (at most that to the point it got), and the sign.
  std::atomic<std::size_t> windings{0};
  parallel_for_each_index(0, n, [&](std::size_t s) {
    const Vec3f p = grid.position(s % nx, s / nx % ny, s / (nx * ny));
    if (face[s] == kNoIndex) return d2[s] = kInf, void();  // no shell at all (a grid far from the mesh)
    const bvh::BvhTriangle& t = tris[leaf_of[face[s]]];
    TriangleRegion region;
    const Vec3f c = closest_point_on_triangle(p, t.a, t.b, t.c, region);
    float d = (c - p).norm();
    bool inside = false;
    if (options.sign == SignMethod::pseudonormal) {
      inside = (p - c).dot(mesh.pseudonormal(face[s], region)) < 0;
    } else if (options.sign == SignMethod::winding) {
      inside = mesh.inside_by_winding(p);
      ++windings;
    }
    d2[s] = inside ? -d : d;
  }, 1024);
  result.distance = std::move(shell.distance);
  if (options.faces) result.faces = std::move(face);
  result.stats.in_band = n;
  result.stats.winding_numbers = windings;
}

}  // namespace

SdfGrid sdf_grid(const MeshDistance& mesh, const Grid3Geometry& grid, const SdfGridOptions& options) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(grid.spacing[a]) || !(grid.spacing[a] > 0))
      throw Error(fmt::format("sdf grid: spacing must be finite and > 0, got {} along {}", grid.spacing[a], char('x' + a)));
    if (!std::isfinite(grid.origin[a])) throw Error("sdf grid: the origin is not finite");
  }
  if (std::isnan(options.band) || !(options.band >= 0))
    throw Error(fmt::format("sdf grid: the band must be >= 0 samples, got {}", options.band));
  const AABB3f box = grid.bounds();
  if (!box.hi.allFinite()) throw Error("sdf grid: the grid reaches beyond float range");
  for (const Vec3f& corner : {box.lo, box.hi})
    check_query_range(std::span<const float>(corner.data(), 3), kDistanceCoordinateLimit, "sdf grid");
  const std::size_t n = Grid3<float>::checked_size(grid.dims[0], grid.dims[1], grid.dims[2]);
  // Refuse before allocating what the machine cannot hold.
  const double bytes = double(n) * (options.faces ? 8.0 : 4.0);
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (memory > 0 && bytes > memory)
    throw Error(fmt::format("sdf grid: {} x {} x {} samples need {:.1f} GB, more than this machine's {:.1f} GB",
                            grid.dims[0], grid.dims[1], grid.dims[2], bytes / 1e9, memory / 1e9));

  SdfGrid result;
  static_cast<Grid3Geometry&>(result.distance) = grid;
  // Prefaulted (huge pages where the kernel gives them): a fault per 4 KiB page cost more than the writes.
  result.distance.data = detail::prefaulted_vector<float>(n);
  if (options.faces) result.faces = detail::prefaulted_vector<std::uint32_t>(n);
  result.stats.samples = n;
  if (n == 0) return result;
  if (options.method == SdfMethod::propagation) {
    if (std::isfinite(options.band)) throw Error("sdf grid: the propagation method computes the whole grid (no band)");
    propagate(mesh, grid, options, result);
    return result;
  }
  const GridSolver solver(mesh, grid, options);
  std::array<std::size_t, 3> tiles;
  for (int a = 0; a < 3; ++a) tiles[a] = (grid.dims[a] + kTile - 1) / kTile;
  const std::size_t num_tiles = tiles[0] * tiles[1] * tiles[2];
  result.stats.tiles = num_tiles;
  std::atomic<std::size_t> in_band{0}, outside{0}, windings{0};
  std::atomic<std::uint64_t> candidates{0};
  // The tiles in Morton order: consecutive tiles, and each thread's share, are
  // neighbours in space whose faces are still in cache.
  std::vector<std::pair<std::uint64_t, std::size_t>> order(num_tiles);
  for (std::size_t t = 0; t < num_tiles; ++t)
    order[t] = {morton3d_encode64(std::uint32_t(t % tiles[0]), std::uint32_t(t / tiles[0] % tiles[1]),
                                  std::uint32_t(t / (tiles[0] * tiles[1]))),
                t};
  std::sort(order.begin(), order.end());
  parallel_for_each_index(
      0, num_tiles,
      [&](std::size_t m) {
        const std::size_t t = order[m].second;
        const std::array<std::size_t, 3> c{t % tiles[0], t / tiles[0] % tiles[1], t / (tiles[0] * tiles[1])};
        std::array<std::size_t, 3> lo, hi;
        for (int a = 0; a < 3; ++a) lo[a] = c[a] * kTile, hi[a] = std::min(lo[a] + kTile, grid.dims[a]);
        SdfGridStats s;
        solver.tile(SampleBox(grid, lo, hi), result.distance.data.data(), options.faces ? result.faces.data() : nullptr,
                    s);
        in_band += s.in_band;
        outside += s.tiles_outside;
        windings += s.winding_numbers;
        candidates += std::uint64_t(s.candidates_per_sample);
      },
      1);
  result.stats.in_band = in_band;
  result.stats.tiles_outside = outside;
  result.stats.winding_numbers = windings;
  result.stats.candidates_per_sample = in_band ? double(candidates) / double(in_band) : 0.0;
  return result;
}

SdfGrid sdf_grid(const TriMesh& mesh, const Grid3Geometry& grid, const SdfGridOptions& options) {
  return sdf_grid(MeshDistance::build(mesh), grid, options);
}

}  // namespace geods::field
