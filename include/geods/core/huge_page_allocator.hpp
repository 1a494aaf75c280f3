#pragma once
// A std::vector allocator for large arrays that queries read at random (the
// wide nodes and triangle groups of bvh::TriangleBvh): blocks of 1 MiB or more are 2 MiB
// aligned (and sized) and, on Linux, advised to use transparent huge pages, so that an
// incoherent ray does not pay a TLB miss (a page walk) on top of each cache
// miss. Smaller blocks and other systems get ordinary aligned memory.
#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace geods {

template <typename T>
class HugePageAllocator {
 public:
  using value_type = T;
  static constexpr std::size_t kHugePage = std::size_t(2) << 20;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    std::size_t bytes = n * sizeof(T);
    const bool huge = bytes >= kHugePage / 2;  // rounding up wastes less than half
    const std::size_t align = huge ? kHugePage : std::max<std::size_t>(alignof(T), sizeof(void*));
    bytes = (bytes + align - 1) / align * align;  // aligned_alloc wants a multiple of the alignment
    void* p = std::aligned_alloc(align, bytes);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (huge) madvise(p, bytes, MADV_HUGEPAGE);  // advice only: failure leaves ordinary pages
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) { std::free(p); }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
};

}  // namespace geods
