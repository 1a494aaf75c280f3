#pragma once
// The locator of Theorem 13: for every stored item id, which structure V_i
// holds it and in which slot, so Delete(W, d) finds d without searching the
// structures. The seed uses a balanced search tree T (O(log n) per lookup);
// a hash map plays the same role in O(1) expected. Rebuilding moves items to
// a new structure, and their entries are rewritten then, which the build's
// own O(B_V(2^j)) cost already covers (seed §7.2.3).
#include <cstddef>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

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

// Two generations of hash maps, so that growing never rehashes every entry in
// one call (a std::unordered_map rehash would be the slowest single insert of
// the worst-case variant): when `current_` is full it becomes `old_`, a map
// reserved for twice as many starts, and every set() moves two entries over.
class Locator {
 public:
  Locator() = default;
  explicit Locator(std::size_t expected) { current_.reserve(expected); }

  std::size_t size() const { return current_.size() + old_.size(); }
  const Location* find(Id id) const {
    if (const auto it = current_.find(id); it != current_.end()) return &it->second;
    if (const auto it = old_.find(id); it != old_.end()) return &it->second;
    return nullptr;
  }
  void set(Id id, Location location) {
    if (!old_.empty()) old_.erase(id);
    if (current_.find(id) == current_.end() && double(current_.size() + 1) > capacity()) grow();
    current_.insert_or_assign(id, location);
    migrate(2);
  }
  /// After mass deletion: if the table is more than four times larger than its
  /// entries need, starts moving them to one of the right size (a generation
  /// change like growing); set() and migrate() move them over, and the old
  /// table's memory is returned once it is empty.
  void shrink() {
    if (!old_.empty() || capacity() <= 4.0 * double(size() + 16)) return;
    old_ = std::move(current_);
    current_ = Map();
    current_.reserve(2 * (old_.size() + 1));
    migrate(0);
  }
  /// Moves up to `count` entries of the old generation over; returns how many.
  std::size_t migrate(std::size_t count) {
    std::size_t moved = 0;
    for (; moved < count && !old_.empty(); ++moved) current_.insert(old_.extract(old_.begin()));
    if (old_.empty() && old_.bucket_count() > 1) old_ = Map();  // frees the old bucket array
    return moved;
  }
  /// Entries still in the old generation.
  std::size_t migrating() const { return old_.size(); }
  void erase(Id id) {
    if (current_.erase(id) == 0) old_.erase(id);
  }

  template <typename F>
  void for_each(const F& f) const {
    for (const auto& [id, location] : current_) f(id, location);
    for (const auto& [id, location] : old_) f(id, location);
  }

  /// Heap bytes, about: buckets and one node per entry.
  std::size_t bytes() const {
    return (current_.bucket_count() + old_.bucket_count()) * sizeof(void*) +
           size() * (sizeof(std::pair<const Id, Location>) + 2 * sizeof(void*));
  }

 private:
  using Map = std::unordered_map<Id, Location>;

  double capacity() const { return double(current_.bucket_count()) * double(current_.max_load_factor()); }

  void grow() {
    while (!old_.empty()) current_.insert(old_.extract(old_.begin()));  // only if set() was outpaced
    old_ = std::move(current_);
    current_ = Map();
    current_.reserve(2 * (old_.size() + 1));
  }

  Map current_, old_;
};

}  // namespace geods::dynamic
