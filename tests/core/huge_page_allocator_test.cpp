// HugePageAllocator: large blocks 2 MiB aligned, small ones aligned for their type, both usable.
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

}  // namespace
}  // namespace geods
