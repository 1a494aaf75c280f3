#pragma once
// A std::vector allocator for large arrays that queries read at random (the
// wide nodes and triangle groups of bvh::TriangleBvh): blocks of 1 MiB or more are 2 MiB
// aligned (and sized), on Linux advised to use transparent huge pages, so that an
// incoherent ray does not pay a TLB miss (a page walk) on top of each cache
// miss, and first touched by all threads, so that the kernel's zeroing of fresh
// pages is shared instead of falling on whichever thread writes the array first.
// Smaller blocks and other systems get ordinary aligned memory.
// advise_huge_pages() asks the same for a std::vector's storage (a hint: the
// kernel may be set to use them only where asked; the pages are touched later).
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

namespace geods {

namespace detail {
inline constexpr std::size_t kHugePage = std::size_t(2) << 20;
/// `bytes` of memory as described above; throws std::bad_alloc. With touched = false
/// the pages are left for the caller's first writes to fault in (for arrays whose
/// elements are written in parallel, or of which only a part is ever written).
void* allocate_huge_pages(std::size_t bytes, std::size_t alignment, bool touched = true);
/// Frees a block of allocate_huge_pages(bytes, ...). Blocks of 1 MiB or more are
/// kept (256 MiB in all, the oldest freed first) for the next allocation of the
/// same size, which then finds its pages already faulted in.
void free_huge_pages(void* p, std::size_t bytes);
/// Advises transparent huge pages for the whole small pages of [p, p + bytes) (2 MiB or more).
void advise_huge_pages(void* p, std::size_t bytes);
/// Maps the whole small pages of [p, p + bytes) writable before they are written, if they
/// are 64 KiB or more: huge pages advised, then one MADV_POPULATE_WRITE call instead of
/// a page fault per 4 KiB page (several microseconds each on a virtual machine). Advice
/// only: where it fails, or off Linux, the pages fault in as they are first written.
void prefault(const void* p, std::size_t bytes);
}  // namespace detail

/// Asks for transparent huge pages for v's storage (its capacity), before
/// it is first written: a fresh 2 MiB page costs one fault where 512 small
/// ones cost 512.
template <typename T, typename A>
void advise_huge_pages(const std::vector<T, A>& v) {
  detail::advise_huge_pages(const_cast<T*>(v.data()), v.capacity() * sizeof(T));
}

template <typename T>
class HugePageAllocator {
 public:
  using value_type = T;
  static constexpr std::size_t kHugePage = detail::kHugePage;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(detail::allocate_huge_pages(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, std::size_t n) { detail::free_huge_pages(p, n * sizeof(T)); }

  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
};

}  // namespace geods
