#pragma once
// An owning pointer to an array in huge-page memory (allocate_huge_pages) that
// frees it through free_huge_pages with its size, for arrays whose elements
// are written in place rather than kept in a std::vector.
#include <cstddef>
#include <memory>

#include "geods/core/huge_page_allocator.hpp"

namespace geods {

struct HugePageFree {
  std::size_t bytes = 0;
  void operator()(void* p) const { detail::free_huge_pages(p, bytes); }
};

template <typename T>
using HugePageArray = std::unique_ptr<T[], HugePageFree>;

/// Room for n elements of T (at least one), not constructed; touched as in
/// detail::allocate_huge_pages.
template <typename T>
HugePageArray<T> make_huge_page_array(std::size_t n, bool touched) {
  const std::size_t bytes = (n > 0 ? n : 1) * sizeof(T);
  return HugePageArray<T>(static_cast<T*>(detail::allocate_huge_pages(bytes, alignof(T), touched)),
                          HugePageFree{bytes});
}

}  // namespace geods
