#pragma once
// The locator of Theorem 13: for every stored item id, which structure V_i
// holds it and in which slot, so Delete(W, d) finds d without searching the
// structures. The seed uses a balanced search tree T (O(log n) per lookup);
// an array indexed by id plays the same role in O(1). Rebuilding moves items
// to a new structure, and their entries are rewritten then, which the build's
// own O(B_V(2^j)) cost already covers (seed §7.2.3).
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

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

// Ids are dense and never reused, so the entries live in pages of kPageSize
// consecutive ids: a lookup is an array access, no hashing (a merge rewrites
// the entry of every item it moves). A page whose live entries fall below an
// eighth of those it ever held hands them to a hash map and frees itself, so
// the space stays O(live entries) however the deletions fall; later entries
// of its ids go to the map too. The page table covers the ids from
// `first_page_` on and grows as ids come in order. Ids below it (a locator set
// up for sparse ids) or far beyond its end (which would make it large for few
// entries, e.g. an id read from a corrupt file) go to the map as well, so the
// table holds O(ids handed out in order / kPageSize) slots.
// The map has two generations, so that growing never rehashes every entry in
// one call (a std::unordered_map rehash would be the slowest single insert of
// the worst-case variant): when `current_` is full it becomes `old_`, a map
// reserved for twice as many starts, and every entry added moves two over.
class Locator {
 public:
  Locator() = default;
  /// A locator for about `expected` entries of ids below `id_bound`, and later
  /// ids. If at least an eighth of those ids will have an entry, the page
  /// table covers them at once; else (sparse ids) their entries go to the map
  /// and the pages start at id_bound.
  Locator(std::size_t expected, Id id_bound) {
    const Id pages = id_bound / kPageSize + 1;
    if (id_bound / 8 <= Id(expected)) {
      pages_.resize(std::size_t(pages));
    } else {
      first_page_ = pages - 1;
      current_.reserve(expected);
    }
  }

  std::size_t size() const { return paged_ + current_.size() + old_.size(); }
  const Location* find(Id id) const {
    if (const PageSlot* slot = page_slot(id); slot && slot->page) {
      const Page& page = *slot->page;
      const std::size_t i = std::size_t(id) & kPageMask;
      return page.holds(i) ? &page.at[i] : nullptr;
    }
    if (current_.empty() && old_.empty()) return nullptr;
    if (const auto it = current_.find(id); it != current_.end()) return &it->second;
    if (const auto it = old_.find(id); it != old_.end()) return &it->second;
    return nullptr;
  }
  void set(Id id, Location location) {
    const Id p = id >> kPageBits;
    if (p - first_page_ >= pages_.size() && p >= first_page_ && p < far_page_) [[unlikely]] {
      if (p - first_page_ < 2 * Id(pages_.size()) + kPageTableSlack) {
        pages_.resize(std::size_t(p - first_page_ + 1));
      } else {
        far_page_ = p;  // and every page after it: the map
      }
    }
    PageSlot* slot = page_slot(id);
    if (slot && !slot->page && !slot->spilled) slot->page = std::make_unique<Page>();
    if (!slot || !slot->page) return map_set(id, location);
    Page& page = *slot->page;
    const std::size_t i = std::size_t(id) & kPageMask;
    if (!page.holds(i)) {
      page.used[i / 64] |= std::uint64_t(1) << (i % 64);
      ++page.live;
      ++page.held;
      ++paged_;
    }
    page.at[i] = location;
  }
  void erase(Id id) {
    if (PageSlot* slot = page_slot(id); slot && slot->page) {
      Page& page = *slot->page;
      const std::size_t i = std::size_t(id) & kPageMask;
      if (!page.holds(i)) return;
      page.used[i / 64] &= ~(std::uint64_t(1) << (i % 64));
      --page.live;
      --paged_;
      if (8 * page.live < page.held) spill(*slot, id >> kPageBits);
      return;
    }
    if (current_.erase(id) == 0) old_.erase(id);
  }
  /// After mass deletion: if the hash map is more than four times larger than
  /// its entries need, starts moving them to one of the right size (a
  /// generation change like growing); set() and migrate() move them over, and
  /// the old map's memory is returned once it is empty. (Pages are returned as
  /// their entries die, in erase().)
  void shrink() {
    if (!old_.empty() || capacity() <= 4.0 * double(current_.size() + 16)) return;
    old_ = std::move(current_);
    current_ = Map();
    current_.reserve(2 * (old_.size() + 1));
    migrate(0);
  }
  /// Moves up to `count` entries of the map's old generation over; returns how many.
  std::size_t migrate(std::size_t count) {
    std::size_t moved = 0;
    for (; moved < count && !old_.empty(); ++moved) current_.insert(old_.extract(old_.begin()));
    if (old_.empty() && old_.bucket_count() > 1) old_ = Map();  // frees the old bucket array
    return moved;
  }
  /// Entries still in the map's old generation.
  std::size_t migrating() const { return old_.size(); }
  /// Entries in the hash map (from pages that lost most of theirs).
  std::size_t spilled() const { return current_.size() + old_.size(); }

  template <typename F>
  void for_each(const F& f) const {
    for (std::size_t p = 0; p < pages_.size(); ++p) {
      if (!pages_[p].page) continue;
      const Page& page = *pages_[p].page;
      for (std::size_t i = 0; i < kPageSize; ++i)
        if (page.holds(i)) f((first_page_ + p) * kPageSize + i, page.at[i]);
    }
    for (const auto& [id, location] : current_) f(id, location);
    for (const auto& [id, location] : old_) f(id, location);
  }

  /// Heap bytes, about: the page table, the pages, the map's buckets and one node per map entry.
  std::size_t bytes() const {
    std::size_t pages = 0;
    for (const PageSlot& slot : pages_) pages += slot.page ? 1 : 0;
    return pages_.capacity() * sizeof(PageSlot) + pages * sizeof(Page) +
           (current_.bucket_count() + old_.bucket_count()) * sizeof(void*) +
           spilled() * (sizeof(std::pair<const Id, Location>) + 2 * sizeof(void*));
  }

 private:
  static constexpr std::size_t kPageBits = 12;
  static constexpr std::size_t kPageSize = std::size_t(1) << kPageBits;
  static constexpr std::size_t kPageMask = kPageSize - 1;
  // An id this many pages past twice the table's end is far: to the map.
  static constexpr Id kPageTableSlack = 64;
  struct Page {
    std::array<Location, kPageSize> at;
    std::array<std::uint64_t, kPageSize / 64> used{};  // which ids have an entry
    std::uint32_t live = 0;                            // entries now
    std::uint32_t held = 0;                            // entries ever set
    bool holds(std::size_t i) const { return (used[i / 64] >> (i % 64)) & 1; }
  };
  struct PageSlot {
    std::unique_ptr<Page> page;
    bool spilled = false;  // its entries went to the map (and later ones go there)
  };
  using Map = std::unordered_map<Id, Location>;

  // The table's slot of id's page, or nullptr if the page table does not cover
  // it. (Below first_page_ the difference wraps around to a large number; the
  // table never reaches far_page_.)
  const PageSlot* page_slot(Id id) const {
    const Id k = (id >> kPageBits) - first_page_;
    return k < pages_.size() ? &pages_[std::size_t(k)] : nullptr;
  }
  PageSlot* page_slot(Id id) { return const_cast<PageSlot*>(std::as_const(*this).page_slot(id)); }

  // Moves the live entries of page p (in `slot`) to the map and frees the page.
  void spill(PageSlot& slot, Id p) {
    std::unique_ptr<Page> page = std::move(slot.page);
    slot.spilled = true;
    paged_ -= page->live;
    for (std::size_t w = 0; w < page->used.size(); ++w)
      for (std::uint64_t bits = page->used[w]; bits != 0; bits &= bits - 1) {
        const std::size_t i = w * 64 + std::size_t(std::countr_zero(bits));
        map_set(p * kPageSize + i, page->at[i]);
      }
  }

  void map_set(Id id, Location location) {
    if (!old_.empty()) old_.erase(id);
    if (current_.find(id) == current_.end() && double(current_.size() + 1) > capacity()) grow();
    current_.insert_or_assign(id, location);
    migrate(2);
  }

  double capacity() const { return double(current_.bucket_count()) * double(current_.max_load_factor()); }

  void grow() {
    while (!old_.empty()) current_.insert(old_.extract(old_.begin()));  // only if map_set() was outpaced
    old_ = std::move(current_);
    current_ = Map();
    current_.reserve(2 * (old_.size() + 1));
  }

  std::vector<PageSlot> pages_;  // pages_[k]: page p = first_page_ + k, ids [p * kPageSize, (p + 1) * kPageSize)
  Id first_page_ = 0;
  Id far_page_ = std::numeric_limits<Id>::max();  // pages from here on: the map
  std::size_t paged_ = 0;                         // entries in pages
  Map current_, old_;
};

}  // namespace geods::dynamic
