#pragma once
// What nearest-neighbour queries ask for and return.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "geods/core/error.hpp"

namespace geods::spatial {

/// Index of "no point" in fixed-size result tables (fewer than k found).
inline constexpr std::uint32_t kNoIndex = std::numeric_limits<std::uint32_t>::max();

/// A point of the set (its index in the caller's array, or the id of an item
/// of a dynamic structure) and its squared distance.
template <typename T, typename Index = std::uint32_t>
struct Neighbor {
  Index index = std::numeric_limits<Index>::max();  // kNoIndex for std::uint32_t
  T squared_distance = std::numeric_limits<T>::infinity();

  /// The result order: by distance, ties by index (so results are deterministic).
  friend bool operator<(const Neighbor& a, const Neighbor& b) {
    return a.squared_distance < b.squared_distance ||
           (a.squared_distance == b.squared_distance && a.index < b.index);
  }
  friend bool operator==(const Neighbor&, const Neighbor&) = default;
};

/// A k-nearest-neighbour query.
struct KnnRequest {
  std::size_t k = 1;
  /// Approximation: the i-th reported distance is at most (1 + eps) times the
  /// true i-th nearest distance. 0 = exact.
  double eps = 0;
  /// Only points at Euclidean distance <= max_distance count.
  double max_distance = std::numeric_limits<double>::infinity();
};

/// Checks a request (k >= 1, eps finite and >= 0, max_distance >= 0) and
/// returns k; throws geods::Error whose message starts with `who`.
inline std::size_t check_request(const KnnRequest& request, const char* who) {
  if (request.k == 0) throw Error(std::string(who) + ": k must be >= 1");
  if (request.k > (std::size_t(1) << 32)) throw Error(std::string(who) + ": k is too large");
  if (!(request.eps >= 0) || std::isinf(request.eps))
    throw Error(std::string(who) + ": eps must be finite and >= 0, got " + format_number(request.eps));
  if (!(request.max_distance >= 0))
    throw Error(std::string(who) + ": max_distance must be >= 0, got " + format_number(request.max_distance));
  return request.k;
}

/// A Euclidean distance limit squared, in T; one beyond T's range means no limit.
template <typename T>
T squared_limit(double distance) {
  const double d2 = distance * distance;
  return d2 >= double(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::infinity() : T(d2);
}

/// The k best neighbours seen so far, sorted, in a caller-provided array of k
/// slots. k is small in practice, so insertion into a sorted array beats a heap.
template <typename T, typename Index = std::uint32_t>
class KnnResultSet {
 public:
  /// Accepts points with squared distance <= limit until k are found.
  KnnResultSet(Neighbor<T, Index>* slots, std::size_t k, T limit) : slots_(slots), k_(k), limit_(limit), worst_(limit) {}

  std::size_t size() const { return size_; }
  bool full() const { return size_ == k_; }
  /// The squared distance a new point must not exceed to be kept.
  T worst() const { return worst_; }

  void insert(Index index, T squared_distance) {
    const Neighbor<T, Index> candidate{index, squared_distance};
    std::size_t pos;
    if (size_ < k_) {
      if (!(squared_distance <= limit_)) return;
      pos = size_++;
    } else {
      if (!(candidate < slots_[k_ - 1])) return;
      pos = k_ - 1;
    }
    // Linear insertion from the back (k is small): lands after equal entries, like upper_bound.
    while (pos > 0 && candidate < slots_[pos - 1]) {
      slots_[pos] = slots_[pos - 1];
      --pos;
    }
    slots_[pos] = candidate;
    if (size_ == k_) worst_ = slots_[k_ - 1].squared_distance;
  }

  /// Marks the unused slots as "none" (kNoIndex, +inf).
  void finish() {
    for (std::size_t i = size_; i < k_; ++i) slots_[i] = Neighbor<T, Index>{};
  }

 private:
  Neighbor<T, Index>* slots_;
  std::size_t k_;
  std::size_t size_ = 0;
  T limit_;
  T worst_;  // limit_ until k are found, then the k-th distance (kept by insert)
};

}  // namespace geods::spatial
