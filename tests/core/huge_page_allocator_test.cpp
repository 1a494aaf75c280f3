// HugePageAllocator: large blocks 2 MiB aligned, small ones aligned for their type, both usable;
// freed large blocks serve the next allocation of their size.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "geods/core/huge_page_allocator.hpp"

namespace geods {
namespace {

// A type aligned to a cache line, like the wide BVH nodes the allocator serves.
struct alignas(64) CacheLine {
  float data[32];
};

TEST(HugePageAllocator, LargeBlocksAreHugePageAlignedAndSmallOnesTypeAligned) {
  std::vector<std::uint32_t, HugePageAllocator<std::uint32_t>> large(std::size_t(3) << 20);  // 12 MiB
  std::iota(large.begin(), large.end(), 0u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % HugePageAllocator<int>::kHugePage, 0u);
  EXPECT_EQ(large.back(), std::uint32_t((std::size_t(3) << 20) - 1));

  std::vector<CacheLine, HugePageAllocator<CacheLine>> small(3);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % alignof(CacheLine), 0u);
  small.resize(10000);  // 1.2 MiB: moves to a huge-page block
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % HugePageAllocator<int>::kHugePage, 0u);
}

TEST(HugePageAllocator, FreedLargeBlocksServeTheNextAllocationOfTheirSize) {
  using detail::allocate_huge_pages;
  using detail::free_huge_pages;
  constexpr std::size_t kMiB = std::size_t(1) << 20;
  // 3 MiB rounds to 4 MiB: any size of the same rounding reuses the block.
  void* p = allocate_huge_pages(3 * kMiB, 64);
  static_cast<char*>(p)[0] = 1;
  free_huge_pages(p, 3 * kMiB);
  void* q = allocate_huge_pages(4 * kMiB - 1, 64);
  EXPECT_EQ(q, p);
  // The most recently freed first.
  void* a = allocate_huge_pages(6 * kMiB, 64);
  void* b = allocate_huge_pages(6 * kMiB, 64);
  free_huge_pages(a, 6 * kMiB);
  free_huge_pages(b, 6 * kMiB);
  EXPECT_EQ(allocate_huge_pages(6 * kMiB, 64), b);
  // Another size gets fresh memory (the 6 MiB block a is still held, so it cannot be it).
  void* c = allocate_huge_pages(8 * kMiB, 64);
  EXPECT_NE(c, a);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(c) % detail::kHugePage, 0u);
  EXPECT_EQ(allocate_huge_pages(6 * kMiB, 64), a);
  for (void* x : {q, a, b, c}) free_huge_pages(x, x == q ? 4 * kMiB : x == c ? 8 * kMiB : 6 * kMiB);
  // Small blocks go straight back (nothing to check but that it works).
  void* s = allocate_huge_pages(1000, 16);
  free_huge_pages(s, 1000);
}

}  // namespace
}  // namespace geods
