// BRIO with a branch-free Hilbert index and a radix sort of packed keys.
#include "brio_order.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "../core/prefault.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"

namespace geods::voronoi {
namespace {

std::uint32_t interleave_bits(std::uint32_t x) {
  x = (x | (x << 8)) & 0x00FF00FF;
  x = (x | (x << 4)) & 0x0F0F0F0F;
  x = (x | (x << 2)) & 0x33333333;
  x = (x | (x << 1)) & 0x55555555;
  return x;
}

// Index of (x, y) along the Hilbert curve of a 2^16 x 2^16 grid, without
// branches: the orientation of each level is a prefix scan over the bits
// (after Fabian Giesen's and rawrunprotected's formulation). Equal to the
// classic loop over the 16 levels.
std::uint32_t hilbert_index(std::uint32_t x, std::uint32_t y) {
  std::uint32_t A, B, C, D;
  {
    const std::uint32_t a = x ^ y, b = 0xFFFF ^ a, c = 0xFFFF ^ (x | y), d = x & (y ^ 0xFFFF);
    A = a | (b >> 1);
    B = (a >> 1) ^ a;
    C = ((c >> 1) ^ (b & (d >> 1))) ^ c;
    D = ((a & (c >> 1)) ^ (d >> 1)) ^ d;
  }
  for (int shift = 2; shift <= 4; shift *= 2) {
    const std::uint32_t a = A, b = B, c = C, d = D;
    A = (a & (a >> shift)) ^ (b & (b >> shift));
    B = (a & (b >> shift)) ^ (b & ((a ^ b) >> shift));
    C ^= (a & (c >> shift)) ^ (b & (d >> shift));
    D ^= (b & (c >> shift)) ^ ((a ^ b) & (d >> shift));
  }
  {
    const std::uint32_t a = A, b = B, c = C, d = D;
    C ^= (a & (c >> 8)) ^ (b & (d >> 8));
    D ^= (b & (c >> 8)) ^ ((a ^ b) & (d >> 8));
  }
  const std::uint32_t a = C ^ (C >> 1), b = D ^ (D >> 1);
  const std::uint32_t i0 = x ^ y, i1 = b | (0xFFFF ^ (i0 | a));
  return (interleave_bits(i1) << 1) | interleave_bits(i0);
}

// Index of (x, y, z) along the Hilbert curve of a 2^kBits3 grid per axis
// (Skilling, "Programming the Hilbert curve", 2004: axes to transpose, then
// the transpose's bits interleaved).
constexpr int kBits3 = 9;
std::uint32_t hilbert_index3(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  std::uint32_t X[3] = {x, y, z};
  constexpr std::uint32_t M = 1u << (kBits3 - 1);
  for (std::uint32_t Q = M; Q > 1; Q >>= 1) {
    const std::uint32_t P = Q - 1;
    for (int i = 0; i < 3; ++i)
      if (X[i] & Q) {
        X[0] ^= P;
      } else {
        const std::uint32_t t = (X[0] ^ X[i]) & P;
        X[0] ^= t, X[i] ^= t;
      }
  }
  X[1] ^= X[0], X[2] ^= X[1];
  std::uint32_t t = 0;
  for (std::uint32_t Q = M; Q > 1; Q >>= 1)
    if (X[2] & Q) t ^= Q - 1;
  for (auto& v : X) v ^= t;
  return morton3d_encode32(X[2], X[1], X[0]);
}

// Sorts `items` by their bits [first_bit, first_bit + bits), stably (LSD radix sort, 11 bits a pass).
void radix_sort(std::vector<std::uint64_t>& items, int first_bit, int bits) {
  constexpr int kDigit = 11;
  constexpr std::uint64_t kMask = (1u << kDigit) - 1;
  std::vector<std::uint64_t> buffer = detail::prefaulted_vector<std::uint64_t>(items.size());
  std::vector<std::size_t> count(kMask + 2);
  for (int shift = first_bit; shift < first_bit + bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (std::uint64_t item : items) ++count[((item >> shift) & kMask) + 1];
    for (std::size_t i = 0; i <= kMask; ++i) count[i + 1] += count[i];
    for (std::uint64_t item : items) buffer[count[(item >> shift) & kMask]++] = item;
    items.swap(buffer);
  }
}

}  // namespace

std::vector<std::uint32_t> brio_order(std::span<const Vec2d> points, std::span<const std::uint32_t> active,
                                      std::uint64_t seed) {
  const std::size_t n = active.size();
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (std::uint32_t i : active)
    for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], points[i][a]), hi[a] = std::max(hi[a], points[i][a]);
  // Halves keep the extent finite for coordinates near the double range.
  double scale[2];
  for (int a = 0; a < 2; ++a) {
    const double extent = hi[a] * 0.5 - lo[a] * 0.5;
    scale[a] = extent > 0 ? 16383.0 / extent : 0.0;
  }
  // BRIO rounds: a point lands in the last round with probability 1/2, the one
  // before with 1/4, ...; odd rounds run the Hilbert curve backwards so that
  // consecutive rounds meet where they end. The key packs round (6 bits),
  // Hilbert index on a 2^14 grid (28 bits) and point index (30 bits).
  const int last_round = int(std::bit_width(n));
  std::vector<std::uint64_t> keys = detail::prefaulted_vector<std::uint64_t>(n);
  Rng rng(seed);
  std::vector<std::uint64_t> random = detail::prefaulted_vector<std::uint64_t>(n);
  for (auto& r : random) r = rng();
  parallel_for(0, n, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Vec2d& p = points[active[k]];
      const auto cell = [&](int a) {
        const double t = (p[a] * 0.5 - lo[a] * 0.5) * scale[a];
        return std::uint32_t(std::clamp(t, 0.0, 16383.0));
      };
      const int round = std::max(0, last_round - std::countr_zero(random[k] | (std::uint64_t(1) << 63)));
      std::uint32_t h = hilbert_index(cell(0), cell(1));
      if (round % 2) h = ~h & 0xFFFFFFF;
      keys[k] = (std::uint64_t(round) << 58) | (std::uint64_t(h) << 30) | active[k];
    }
  });
  radix_sort(keys, 30, 34);
  std::vector<std::uint32_t> order = detail::prefaulted_vector<std::uint32_t>(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = std::uint32_t(keys[k] & 0x3FFFFFFF);
  return order;
}

std::vector<std::uint32_t> brio_order(std::span<const Vec3d> points, std::span<const std::uint32_t> active,
                                      std::uint64_t seed) {
  const std::size_t n = active.size();
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::uint32_t i : active)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], points[i][a]), hi[a] = std::max(hi[a], points[i][a]);
  constexpr double kTop = double((1u << kBits3) - 1);
  double scale[3];
  for (int a = 0; a < 3; ++a) {
    const double extent = hi[a] * 0.5 - lo[a] * 0.5;
    scale[a] = extent > 0 ? kTop / extent : 0.0;
  }
  // As in 2D: the key packs round (6 bits), Hilbert index (27 bits) and point index (31 bits).
  const int last_round = int(std::bit_width(n));
  std::vector<std::uint64_t> keys = detail::prefaulted_vector<std::uint64_t>(n);
  Rng rng(seed);
  std::vector<std::uint64_t> random = detail::prefaulted_vector<std::uint64_t>(n);
  for (auto& r : random) r = rng();
  constexpr std::uint32_t kHilbertMask = (1u << (3 * kBits3)) - 1;
  parallel_for(0, n, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Vec3d& p = points[active[k]];
      const auto cell = [&](int a) {
        const double t = (p[a] * 0.5 - lo[a] * 0.5) * scale[a];
        return std::uint32_t(std::clamp(t, 0.0, kTop));
      };
      const int round = std::max(0, last_round - std::countr_zero(random[k] | (std::uint64_t(1) << 63)));
      std::uint32_t h = hilbert_index3(cell(0), cell(1), cell(2));
      if (round % 2) h = ~h & kHilbertMask;
      keys[k] = (std::uint64_t(round) << 58) | (std::uint64_t(h) << 31) | active[k];
    }
  });
  radix_sort(keys, 31, 33);
  std::vector<std::uint32_t> order = detail::prefaulted_vector<std::uint32_t>(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = std::uint32_t(keys[k] & 0x7FFFFFFF);
  return order;
}

}  // namespace geods::voronoi
