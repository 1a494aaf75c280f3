#pragma once
// Mapping the fresh pages of a large array before it is written: one madvise
// call instead of a page fault per 4 KiB page, each of which is costly (several
// microseconds on a virtual machine, where the fault goes through the
// hypervisor). Advice only: where it fails, or off Linux, the pages fault in
// as they are first written.
#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace geods::detail {

/// Maps the whole pages of [data, data + bytes) writable, if they are at least 64 KiB.
inline void prefault(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  constexpr std::uintptr_t kPage = 4096;
  const auto first = (reinterpret_cast<std::uintptr_t>(data) + kPage - 1) & ~(kPage - 1);
  const auto last = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kPage - 1);
  if (last < first + (std::uintptr_t(1) << 16)) return;
#if defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  const auto huge_first = (first + kHuge - 1) & ~(kHuge - 1), huge_last = last & ~(kHuge - 1);
  if (huge_last > huge_first) madvise(reinterpret_cast<void*>(huge_first), huge_last - huge_first, MADV_HUGEPAGE);
#endif
  madvise(reinterpret_cast<void*>(first), last - first, MADV_POPULATE_WRITE);
#else
  (void)data, (void)bytes;
#endif
}

/// v.reserve(size), then its storage prefaulted.
template <class T>
void reserve_prefaulted(std::vector<T>& v, std::size_t size) {
  v.reserve(size);
  prefault(v.data(), v.capacity() * sizeof(T));
}

/// std::vector<T>(size, value), its storage prefaulted before it is filled.
template <class T>
std::vector<T> prefaulted_vector(std::size_t size, const T& value = T()) {
  std::vector<T> v;
  reserve_prefaulted(v, size);
  v.assign(size, value);
  return v;
}

}  // namespace geods::detail
