#include "geods/core/weld.hpp"

#include <cstring>
#include <limits>

namespace geods {

// Vertices go into a hash table of positions in index order, so a position's first index is its smallest.
std::vector<std::uint32_t> weld(std::span<const Vec3f> vertices) {
  constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  int bits = 4;
  while ((std::size_t(1) << bits) < 2 * vertices.size()) ++bits;
  const std::size_t mask = (std::size_t(1) << bits) - 1;
  std::vector<std::uint32_t> slots(mask + 1, kEmpty);
  std::vector<std::uint32_t> id(vertices.size());
  for (std::uint32_t v = 0; v < vertices.size(); ++v) {
    const Vec3f& p = vertices[v];
    std::uint64_t h = 0;
    for (int c = 0; c < 3; ++c) {
      const float x = p[c] + 0.0f;  // -0 becomes +0: the same position
      std::uint32_t b;
      std::memcpy(&b, &x, sizeof b);
      h = (h + b) * 0x9E3779B97F4A7C15ull;
    }
    std::size_t s = std::size_t(h >> (64 - bits));
    while (slots[s] != kEmpty && vertices[slots[s]] != p) s = (s + 1) & mask;
    if (slots[s] == kEmpty) slots[s] = v;
    id[v] = slots[s];
  }
  return id;
}

}  // namespace geods
