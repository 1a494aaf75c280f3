#pragma once
// std::vector storage mapped before it is written (detail::prefault): for the
// large arrays a build fills once, where a page fault per 4 KiB page costs more
// than the writes.
#include <cstddef>
#include <vector>

#include "geods/core/huge_page_allocator.hpp"

namespace geods::detail {

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
