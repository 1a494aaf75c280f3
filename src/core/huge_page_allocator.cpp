#include "geods/core/huge_page_allocator.hpp"

#include "geods/core/parallel.hpp"

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#else
#define ASAN_POISON_MEMORY_REGION(p, n) ((void)(p), (void)(n))
#define ASAN_UNPOISON_MEMORY_REGION(p, n) ((void)(p), (void)(n))
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

// Blocks of 1 MiB or more are rounded to whole huge pages: their size as allocated (and kept).
std::size_t rounded_size(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }
bool is_huge(std::size_t bytes) { return bytes >= kHugePage / 2; }  // rounding up wastes less than half

// Freed huge blocks kept for the next allocation of the same size, most recent
// last, up to kCacheBytes in all. Returned to the system, they would be faulted
// in again by the next build: on a virtual machine that reports free memory to
// its host, the host takes the pages back within seconds, and refaulting them
// doubled the time of the later builds in one process (docs/bvh.md). Under
// AddressSanitizer a kept block is poisoned, so a use after free is still caught.
struct BlockCache {
  static constexpr std::size_t kCacheBytes = std::size_t(256) << 20;
  std::mutex mutex;
  std::vector<std::pair<void*, std::size_t>> blocks;
  std::size_t bytes = 0;
};
BlockCache& block_cache() {
  static BlockCache* cache = new BlockCache;  // never destroyed: frees may come from static destructors
  return *cache;
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
  const bool huge = is_huge(bytes);
  const std::size_t align = huge ? kHugePage : std::max<std::size_t>(alignment, sizeof(void*));
  bytes = huge ? rounded_size(bytes) : (bytes + align - 1) / align * align;  // aligned_alloc: a multiple of align
  if (huge) {
    BlockCache& cache = block_cache();
    const std::lock_guard lock(cache.mutex);
    for (auto b = cache.blocks.rbegin(); b != cache.blocks.rend(); ++b) {
      if (b->second != bytes) continue;
      void* p = b->first;  // already advised, and faulted in where it was written
      cache.bytes -= bytes;
      cache.blocks.erase(std::next(b).base());
      ASAN_UNPOISON_MEMORY_REGION(p, bytes);
      return p;
    }
  }
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

void free_huge_pages(void* p, std::size_t bytes) {
  if (!p) return;
  if (!is_huge(bytes)) {
    std::free(p);
    return;
  }
  bytes = rounded_size(bytes);
  ASAN_POISON_MEMORY_REGION(p, bytes);
  BlockCache& cache = block_cache();
  std::vector<std::pair<void*, std::size_t>> evicted;
  {
    const std::lock_guard lock(cache.mutex);
    cache.blocks.emplace_back(p, bytes);
    cache.bytes += bytes;
    std::size_t n = 0;  // the oldest blocks go first
    while (cache.bytes > BlockCache::kCacheBytes) {
      cache.bytes -= cache.blocks[n].second;
      evicted.push_back(cache.blocks[n++]);
    }
    cache.blocks.erase(cache.blocks.begin(), cache.blocks.begin() + std::ptrdiff_t(n));
  }
  for (const auto& [q, size] : evicted) {
    ASAN_UNPOISON_MEMORY_REGION(q, size);
    std::free(q);
  }
}

}  // namespace geods::detail
