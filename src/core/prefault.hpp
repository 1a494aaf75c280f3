#pragma once
// std::vector storage mapped before it is written (detail::prefault): for the
// large arrays a build fills once, where a page fault per 4 KiB page costs more
// than the writes.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geods/core/huge_page_allocator.hpp"

namespace geods::detail {

/// v.reserve(size), then its storage prefaulted.
template <class T>
void reserve_prefaulted(std::vector<T>& v, std::size_t size) {
  v.reserve(size);
  prefault(v.data(), v.capacity() * sizeof(T));
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
