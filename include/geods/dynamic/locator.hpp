#pragma once
// The locator of Theorem 13: for every stored item id, which structure V_i
// holds it and in which slot, so Delete(W, d) finds d without searching the
// structures. The seed uses a balanced search tree T (O(log n) per lookup);
// a hash map plays the same role in O(1) expected. Rebuilding moves items to
// a new structure, and their entries are rewritten then, which the build's
// own O(B_V(2^j)) cost already covers (seed §7.2.3).
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace geods::dynamic {

/// Item ids: handed out by insert, never reused.
using Id = std::uint64_t;
inline constexpr Id kNoId = std::numeric_limits<Id>::max();

/// Where an item lives: the level i of its structure (2^i slots), the
/// structure's serial number (a level may hold several in the worst-case
/// variant) and the slot inside it.
struct Location {
  std::uint32_t level = 0;
  std::uint32_t serial = 0;
  std::uint32_t slot = 0;
};

class Locator {
 public:
  Locator() = default;
  explicit Locator(std::size_t expected) { map_.reserve(expected); }

  std::size_t size() const { return map_.size(); }
  const Location* find(Id id) const {
    const auto it = map_.find(id);
    return it == map_.end() ? nullptr : &it->second;
  }
  void set(Id id, Location location) { map_.insert_or_assign(id, location); }
  void erase(Id id) { map_.erase(id); }

  template <typename F>
  void for_each(const F& f) const {
    for (const auto& [id, location] : map_) f(id, location);
  }

  /// Heap bytes, about: buckets and one node per entry.
  std::size_t bytes() const {
    return map_.bucket_count() * sizeof(void*) + map_.size() * (sizeof(std::pair<const Id, Location>) + 2 * sizeof(void*));
  }

 private:
  std::unordered_map<Id, Location> map_;
};

}  // namespace geods::dynamic
