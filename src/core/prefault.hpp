#pragma once
// std::vector storage mapped before it is written (detail::prefault): for the
// large arrays a build fills once, where a page fault per 4 KiB page costs more
// than the writes.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/parallel.hpp"

namespace geods::detail {

/// v.reserve(size), then its storage prefaulted.
template <class T>
void reserve_prefaulted(std::vector<T>& v, std::size_t size) {
  v.reserve(size);
  prefault(v.data(), v.capacity() * sizeof(T));
}

/// prefault() by all threads, each a run of whole 2 MiB pieces: for memory that
/// the calling thread alone would otherwise fault in, page by page.
inline void prefault_in_parallel(const void* p, std::size_t bytes) {
  const auto begin = reinterpret_cast<std::uintptr_t>(p), end = begin + bytes;
  const std::uintptr_t first = begin & ~(kHugePage - 1);
  parallel_for(0, (end - first + kHugePage - 1) / kHugePage, 1, [&](std::size_t a, std::size_t b) {
    const std::uintptr_t lo = std::max<std::uintptr_t>(begin, first + a * kHugePage);
    const std::uintptr_t hi = std::min<std::uintptr_t>(end, first + b * kHugePage);
    prefault(reinterpret_cast<const void*>(lo), hi - lo);
  });
}

/// v.reserve(size), its storage prefaulted by all threads (prefault_in_parallel): for
/// an array that resize() is about to write on one thread, or threads to fill at once.
template <class T>
void reserve_prefaulted_in_parallel(std::vector<T>& v, std::size_t size) {
  v.reserve(size);
  prefault_in_parallel(v.data(), v.capacity() * sizeof(T));
}

/// v.reserve(size) for an array that fills from the front to a size not known in advance: its
/// storage advised to use huge pages (a fault per 2 MiB as it fills), and the small pages before
/// the first 2 MiB boundary, which would fault one by one, mapped now.
template <class T>
void reserve_growing(std::vector<T>& v, std::size_t size) {
  v.reserve(size);
  geods::advise_huge_pages(v);
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const std::size_t to_boundary = ((begin + kHugePage - 1) & ~(kHugePage - 1)) - begin;
  prefault(v.data(), std::min(v.capacity() * sizeof(T), to_boundary));
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
