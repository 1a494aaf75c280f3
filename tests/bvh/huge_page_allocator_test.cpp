// HugePageAllocator: large blocks 2 MiB aligned, small ones aligned for their type, both usable.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "geods/bvh/huge_page_allocator.hpp"
#include "geods/bvh/wide_node.hpp"

namespace geods::bvh {
namespace {

TEST(HugePageAllocator, LargeBlocksAreHugePageAlignedAndSmallOnesTypeAligned) {
  std::vector<std::uint32_t, HugePageAllocator<std::uint32_t>> large(std::size_t(3) << 20);  // 12 MiB
  std::iota(large.begin(), large.end(), 0u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % HugePageAllocator<int>::kHugePage, 0u);
  EXPECT_EQ(large.back(), std::uint32_t((std::size_t(3) << 20) - 1));

  std::vector<WideNode<4>, HugePageAllocator<WideNode<4>>> small(3);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % alignof(WideNode<4>), 0u);
  small.resize(10000);  // 1.2 MiB: moves to a huge-page block
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % HugePageAllocator<int>::kHugePage, 0u);
}

}  // namespace
}  // namespace geods::bvh
