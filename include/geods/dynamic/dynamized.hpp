#pragma once
// Generic dynamization of a static structure (seed §7): Dynamized<S> stores
// items in structures V_i of S with 2^i slots each and supports Insert and
// Delete on top of S's build / extract / weak_delete.
//
//  - Variant::amortized, the binary structure (Theorem 11): one V_i per set
//    bit of the slot count; Insert builds V_j from the new item and
//    V_0 .. V_{j-1}, like a carry in binary addition. O(log n / n · B_V(n))
//    amortized per insert.
//  - Variant::worst_case (Theorem 14): a level may hold up to three V_i;
//    when it holds two, their union starts being built as a V_{i+1} in steps
//    (S::Builder) spread over the next 2^i inserts, while the two keep
//    answering queries. Each insert advances every such build: 8 of its
//    items are gathered, or about estimated_work / 2^(i-1) units of the
//    build are done, or 8 locator entries of its items are rewritten
//    (deletions meanwhile go to both copies); then it replaces the two. So
//    no insert pays for a whole build or a whole relocation: O(log^2 n) per
//    insert for the k-d tree. If a level fills up anyway (the estimate was short) the build is
//    finished on the spot, and counted in stats().forced_builds.
//  - Delete (Theorems 12, 13): the locator (locator.hpp) finds the V_i and
//    slot of an id, weak_delete hides it. Dead slots stay in their structure
//    (and move with it through merges, so every V_i keeps exactly 2^i slots)
//    until more than max_dead_fraction of all slots are dead (the seed's 1/2):
//    then everything is rebuilt from the live items alone, freeing the rest.
//
// Ids are handed out by insert (0, 1, 2, ...) and never reused; removing an
// id that is not stored (never inserted, or already removed) is an error.
#include <algorithm>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/dynamic/locator.hpp"
#include "geods/dynamic/static_structure.hpp"

namespace geods::dynamic {

enum class Variant { amortized, worst_case };

struct DynamizeOptions {
  Variant variant = Variant::amortized;
  /// Rebuild everything when more than this fraction of the stored slots is
  /// weakly deleted; in (0, 1). Theorem 12 uses 1/2: space stays O(S_V(live)).
  double max_dead_fraction = 0.5;
};

struct DynamizedStats {
  std::size_t live = 0;
  std::size_t dead = 0;                 // weakly deleted slots still stored
  std::size_t structures = 0;           // complete V_i
  std::size_t building = 0;             // V_i under construction (worst-case variant)
  std::vector<std::size_t> per_level;   // complete structures on level i (2^i slots each)
  std::size_t rebuilds = 0;             // global reconstructions so far
  std::size_t forced_builds = 0;        // worst case: builds finished early
  std::size_t locator_bytes = 0;
};

namespace detail {
template <typename S>
struct BuilderOf {
  using type = std::monostate;
};
template <SteppedBuild S>
struct BuilderOf<S> {
  using type = typename S::Builder;
};
}  // namespace detail

template <StaticStructure S>
class Dynamized {
 public:
  using Item = typename S::Item;

  explicit Dynamized(DynamizeOptions options = {}) : options_(options) {
    if (options.variant == Variant::worst_case && !SteppedBuild<S>)
      throw Error("Dynamized: the worst-case variant needs a structure whose build runs in steps");
    if (!(options.max_dead_fraction > 0 && options.max_dead_fraction < 1))
      throw Error("Dynamized: max_dead_fraction must lie in (0, 1), got " + std::to_string(options.max_dead_fraction));
  }

  const DynamizeOptions& options() const { return options_; }
  /// Live items.
  std::size_t size() const { return locator_.size(); }
  /// Weakly deleted slots still stored.
  std::size_t dead() const { return dead_; }
  bool contains(Id id) const { return locator_.find(id) != nullptr; }

  /// The structure holding id and its slot there, or {nullptr, 0}.
  std::pair<const S*, std::size_t> locate(Id id) const {
    const Location* at = locator_.find(id);
    if (!at) return {nullptr, 0};
    const Part* copy = const_cast<Dynamized*>(this)->relocating(*at);
    return {copy ? &copy->structure : &part(*at).structure, at->slot};
  }

  /// Inserts one item; returns its new id.
  Id insert(Item item) {
    const Id id = next_id_++;
    if (options_.variant == Variant::amortized) {
      insert_amortized(std::move(item), id);
    } else {
      insert_worst_case(std::move(item), id);
    }
    return id;
  }

  /// Inserts items in order; returns their ids. A batch at least as large as
  /// what is stored is one Build(W, D) over everything (Lemma 10) instead.
  std::vector<Id> insert(std::vector<Item> items) {
    std::vector<Id> ids(items.size());
    if (!items.empty() && items.size() >= size() + dead_) {
      for (Id& id : ids) id = next_id_++;
      auto [all, all_ids] = live_items();
      all.insert(all.end(), std::make_move_iterator(items.begin()), std::make_move_iterator(items.end()));
      all_ids.insert(all_ids.end(), ids.begin(), ids.end());
      build_all(std::move(all), std::move(all_ids));
      return ids;
    }
    for (std::size_t i = 0; i < items.size(); ++i) ids[i] = insert(std::move(items[i]));
    return ids;
  }

  /// Deletes the items; all ids are checked first, so on error nothing is
  /// removed. Throws geods::Error for an id not stored or given twice.
  void remove(std::span<const Id> ids)
    requires WeakDeletable<S>
  {
    for (Id id : ids)
      if (!contains(id))
        throw Error("remove: id " + std::to_string(id) + " is not stored (never inserted, or removed already)");
    std::vector<Id> sorted(ids.begin(), ids.end());
    std::sort(sorted.begin(), sorted.end());
    if (const auto twice = std::adjacent_find(sorted.begin(), sorted.end()); twice != sorted.end())
      throw Error("remove: id " + std::to_string(*twice) + " is given twice");
    for (Id id : ids) {
      const Location at = *locator_.find(id);
      if (Part* copy = relocating(at)) {
        // Already moved to a V_{i+1} being relocated: delete it there and in its source, which still answers queries.
        const std::size_t half = copy->structure.size() / 2;
        kill(levels_[at.level - 1][at.slot < half ? 0 : 1], at.slot % half);
        kill(*copy, at.slot);
      } else {
        kill(part(at), at.slot);
      }
      ++dead_;
      locator_.erase(id);
    }
    if (double(dead_) > options_.max_dead_fraction * double(size() + dead_)) rebuild();
  }
  void remove(Id id)
    requires WeakDeletable<S>
  {
    remove(std::span<const Id>(&id, 1));
  }

  /// Global reconstruction (Theorem 12): rebuilds the binary structure from
  /// the live items; dead slots, pending builds and their memory are freed.
  void rebuild() {
    auto [items, ids] = live_items();
    build_all(std::move(items), std::move(ids));
    ++rebuilds_;
  }

  /// Calls f(structure, ids) for every complete structure, largest first, where
  /// ids[slot] is the id in that slot (kNoId if deleted). Queries combine the
  /// answers; largest first, a k-nearest search finds good candidates early and
  /// then prunes most small structures at their root.
  template <typename F>
  void for_each(const F& f) const {
    for (auto level = levels_.rbegin(); level != levels_.rend(); ++level)
      for (const Part& p : *level) f(p.structure, std::span<const Id>(p.ids));
  }

  /// Every live item with its id (Extract(W, D)).
  std::pair<std::vector<Item>, std::vector<Id>> live_items() const {
    std::pair<std::vector<Item>, std::vector<Id>> out;
    out.first.reserve(size());
    out.second.reserve(size());
    for_each([&](const S& s, std::span<const Id> ids) {
      std::vector<Item> items = s.extract();
      for (std::size_t slot = 0; slot < ids.size(); ++slot) {
        if (ids[slot] == kNoId) continue;
        out.first.push_back(std::move(items[slot]));
        out.second.push_back(ids[slot]);
      }
    });
    return out;
  }

  /// Checks the decomposition and the locator; throws geods::Error naming the
  /// first violation. Amortized: exactly one structure of 2^i slots per set
  /// bit i of the slot count (live + dead). Worst case: at most three
  /// structures of 2^i slots on level i, and a build in progress exactly on
  /// the levels holding two or more. Both: slot tables, dead counts, the
  /// locator is a bijection onto the live slots, the dead fraction is within
  /// bounds, and each structure's own validate() if it has one.
  void validate() const {
    auto fail = [](const std::string& what) { throw Error("Dynamized::validate: " + what); };
    std::size_t slots = 0, live = 0, dead = 0;
    for (std::size_t i = 0; i < levels_.size(); ++i) {
      const std::string where = "level " + std::to_string(i) + ": ";
      const std::size_t count = levels_[i].size();
      const bool pending = building(i);
      if (options_.variant == Variant::amortized) {
        if (count > 1 || pending) fail(where + "more than one structure");
      } else if (count > 3 || (count >= 2) != pending) {
        fail(where + std::to_string(count) + " structures and " + (pending ? "a" : "no") + " build in progress");
      }
      // Slots of the first two structures below `relocated` have moved to the V_{i+1} built from them.
      const Part* copy = pending ? building_[i]->result ? &*building_[i]->result : nullptr : nullptr;
      const std::size_t relocated = copy ? building_[i]->relocated : 0, half = std::size_t(1) << i;
      if (copy) check_part(*copy, 2 * half, relocated, fail, where + "structure being relocated: ");
      for (std::size_t k = 0; k < count; ++k) {
        const Part& p = levels_[i][k];
        const std::size_t moved = k < 2 ? std::clamp(relocated, k * half, (k + 1) * half) - k * half : 0;
        for (std::size_t slot = 0; slot < p.ids.size(); ++slot) {
          if (slot >= moved && p.ids[slot] != kNoId) {
            const Location* at = locator_.find(p.ids[slot]);
            if (!at || at->level != i || at->serial != p.serial || at->slot != slot)
              fail(where + "the locator does not point to id " + std::to_string(p.ids[slot]));
          }
          if (slot < moved) {
            const Id id = copy->ids[k * half + slot];
            const Location* at = id == kNoId ? nullptr : locator_.find(id);
            if (id != p.ids[slot] || (id != kNoId && (!at || at->level != i + 1 || at->serial != copy->serial ||
                                                      at->slot != k * half + slot)))
              fail(where + "a relocated slot does not match its source");
          }
        }
        check_part(p, half, half, fail, where);
        slots += p.ids.size();
        dead += p.dead;
        live += p.ids.size() - p.dead;
      }
    }
    if (live != locator_.size())
      fail(std::to_string(live) + " live slots but " + std::to_string(locator_.size()) + " locator entries");
    if (dead != dead_) fail("wrong total dead count");
    if (double(dead) > options_.max_dead_fraction * double(slots)) fail("too many dead slots");
    if (options_.variant == Variant::amortized)
      for (std::size_t i = 0; i < 64; ++i)
        if (((slots >> i) & 1) != (i < levels_.size() ? levels_[i].size() : 0))
          fail("the structures do not match the binary representation of " + std::to_string(slots));
  }

  DynamizedStats stats() const {
    DynamizedStats s;
    s.live = size();
    s.dead = dead_;
    for (std::size_t i = 0; i < levels_.size(); ++i) {
      s.per_level.push_back(levels_[i].size());
      s.structures += levels_[i].size();
      s.building += building(i) ? 1 : 0;
    }
    while (!s.per_level.empty() && s.per_level.back() == 0) s.per_level.pop_back();
    s.rebuilds = rebuilds_;
    s.forced_builds = forced_builds_;
    s.locator_bytes = locator_.bytes();
    return s;
  }

 private:
  struct Part {
    S structure;
    std::vector<Id> ids;  // slot -> id, kNoId once deleted
    std::uint32_t serial;
    std::size_t dead;
  };

  // A V_{i+1} under construction from the first two structures of level i, in
  // three phases spread over 2^i inserts: its items are gathered from the two
  // (2^(i-2) inserts), built (2^(i-1)), and their locator entries rewritten (2^(i-2)).
  struct Pending {
    std::vector<Item> items;                                     // being gathered
    std::optional<typename detail::BuilderOf<S>::type> builder;  // once gathered
    std::size_t work_per_insert = 0;
    std::optional<Part> result;  // once built; ids filled up to `relocated`
    std::size_t relocated = 0;
  };

  // Items gathered, and locator entries rewritten, per insert: 2^(i+1) slots in 2^(i-2) inserts.
  static constexpr std::size_t kSlotsPerInsert = 8;

  // Sizes, dead counts and the structure's own checks.
  template <typename Fail>
  static void check_part(const Part& p, std::size_t slots, std::size_t ids, const Fail& fail, const std::string& where) {
    if (p.structure.size() != slots || p.ids.size() != ids)
      fail(where + "a structure of " + std::to_string(p.structure.size()) + " slots");
    if (std::size_t(std::count(p.ids.begin(), p.ids.end(), kNoId)) != p.dead) fail(where + "wrong dead count");
    if constexpr (requires { p.structure.dead(); })
      if (p.structure.dead() != p.dead) fail(where + "the structure's dead count disagrees");
    if constexpr (requires { p.structure.validate(); }) p.structure.validate();
  }

  Part& part(const Location& at) {
    if (at.level < levels_.size())
      for (Part& p : levels_[at.level])
        if (p.serial == at.serial) return p;
    throw Error("Dynamized: the locator points to a missing structure");
  }
  const Part& part(const Location& at) const { return const_cast<Dynamized*>(this)->part(at); }

  // The V_{i+1} being relocated that `at` points to, if any.
  Part* relocating(const Location& at) {
    if (at.level == 0 || !building(at.level - 1)) return nullptr;
    std::optional<Part>& result = building_[at.level - 1]->result;
    return result && result->serial == at.serial ? &*result : nullptr;
  }

  bool building(std::size_t level) const { return level < building_.size() && building_[level].has_value(); }

  static void kill(Part& p, std::size_t slot) {
    if constexpr (WeakDeletable<S>) p.structure.weak_delete(slot);
    p.ids[slot] = kNoId;
    ++p.dead;
  }

  // A finished structure for `level`: dead slots are weakly deleted in it, live
  // ones are pointed to by the locator.
  Part make_part(std::size_t level, S structure, std::vector<Id> ids) {
    Part p{std::move(structure), std::move(ids), next_serial_++, 0};
    for (std::size_t slot = 0; slot < p.ids.size(); ++slot) {
      if (p.ids[slot] == kNoId) {
        if constexpr (WeakDeletable<S>) p.structure.weak_delete(slot);
        ++p.dead;
      } else {
        locator_.set(p.ids[slot], Location{std::uint32_t(level), p.serial, std::uint32_t(slot)});
      }
    }
    return p;
  }

  void add(std::size_t level, Part p) {
    if (levels_.size() <= level) levels_.resize(level + 1);
    levels_[level].push_back(std::move(p));
  }

  // Appends every slot of p (dead ones too, so slot positions carry over).
  static void append(const Part& p, std::vector<Item>& items, std::vector<Id>* ids) {
    std::vector<Item> extracted = p.structure.extract();
    items.insert(items.end(), std::make_move_iterator(extracted.begin()), std::make_move_iterator(extracted.end()));
    if (ids) ids->insert(ids->end(), p.ids.begin(), p.ids.end());
  }

  // Build(W, D): one structure per set bit of |D|, largest first (Lemma 10).
  void build_all(std::vector<Item> items, std::vector<Id> ids) {
    levels_.clear();
    building_.clear();
    locator_ = Locator(items.size());
    dead_ = 0;
    std::size_t offset = 0;
    for (std::size_t i = 64; i-- > 0;) {
      const std::size_t count = std::size_t(1) << i;
      if (!((items.size() >> i) & 1)) continue;
      std::vector<Item> chunk(std::make_move_iterator(items.begin() + offset),
                              std::make_move_iterator(items.begin() + offset + count));
      add(i, make_part(i, S::build(std::move(chunk)),
                       std::vector<Id>(ids.begin() + offset, ids.begin() + offset + count)));
      offset += count;
    }
  }

  // Theorem 11: V_j := build(V_0 ∪ ... ∪ V_{j-1} ∪ {d}) for the lowest empty level j.
  void insert_amortized(Item item, Id id) {
    std::size_t j = 0;
    while (j < levels_.size() && !levels_[j].empty()) ++j;
    std::vector<Item> items;
    std::vector<Id> ids;
    items.reserve(std::size_t(1) << j);
    ids.reserve(std::size_t(1) << j);
    for (std::size_t i = 0; i < j; ++i) {
      append(levels_[i].front(), items, &ids);
      levels_[i].clear();
    }
    items.push_back(std::move(item));
    ids.push_back(id);
    add(j, make_part(j, S::build(std::move(items)), std::move(ids)));
  }

  // Theorem 14: advance the builds in progress, add {d} on level 0, start
  // building wherever a level now holds two structures.
  void insert_worst_case(Item item, Id id) {
    for (std::size_t i = 0; i < building_.size(); ++i)
      if (building(i) && advance(i, false)) install(i);
    std::vector<Item> single;
    single.push_back(std::move(item));
    push(0, make_part(0, S::build(std::move(single)), std::vector<Id>{id}));
    for (std::size_t i = 0; i < levels_.size(); ++i)
      if (levels_[i].size() >= 2 && !building(i)) start_build(i);
  }

  // Adds a structure to a level of the worst-case variant; a level never holds a fourth.
  void push(std::size_t level, Part p) {
    while (level < levels_.size() && levels_[level].size() >= 3) {
      if (!building(level)) start_build(level);
      ++forced_builds_;
      advance(level, true);
      install(level);
    }
    add(level, std::move(p));
  }

  void start_build(std::size_t level) {
    if (building_.size() <= level) building_.resize(level + 1);
    Pending& p = building_[level].emplace();
    p.items.reserve(std::size_t(2) << level);
    if constexpr (!requires(const S& s) { s.item(std::size_t{}); }) {
      append(levels_[level][0], p.items, nullptr);  // no item access: gathered at once
      append(levels_[level][1], p.items, nullptr);
    }
  }

  // One insert's share of the work on level's build (all of it if `all`); a
  // phase that ends leaves the rest of the share to the next. True once relocated.
  bool advance(std::size_t level, bool all) {
    if constexpr (SteppedBuild<S>) {
      Pending& p = *building_[level];
      const std::size_t half = std::size_t(1) << level;
      if (!p.builder) {
        if constexpr (requires(const S& s) { s.item(std::size_t{}); }) {
          const std::size_t end = all ? 2 * half : std::min(2 * half, p.items.size() + kSlotsPerInsert);
          for (std::size_t slot = p.items.size(); slot < end; ++slot)
            p.items.push_back(levels_[level][slot < half ? 0 : 1].structure.item(slot % half));
          if (p.items.size() < 2 * half) return false;
        }
        p.builder.emplace(std::move(p.items));
        // Built within about 2^(level-1) inserts.
        p.work_per_insert = std::size_t(p.builder->estimated_work()) / std::max<std::size_t>(1, half / 2) + 1;
      }
      if (!p.result) {
        if (!p.builder->step(all ? std::numeric_limits<std::size_t>::max() : p.work_per_insert)) return false;
        p.result.emplace(Part{p.builder->finish(), {}, next_serial_++, 0});
        p.result->ids.reserve(2 * half);
      }
      Part& copy = *p.result;
      const std::size_t end = all ? 2 * half : std::min(2 * half, p.relocated + kSlotsPerInsert);
      for (; p.relocated < end; ++p.relocated) {
        const std::size_t slot = p.relocated;
        const Id id = levels_[level][slot < half ? 0 : 1].ids[slot % half];
        copy.ids.push_back(id);
        if (id == kNoId) {
          if constexpr (WeakDeletable<S>) copy.structure.weak_delete(slot);
          ++copy.dead;
        } else {
          locator_.set(id, Location{std::uint32_t(level + 1), copy.serial, std::uint32_t(slot)});
        }
      }
      return p.relocated == 2 * half;
    } else {
      return true;
    }
  }

  // Replaces level's first two structures by the V_{i+1} built and relocated from them.
  void install(std::size_t level) {
    Part result = std::move(*building_[level]->result);
    building_[level].reset();
    levels_[level].erase(levels_[level].begin(), levels_[level].begin() + 2);
    push(level + 1, std::move(result));
  }

  DynamizeOptions options_;
  std::vector<std::vector<Part>> levels_;         // levels_[i]: complete structures of 2^i slots
  std::vector<std::optional<Pending>> building_;  // building_[i]: a V_{i+1} from level i's first two
  Locator locator_;
  std::size_t dead_ = 0;
  Id next_id_ = 0;
  std::uint32_t next_serial_ = 0;
  std::size_t rebuilds_ = 0;
  std::size_t forced_builds_ = 0;
};

}  // namespace geods::dynamic
