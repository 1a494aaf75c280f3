#include "geods/core/huge_page_allocator.hpp"

#include "geods/core/parallel.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace geods::detail {

namespace {

// The whole small pages of [p, p + bytes): their start and their length (0 if none).
[[maybe_unused]] std::pair<void*, std::size_t> whole_pages(const void* p, std::size_t bytes) {
  constexpr std::uintptr_t kPage = 4096;
  const auto first = (reinterpret_cast<std::uintptr_t>(p) + kPage - 1) & ~(kPage - 1);
  const auto last = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kPage - 1);
  return {reinterpret_cast<void*>(first), last > first ? last - first : 0};
}

}  // namespace

void advise_huge_pages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const auto [first, length] = whole_pages(p, bytes);
  if (length >= kHugePage) madvise(first, length, MADV_HUGEPAGE);  // advice only: failure leaves ordinary pages
#else
  (void)p, (void)bytes;
#endif
}

void prefault(const void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  const auto [first, length] = whole_pages(p, bytes);
  if (length < (std::size_t(1) << 16)) return;
  advise_huge_pages(first, length);
  madvise(first, length, MADV_POPULATE_WRITE);
#else
  (void)p, (void)bytes;
#endif
}

void* allocate_huge_pages(std::size_t bytes, std::size_t alignment, bool touched) {
  constexpr std::size_t kPage = 4096;
  const bool huge = bytes >= kHugePage / 2;  // rounding up wastes less than half
  const std::size_t align = huge ? kHugePage : std::max<std::size_t>(alignment, sizeof(void*));
  bytes = (bytes + align - 1) / align * align;  // aligned_alloc wants a multiple of the alignment
  void* p = std::aligned_alloc(align, bytes);
  if (!p) throw std::bad_alloc();
  if (!huge) return p;
  advise_huge_pages(p, bytes);
  if (!touched) return p;
  // One write per small page (which faults in the whole huge page where there is one), a
  // huge page per task: the fresh memory's contents are unspecified, so a zero changes nothing.
  auto* bytes_of = static_cast<volatile char*>(p);
  parallel_for(0, bytes / kPage, kHugePage / kPage, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) bytes_of[i * kPage] = 0;
  });
  return p;
}

}  // namespace geods::detail
