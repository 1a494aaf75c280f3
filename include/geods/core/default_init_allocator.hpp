#pragma once
// An allocator adaptor whose vectors leave new elements default-initialized
// (trivial ones: not written) where the allocator A would value-initialize
// them: for arrays that a parallel fill writes right after they are sized, so
// that their pages are first touched by the filling threads instead of being
// zeroed on one thread first.
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace geods {

template <typename A>
struct DefaultInitAllocator : A {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<typename std::allocator_traits<A>::template rebind_alloc<U>>;
  };
  DefaultInitAllocator() = default;
  template <typename B>
  DefaultInitAllocator(const DefaultInitAllocator<B>& o) noexcept : A(o) {}  // NOLINT(google-explicit-constructor)

  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

}  // namespace geods
