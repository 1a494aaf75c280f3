#include "geods/core/huge_page_allocator.hpp"

#include "geods/core/parallel.hpp"

#include <algorithm>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace geods::detail {

void* allocate_huge_pages(std::size_t bytes, std::size_t alignment) {
  constexpr std::size_t kPage = 4096;
  const bool huge = bytes >= kHugePage / 2;  // rounding up wastes less than half
  const std::size_t align = huge ? kHugePage : std::max<std::size_t>(alignment, sizeof(void*));
  bytes = (bytes + align - 1) / align * align;  // aligned_alloc wants a multiple of the alignment
  void* p = std::aligned_alloc(align, bytes);
  if (!p) throw std::bad_alloc();
  if (!huge) return p;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  madvise(p, bytes, MADV_HUGEPAGE);  // advice only: failure leaves ordinary pages
#endif
  // One write per small page (which faults in the whole huge page where there is one), a
  // huge page per task: the fresh memory's contents are unspecified, so a zero changes nothing.
  auto* bytes_of = static_cast<volatile char*>(p);
  parallel_for(0, bytes / kPage, kHugePage / kPage, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) bytes_of[i * kPage] = 0;
  });
  return p;
}

}  // namespace geods::detail
