#pragma once
// An immutable flat array that either owns its elements or views them in place
// (in a memory-mapped file, kept alive by a shared owner). Structures hold their
// node and index arrays in it, so that a loaded structure reads the file's pages
// directly: no parse, no copy. Element access costs what std::vector's does.
// A vector with another allocator (huge pages) can be moved in too; it is then
// held behind the shared owner, and copies of the array share it.
#include <algorithm>
#include <concepts>
#include <cstddef>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/core/bytewise.hpp"

namespace geods {

template <typename T>
class FlatArray {
  static_assert(is_bytewise_v<T>, "FlatArray<T>: T is stored in files as is");

 public:
  using value_type = T;

  FlatArray() = default;
  /// Takes ownership of the elements.
  FlatArray(std::vector<T> elements)  // NOLINT(google-explicit-constructor): a vector is a FlatArray
      : owned_(std::move(elements)), data_(owned_.data()), size_(owned_.size()) {}
  /// Takes ownership of elements allocated otherwise (HugePageAllocator...).
  template <typename Allocator>
    requires(!std::is_same_v<Allocator, std::allocator<T>>)
  FlatArray(std::vector<T, Allocator> elements) {  // NOLINT(google-explicit-constructor)
    auto held = std::make_shared<const std::vector<T, Allocator>>(std::move(elements));
    data_ = held->data();
    size_ = held->size();
    owner_ = std::move(held);
  }
  /// Views `elements` in place; `owner` keeps their memory alive (a MappedFile).
  FlatArray(std::span<const T> elements, std::shared_ptr<const void> owner)
      : owner_(std::move(owner)), data_(elements.data()), size_(elements.size()), mapped_(true) {}

  FlatArray(const FlatArray& o) : owned_(o.owned_), owner_(o.owner_), size_(o.size_), mapped_(o.mapped_) {
    data_ = owner_ ? o.data_ : owned_.data();
  }
  // Moving a vector keeps its buffer, so data_ stays valid.
  FlatArray(FlatArray&& o) noexcept
      : owned_(std::move(o.owned_)), owner_(std::move(o.owner_)), data_(o.data_), size_(o.size_), mapped_(o.mapped_) {
    o.data_ = nullptr;
    o.size_ = 0;
  }
  FlatArray& operator=(FlatArray o) noexcept {
    swap(o);
    return *this;
  }
  void swap(FlatArray& o) noexcept {
    owned_.swap(o.owned_);
    owner_.swap(o.owner_);
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(mapped_, o.mapped_);
  }

  const T* data() const { return data_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  const T& front() const { return data_[0]; }
  const T& back() const { return data_[size_ - 1]; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  std::span<const T> span() const { return {data_, size_}; }
  operator std::span<const T>() const { return span(); }  // NOLINT(google-explicit-constructor)

  /// True when the elements live in a mapped file rather than in memory of their own.
  bool mapped() const { return mapped_; }
  /// Bytes of memory the array owns (0 when mapped).
  std::size_t owned_bytes() const { return mapped_ ? 0 : size_ * sizeof(T); }
  /// A copy of the elements that the caller may change.
  std::vector<T> to_vector() const { return {begin(), end()}; }
  /// The elements as a vector the caller may change, leaving the array empty:
  /// moved out when the array owns them in a std::vector, copied when they are
  /// viewed (so a structure that changes after loading copies once).
  std::vector<T> take_vector() && {
    std::vector<T> elements = owner_ || mapped_ ? to_vector() : std::move(owned_);
    *this = FlatArray();
    return elements;
  }

  /// Element-wise equality, whether owned or viewed.
  friend bool operator==(const FlatArray& a, const FlatArray& b)
    requires std::equality_comparable<T>
  {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  }

 private:
  std::vector<T> owned_;
  std::shared_ptr<const void> owner_;
  const T* data_ = nullptr;
  std::size_t size_ = 0;
  bool mapped_ = false;
};

}  // namespace geods
