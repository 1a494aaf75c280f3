#pragma once
// An immutable flat array that either owns its elements or views them in place
// (in a memory-mapped file, kept alive by a shared owner). Structures hold their
// node and index arrays in it, so that a loaded structure reads the file's pages
// directly: no parse, no copy. Element access costs what std::vector's does.
#include <cstddef>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace geods {

template <typename T>
class FlatArray {
  static_assert(std::is_trivially_copyable_v<T>, "FlatArray<T>: T is stored in files as is");

 public:
  using value_type = T;

  FlatArray() = default;
  /// Takes ownership of the elements.
  FlatArray(std::vector<T> elements)  // NOLINT(google-explicit-constructor): a vector is a FlatArray
      : owned_(std::move(elements)), data_(owned_.data()), size_(owned_.size()) {}
  /// Views `elements` in place; `owner` keeps their memory alive (a MappedFile).
  FlatArray(std::span<const T> elements, std::shared_ptr<const void> owner)
      : owner_(std::move(owner)), data_(elements.data()), size_(elements.size()) {}

  FlatArray(const FlatArray& o) : owned_(o.owned_), owner_(o.owner_), size_(o.size_) {
    data_ = owner_ ? o.data_ : owned_.data();
  }
  // Moving a vector keeps its buffer, so data_ stays valid.
  FlatArray(FlatArray&& o) noexcept
      : owned_(std::move(o.owned_)), owner_(std::move(o.owner_)), data_(o.data_), size_(o.size_) {
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
  bool mapped() const { return owner_ != nullptr; }
  /// Bytes of memory the array owns (0 when mapped).
  std::size_t owned_bytes() const { return owner_ ? 0 : size_ * sizeof(T); }
  /// A copy of the elements that the caller may change.
  std::vector<T> to_vector() const { return {begin(), end()}; }

 private:
  std::vector<T> owned_;
  std::shared_ptr<const void> owner_;
  const T* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace geods
