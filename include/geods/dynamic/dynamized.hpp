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
//    until more than max_dead_fraction f of all slots are dead (the seed's 1/2):
//    then everything is rebuilt from the live items alone, freeing the rest.
//    Amortized variant: in that same call. Worst-case variant (Theorem 14):
//    a global reconstruction runs in steps over the following operations
//    (every insert and every deleted id is one tick). The structures present
//    at its start are frozen as the old generation, which keeps answering
//    queries and taking deletes; new inserts go to fresh levels. Each tick
//    gathers a few of the old live items, or does a share of building them
//    into one "base" structure per set bit of their count, or points a few
//    locator entries at the new copies (a deleted item that was copied is
//    deleted in both). When all are moved, the base structures replace the old
//    generation, which is freed. The schedule is set at the start so that it
//    ends before the dead slots exceed (1 + f) / 2 of all slots (3/4 for
//    f = 1/2): half of the deletions left until that bound suffice. If they do
//    not (an estimate was short) the reconstruction is finished on the spot
//    and counted in stats().forced_rebuilds. So every tick does
//    O(1 + B_V(n) / n) element visits for it: O(log n) for the k-d tree.
//
// Ids are handed out by insert (0, 1, 2, ...) and never reused; removing an
// id that is not stored (never inserted, or already removed) is an error.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
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
  std::size_t rebuilds = 0;             // global reconstructions completed so far
  std::size_t forced_builds = 0;        // worst case: builds finished early
  bool reconstructing = false;          // worst case: a global reconstruction is under way
  std::size_t forced_rebuilds = 0;      // worst case: reconstructions finished early
  /// Element visits of the work done on the side so far: items gathered for a
  /// build, units of build work (KdBlock: element visits) and locator entries
  /// rewritten, in merges and reconstructions. The difference across one
  /// operation measures what it paid, deterministically.
  std::size_t work = 0;
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
      throw Error("Dynamized: max_dead_fraction must lie in (0, 1), got " + format_number(options.max_dead_fraction));
  }

  const DynamizeOptions& options() const { return options_; }
  /// Live items.
  std::size_t size() const { return locator_.size(); }
  /// Weakly deleted slots still stored.
  std::size_t dead() const { return dead_; }
  bool contains(Id id) const { return locator_.find(id) != nullptr; }
  /// stats().work without building the rest of the stats.
  std::size_t work() const { return work_; }

  /// The structure holding id and its slot there, or {nullptr, 0}.
  std::pair<const S*, std::size_t> locate(Id id) const {
    const Location* at = locator_.find(id);
    if (!at) return {nullptr, 0};
    auto* self = const_cast<Dynamized*>(this);
    if (const Part* copy = self->reconstructed(*at).first) return {&copy->structure, at->slot};
    const Part* copy = self->relocating(*at).first;
    return {copy ? &copy->structure : &part(*at).structure, at->slot};
  }

  /// The id the next insert hands out.
  Id next_id() const { return next_id_; }

  /// A structure made of the given parts, e.g. read back from a file: each part
  /// is a structure and its slot -> id table (kNoId for a dead slot, which is
  /// weakly deleted here), of 2^i slots, and goes to level i in the given order.
  /// The worst-case variant starts a build on every level holding two or more,
  /// and a reconstruction if too many slots are dead (the amortized variant
  /// rebuilds then). `next_id` is the id the next insert hands out. Throws
  /// geods::Error for a part whose size is not a power of two or disagrees
  /// with its ids, two parts on one level (amortized variant), or an id given
  /// twice or not below next_id.
  static Dynamized restore(DynamizeOptions options, std::vector<std::pair<S, std::vector<Id>>> parts, Id next_id) {
    Dynamized d(options);
    d.next_id_ = next_id;
    std::size_t slots = 0;
    for (const auto& part : parts) slots += part.second.size();
    d.locator_ = Locator(slots, next_id);
    for (auto& [structure, ids] : parts) {
      const std::size_t n = ids.size();
      if (n == 0 || (n & (n - 1)) != 0 || structure.size() != n)
        throw Error("Dynamized::restore: a structure of " + std::to_string(structure.size()) + " slots with " +
                    std::to_string(n) + " ids, expected a power of two of both");
      for (Id id : ids)
        if (id != kNoId && (id >= next_id || d.locator_.find(id)))
          throw Error("Dynamized::restore: id " + std::to_string(id) + " is given twice or not below the next id");
      const std::size_t level = std::size_t(std::countr_zero(n));
      Part p = d.make_part(level, std::move(structure), std::move(ids));
      d.dead_ += p.dead;
      if (options.variant == Variant::amortized) {
        if (level < d.levels_.size() && !d.levels_[level].empty())
          throw Error("Dynamized::restore: two structures of " + std::to_string(n) + " slots");
        d.add(level, std::move(p));
      } else {
        d.push(level, std::move(p));
      }
    }
    if (options.variant == Variant::amortized) {
      if (d.over(options.max_dead_fraction)) d.rebuild();
    } else {
      for (std::size_t i = 0; i < d.levels_.size(); ++i)
        if (d.levels_[i].size() >= 2 && !d.building(i)) d.start_build(i);
      if (d.over(d.hard_fraction())) {
        d.rebuild();
      } else if (d.over(options.max_dead_fraction)) {
        d.start_reconstruction();
      }
    }
    return d;
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
  /// what is stored is one Build(W, D) over everything (Lemma 10) instead;
  /// in the amortized variant a smaller one rebuilds only the levels its
  /// carry reaches, once (insert_batch_amortized), and ends with the same
  /// levels as inserting its items one by one.
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
    if (options_.variant == Variant::amortized && items.size() > 1) {
      for (Id& id : ids) id = next_id_++;
      insert_batch_amortized(std::move(items), ids);
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
    for (Id id : ids) {
      const Location* at = locator_.find(id);
      if (!at) throw Error("remove: id " + std::to_string(id) + " is not stored (never inserted, or removed already)");
      __builtin_prefetch(at);  // read below: the misses of a batch overlap here instead of one by one there
    }
    std::vector<Id> sorted(ids.begin(), ids.end());
    std::sort(sorted.begin(), sorted.end());
    if (const auto twice = std::adjacent_find(sorted.begin(), sorted.end()); twice != sorted.end())
      throw Error("remove: id " + std::to_string(*twice) + " is given twice");
    for (Id id : ids) {
      const Location at = *locator_.find(id);
      if (const auto [copy, index] = reconstructed(at); copy) {
        // Already moved by the global reconstruction: delete it there and in the old generation, which still answers queries.
        kill(*copy, at.slot);
        kill_at(recon_->from[index]);
      } else {
        kill_at(at);
      }
      ++dead_;
      locator_.erase(id);
      if (options_.variant == Variant::worst_case) tick();
    }
    if (options_.variant == Variant::amortized && over(options_.max_dead_fraction)) rebuild();
  }
  void remove(Id id)
    requires WeakDeletable<S>
  {
    remove(std::span<const Id>(&id, 1));
  }

  /// Global reconstruction (Theorem 12) now, in this call: rebuilds the binary
  /// structure from the live items; dead slots, pending builds, a reconstruction
  /// under way and their memory are freed.
  void rebuild() {
    auto [items, ids] = live_items();
    build_all(std::move(items), std::move(ids));
    ++rebuilds_;
  }

  /// Calls f(structure, ids) for every complete structure, largest first, where
  /// ids[slot] is the id in that slot (kNoId if deleted). Queries combine the
  /// answers; largest first, a k-nearest search finds good candidates early and
  /// then prunes most small structures at their root. During a global
  /// reconstruction these are the old generation's and the new levels'; the
  /// copies under construction are not visited.
  template <typename F>
  void for_each(const F& f) const {
    if (recon_) for_each_in(recon_->base, recon_->levels, f);
    for_each_in(base_, levels_, f);
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
  /// the levels holding two or more; base structures (from the last global
  /// reconstruction) of distinct powers of two; during a reconstruction, the
  /// same for the frozen old generation, the copies built so far have the
  /// gathered items' ids up to the relocation point and the locator points
  /// to them there. Both: slot tables, dead counts, the locator is a
  /// bijection onto the live slots, the dead fraction is at most
  /// max_dead_fraction (at most (1 + max_dead_fraction) / 2 during a
  /// reconstruction), and each structure's own validate() if it has one.
  void validate() const {
    auto fail = [](const std::string& what) { throw Error("Dynamized::validate: " + what); };
    auto same = [](const Location& a, const Location& b) {
      return a.level == b.level && a.serial == b.serial && a.slot == b.slot;
    };
    // The locator has id at `loc`, or in the reconstruction's copy made from `loc`.
    auto expect_at = [&](Id id, const Location& loc) {
      const Location* at = locator_.find(id);
      if (!at) return false;
      if (same(*at, loc)) return true;
      const auto [copy, index] = const_cast<Dynamized*>(this)->reconstructed(*at);
      return copy && copy->ids.size() > at->slot && copy->ids[at->slot] == id && same(recon_->from[index], loc);
    };
    std::size_t slots = 0, live = 0, dead = 0;
    auto count = [&](const Part& p) {
      slots += p.ids.size();
      dead += p.dead;
      live += p.ids.size() - p.dead;
    };
    auto check_levels = [&](const std::vector<std::vector<Part>>& levels,
                            const std::vector<std::optional<Pending>>& building, const std::string& gen) {
      for (std::size_t i = 0; i < levels.size(); ++i) {
        const std::string where = gen + "level " + std::to_string(i) + ": ";
        const std::size_t n = levels[i].size();
        const bool pending = i < building.size() && building[i].has_value();
        if (options_.variant == Variant::amortized) {
          if (n > 1 || pending) fail(where + "more than one structure");
        } else if (n > 3 || (n >= 2) != pending) {
          fail(where + std::to_string(n) + " structures and " + (pending ? "a" : "no") + " build in progress");
        }
        // Slots of the first two structures below `relocated` have moved to the V_{i+1} built from them.
        const Part* copy = pending ? building[i]->result ? &*building[i]->result : nullptr : nullptr;
        const std::size_t relocated = copy ? building[i]->relocated : 0, half = std::size_t(1) << i;
        if (copy) check_part(*copy, 2 * half, relocated, fail, where + "structure being relocated: ");
        for (std::size_t k = 0; k < n; ++k) {
          const Part& p = levels[i][k];
          const std::size_t moved = k < 2 ? std::clamp(relocated, k * half, (k + 1) * half) - k * half : 0;
          for (std::size_t slot = 0; slot < p.ids.size(); ++slot) {
            const Id id = p.ids[slot];
            if (slot >= moved) {
              if (id != kNoId && !expect_at(id, Location{std::uint32_t(i), p.serial, std::uint32_t(slot)}))
                fail(where + "the locator does not point to id " + std::to_string(id));
            } else if (id != copy->ids[k * half + slot] ||
                       (id != kNoId &&
                        !expect_at(id, Location{std::uint32_t(i + 1), copy->serial, std::uint32_t(k * half + slot)}))) {
              fail(where + "a relocated slot does not match its source");
            }
          }
          check_part(p, half, half, fail, where);
          count(p);
        }
      }
    };
    auto check_base = [&](const std::vector<Part>& base, const std::string& gen) {
      for (std::size_t k = 0; k < base.size(); ++k) {
        const Part& p = base[k];
        const std::size_t n = p.ids.size();
        if (options_.variant == Variant::amortized || n == 0 || (n & (n - 1)) != 0 ||
            (k > 0 && n >= base[k - 1].ids.size()))
          fail(gen + "base structures are not distinct powers of two, largest first");
        for (std::size_t slot = 0; slot < n; ++slot)
          if (p.ids[slot] != kNoId && !expect_at(p.ids[slot], Location{kBase, p.serial, std::uint32_t(slot)}))
            fail(gen + "base: the locator does not point to id " + std::to_string(p.ids[slot]));
        check_part(p, n, n, fail, gen + "base: ");
        count(p);
      }
    };
    check_levels(levels_, building_, "");
    check_base(base_, "");
    if (recon_) {
      const Reconstruction& r = *recon_;
      if (!base_.empty()) fail("base structures besides a reconstruction under way");
      check_levels(r.levels, r.building, "old generation, ");
      check_base(r.base, "old generation, ");
      if (r.ids.size() != r.from.size() || r.result.size() != r.result_offset.size())
        fail("reconstruction: inconsistent tables");
      std::size_t offset = 0;
      for (std::size_t k = 0; k < r.result.size(); ++k) {
        const Part& p = r.result[k];
        const std::size_t n = p.structure.size();
        if (r.result_offset[k] != offset || n != std::bit_floor(r.ids.size() - offset))
          fail("reconstruction: copies are not one per set bit of the gathered count, largest first");
        const std::size_t filled = std::clamp(r.relocated, offset, offset + n) - offset;
        check_part(p, n, filled, fail, "reconstruction copy: ");
        for (std::size_t slot = 0; slot < filled; ++slot) {
          const Id id = p.ids[slot];
          const Location* at = id == kNoId ? nullptr : locator_.find(id);
          if (id != kNoId && (id != r.ids[offset + slot] || !at ||
                              !same(*at, Location{kBase, p.serial, std::uint32_t(slot)})))
            fail("reconstruction copy: slot " + std::to_string(slot) + " does not match the locator");
        }
        offset += n;
      }
      if (r.relocated > offset) fail("reconstruction: relocated beyond the copies built");
    }
    if (live != locator_.size())
      fail(std::to_string(live) + " live slots but " + std::to_string(locator_.size()) + " locator entries");
    if (dead != dead_) fail("wrong total dead count");
    const double bound = recon_ ? hard_fraction() : options_.max_dead_fraction;
    if (double(dead) > bound * double(slots)) fail("too many dead slots");
    if (options_.variant == Variant::amortized)
      for (std::size_t i = 0; i < 64; ++i)
        if (((slots >> i) & 1) != (i < levels_.size() ? levels_[i].size() : 0))
          fail("the structures do not match the binary representation of " + std::to_string(slots));
  }

  DynamizedStats stats() const {
    DynamizedStats s;
    s.live = size();
    s.dead = dead_;
    auto on_level = [&](std::size_t i) -> std::size_t& {
      if (s.per_level.size() <= i) s.per_level.resize(i + 1);
      return s.per_level[i];
    };
    auto add_levels = [&](const std::vector<std::vector<Part>>& levels,
                          const std::vector<std::optional<Pending>>& building) {
      for (std::size_t i = 0; i < levels.size(); ++i) {
        on_level(i) += levels[i].size();
        s.structures += levels[i].size();
      }
      for (const auto& b : building) s.building += b.has_value() ? 1 : 0;
    };
    auto add_base = [&](const std::vector<Part>& base) {
      for (const Part& p : base) {
        ++on_level(std::size_t(std::countr_zero(p.ids.size())));
        ++s.structures;
      }
    };
    add_levels(levels_, building_);
    add_base(base_);
    if (recon_) {
      add_levels(recon_->levels, recon_->building);
      add_base(recon_->base);
    }
    while (!s.per_level.empty() && s.per_level.back() == 0) s.per_level.pop_back();
    s.rebuilds = rebuilds_;
    s.forced_builds = forced_builds_;
    s.reconstructing = recon_ != nullptr;
    s.forced_rebuilds = forced_rebuilds_;
    s.work = work_;
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

  // A global reconstruction of the worst-case variant, spread over `ticks`
  // operations: the live items of the old generation are gathered (a quarter
  // of the ticks), built into one copy per set bit of their count, largest
  // first (half), and the locator pointed at the copies (a quarter).
  struct Reconstruction {
    // The old generation, frozen: it answers queries and takes deletes until replaced.
    std::vector<std::vector<Part>> levels;
    std::vector<std::optional<Pending>> building;
    std::vector<Part> base;
    std::vector<const Part*> sources;  // its complete structures, in gathering order
    std::size_t source = 0, slot = 0;  // the gathering cursor
    bool gathered = false;
    std::vector<Item> items;     // the live items gathered (moved into the builds)
    std::vector<Id> ids;         // their ids
    std::vector<Location> from;  // where they are in the old generation
    std::vector<std::vector<Item>> tail;  // the items of every copy but the largest, split off in steps
    std::size_t split = 0;                // items split off so far
    std::size_t built = 0;                // items in finished copies
    std::vector<std::optional<typename detail::BuilderOf<S>::type>> builders;  // one per copy, once gathered
    std::size_t work_per_tick = 0;  // build work per tick, for all copies together
    std::size_t granted = 0;        // build work given to the copy being built
    std::vector<Part> result;                // the copies, ids filled up to `relocated`
    std::vector<std::size_t> result_offset;  // index in `ids` of each copy's slot 0
    std::size_t relocated = 0;
    std::size_t ticks = 1, gather_per_tick = 0, relocate_per_tick = 0;
  };

  // Items gathered, and locator entries rewritten, per insert: 2^(i+1) slots in 2^(i-2) inserts.
  static constexpr std::size_t kSlotsPerInsert = 8;
  // A reconstruction gathers and relocates at least this many items per tick.
  static constexpr std::size_t kReconMinPerTick = 16;
  // Location::level of a base structure.
  static constexpr std::uint32_t kBase = std::numeric_limits<std::uint32_t>::max();

  template <typename F>
  static void for_each_in(const std::vector<Part>& base, const std::vector<std::vector<Part>>& levels, const F& f) {
    for (const Part& p : base) f(p.structure, std::span<const Id>(p.ids));
    for (auto level = levels.rbegin(); level != levels.rend(); ++level)
      for (const Part& p : *level) f(p.structure, std::span<const Id>(p.ids));
  }

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

  // The complete structure `at` points to, in the current or the old generation.
  Part& part(const Location& at) {
    auto find = [&](std::vector<Part>& parts) -> Part* {
      for (Part& p : parts)
        if (p.serial == at.serial) return &p;
      return nullptr;
    };
    Part* p = nullptr;
    if (at.level == kBase) {
      p = find(base_);
      if (!p && recon_) p = find(recon_->base);
    } else {
      if (at.level < levels_.size()) p = find(levels_[at.level]);
      if (!p && recon_ && at.level < recon_->levels.size()) p = find(recon_->levels[at.level]);
    }
    if (!p) throw Error("Dynamized: the locator points to a missing structure");
    return *p;
  }
  const Part& part(const Location& at) const { return const_cast<Dynamized*>(this)->part(at); }

  // The V_{i+1} being relocated that `at` points to, if any, and the levels of its sources.
  std::pair<Part*, std::vector<std::vector<Part>>*> relocating(const Location& at) {
    if (at.level == 0 || at.level == kBase) return {nullptr, nullptr};
    auto in = [&](std::vector<std::optional<Pending>>& building, std::vector<std::vector<Part>>& levels)
        -> std::pair<Part*, std::vector<std::vector<Part>>*> {
      if (at.level - 1 >= building.size() || !building[at.level - 1]) return {nullptr, nullptr};
      std::optional<Part>& result = building[at.level - 1]->result;
      return result && result->serial == at.serial ? std::pair{&*result, &levels} : std::pair{nullptr, nullptr};
    };
    auto found = in(building_, levels_);
    if (!found.first && recon_) found = in(recon_->building, recon_->levels);
    return found;
  }

  // The reconstruction's copy that `at` points to, if any, and the item's index in its tables.
  std::pair<Part*, std::size_t> reconstructed(const Location& at) {
    if (!recon_ || at.level != kBase) return {nullptr, 0};
    for (std::size_t k = 0; k < recon_->result.size(); ++k)
      if (recon_->result[k].serial == at.serial) return {&recon_->result[k], recon_->result_offset[k] + at.slot};
    return {nullptr, 0};
  }

  bool building(std::size_t level) const { return level < building_.size() && building_[level].has_value(); }

  static void kill(Part& p, std::size_t slot) {
    if constexpr (WeakDeletable<S>) p.structure.weak_delete(slot);
    p.ids[slot] = kNoId;
    ++p.dead;
  }

  // Deletes the slot `at` points to, in both copies if it is being relocated.
  void kill_at(const Location& at) {
    if (const auto [copy, levels] = relocating(at); copy) {
      const std::size_t half = copy->structure.size() / 2;
      kill((*levels)[at.level - 1][at.slot < half ? 0 : 1], at.slot % half);
      kill(*copy, at.slot);
    } else {
      kill(part(at), at.slot);
    }
  }

  bool over(double fraction) const { return double(dead_) > fraction * double(size() + dead_); }
  // The dead fraction a reconstruction must end before: halfway from max_dead_fraction to 1.
  double hard_fraction() const { return (1 + options_.max_dead_fraction) / 2; }

  // S::build, with its work counted.
  S build_counted(std::vector<Item> items) {
    work_ += items.size();
    if constexpr (SteppedBuild<S>) {
      typename S::Builder builder(std::move(items));
      work_ += std::size_t(builder.estimated_work());
      return builder.finish();
    } else {
      return S::build(std::move(items));
    }
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
  void append(const Part& p, std::vector<Item>& items, std::vector<Id>* ids) {
    std::vector<Item> extracted = p.structure.extract();
    work_ += extracted.size();
    items.insert(items.end(), std::make_move_iterator(extracted.begin()), std::make_move_iterator(extracted.end()));
    if (ids) ids->insert(ids->end(), p.ids.begin(), p.ids.end());
  }

  // Build(W, D): one structure per set bit of |D|, largest first (Lemma 10).
  void build_all(std::vector<Item> items, std::vector<Id> ids) {
    levels_.clear();
    building_.clear();
    base_.clear();
    recon_.reset();
    locator_ = Locator(items.size(), next_id_);
    dead_ = 0;
    std::size_t offset = 0;
    for (std::size_t i = 64; i-- > 0;) {
      const std::size_t count = std::size_t(1) << i;
      if (!((items.size() >> i) & 1)) continue;
      std::vector<Item> chunk(std::make_move_iterator(items.begin() + offset),
                              std::make_move_iterator(items.begin() + offset + count));
      add(i, make_part(i, build_counted(std::move(chunk)),
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
    add(j, make_part(j, build_counted(std::move(items)), std::move(ids)));
  }

  // A batch of b items at once, as b inserts one by one would end: the slot
  // count s becomes s + b, whose binary representation keeps the bits above
  // the highest one where the two differ (level p). So the structures above p
  // stay, and those at or below it are rebuilt, with the batch, as one
  // structure per set bit of (s + b) mod 2^(p + 1), largest first. Each item
  // is built into a structure of its final level once, not once per level it
  // passes: the levels below log2(b) are not built b times over.
  void insert_batch_amortized(std::vector<Item> batch, const std::vector<Id>& batch_ids) {
    const std::size_t slots = size() + dead_, total = slots + batch.size();
    const std::size_t p = std::size_t(std::bit_width(slots ^ total)) - 1;
    const std::size_t count = total & ((std::size_t(2) << p) - 1);
    std::vector<Item> items;
    std::vector<Id> ids;
    items.reserve(count);
    ids.reserve(count);
    for (std::size_t i = std::min(p + 1, levels_.size()); i-- > 0;) {
      if (levels_[i].empty()) continue;
      append(levels_[i].front(), items, &ids);
      levels_[i].clear();
    }
    items.insert(items.end(), std::make_move_iterator(batch.begin()), std::make_move_iterator(batch.end()));
    ids.insert(ids.end(), batch_ids.begin(), batch_ids.end());
    std::size_t offset = 0;
    for (std::size_t i = p + 1; i-- > 0;) {
      const std::size_t n = std::size_t(1) << i;
      if (!((count >> i) & 1)) continue;
      std::vector<Item> chunk(std::make_move_iterator(items.begin() + offset),
                              std::make_move_iterator(items.begin() + offset + n));
      add(i, make_part(i, build_counted(std::move(chunk)),
                       std::vector<Id>(ids.begin() + offset, ids.begin() + offset + n)));
      offset += n;
    }
  }

  // Theorem 14: advance the builds in progress, add {d} on level 0, start
  // building wherever a level now holds two structures; then one tick of a
  // global reconstruction.
  void insert_worst_case(Item item, Id id) {
    for (std::size_t i = 0; i < building_.size(); ++i)
      if (building(i) && advance(i, false)) install(i);
    std::vector<Item> single;
    single.push_back(std::move(item));
    push(0, make_part(0, S::build(std::move(single)), std::vector<Id>{id}));
    for (std::size_t i = 0; i < levels_.size(); ++i)
      if (levels_[i].size() >= 2 && !building(i)) start_build(i);
    tick();
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
          work_ += end - p.items.size();
          for (std::size_t slot = p.items.size(); slot < end; ++slot)
            p.items.push_back(levels_[level][slot < half ? 0 : 1].structure.item(slot % half));
          if (p.items.size() < 2 * half) return false;
        }
        p.builder.emplace(std::move(p.items));
        // Built within about 2^(level-1) inserts.
        p.work_per_insert = std::size_t(p.builder->estimated_work()) / std::max<std::size_t>(1, half / 2) + 1;
      }
      if (!p.result) {
        work_ += all ? std::size_t(p.builder->estimated_work()) : p.work_per_insert;
        if (!p.builder->step(all ? std::numeric_limits<std::size_t>::max() : p.work_per_insert)) return false;
        p.result.emplace(Part{p.builder->finish(), {}, next_serial_++, 0});
        p.result->ids.reserve(2 * half);
      }
      Part& copy = *p.result;
      const std::size_t end = all ? 2 * half : std::min(2 * half, p.relocated + kSlotsPerInsert);
      work_ += end - p.relocated;
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

  // Worst case: the share of a global reconstruction paid by one insert or one
  // deleted id. Finishes it at once if the dead fraction reached the hard
  // bound; starts one when it passes max_dead_fraction.
  void tick() {
    work_ += locator_.migrate(kReconMinPerTick);
    if (recon_) {
      if (over(hard_fraction())) {
        ++forced_rebuilds_;
        advance_reconstruction(true);
        install_reconstruction();
      } else if (advance_reconstruction(false)) {
        install_reconstruction();
      }
    }
    if (!recon_ && over(options_.max_dead_fraction)) {
      start_reconstruction();
      if (advance_reconstruction(false)) install_reconstruction();
    }
  }

  // Freezes everything stored as the old generation; new inserts start on empty levels.
  // The schedule: half of the deletions left before the hard bound (each is a tick).
  void start_reconstruction() {
    auto r = std::make_unique<Reconstruction>();
    const std::size_t slots = size() + dead_, live = size();
    r->levels = std::exchange(levels_, {});
    r->building = std::exchange(building_, {});
    r->base = std::exchange(base_, {});
    for (const Part& p : r->base) r->sources.push_back(&p);
    for (const auto& level : r->levels)
      for (const Part& p : level) r->sources.push_back(&p);
    const double room = hard_fraction() * double(slots) - double(dead_);
    r->ticks = std::max<std::size_t>(1, std::size_t(std::max(0.0, room) / 2));
    const std::size_t quarter = std::max<std::size_t>(1, r->ticks / 4);
    r->gather_per_tick = std::max(kReconMinPerTick, (slots + quarter - 1) / quarter);
    r->relocate_per_tick = std::max(kReconMinPerTick, (live + quarter - 1) / quarter);
    r->items.reserve(live);
    r->ids.reserve(live);
    r->from.reserve(live);
    recon_ = std::move(r);
    locator_.shrink();  // after mass deletion its table is returned too, in steps
  }

  // One tick's share of the reconstruction (all of it if `all`): some gathering,
  // a step of one copy's build, some relocation. True once every item is relocated.
  bool advance_reconstruction(bool all) {
    if constexpr (SteppedBuild<S>) {
      Reconstruction& r = *recon_;
      constexpr std::size_t kAll = std::numeric_limits<std::size_t>::max();
      if (!r.gathered) {
        std::size_t budget = all ? kAll : r.gather_per_tick;
        while (budget > 0 && r.source < r.sources.size()) {
          const Part& p = *r.sources[r.source];
          auto take = [&](std::size_t slot, auto&& item) {
            const Id id = p.ids[slot];
            if (id == kNoId) return;
            r.items.push_back(std::forward<decltype(item)>(item));
            r.ids.push_back(id);
            r.from.push_back(*locator_.find(id));
          };
          if constexpr (requires(const S& s) { s.item(std::size_t{}); }) {
            const std::size_t start = r.slot, end = std::min(p.ids.size(), r.slot + budget);
            for (; r.slot < end; ++r.slot)
              if (p.ids[r.slot] != kNoId) take(r.slot, p.structure.item(r.slot));
            work_ += end - start;
            budget -= end - start;
          } else {
            std::vector<Item> extracted = p.structure.extract();  // no item access: a whole structure at once
            for (std::size_t slot = 0; slot < extracted.size(); ++slot) take(slot, std::move(extracted[slot]));
            work_ += extracted.size();
            r.slot = p.ids.size();
          }
          if (r.slot < p.ids.size()) break;
          ++r.source;
          r.slot = 0;
        }
        if (r.source < r.sources.size()) return false;
        r.gathered = true;
      }
      const std::size_t m = r.ids.size();
      if (r.builders.empty() && m > 0) {
        // One copy per set bit of m, largest first. The largest takes the gathered
        // vector itself; the items of the others are first moved out of its end,
        // at the gathering rate.
        const std::size_t first = std::bit_floor(m);
        if (r.tail.empty())
          for (std::size_t offset = first; offset < m; offset += std::bit_floor(m - offset))
            r.tail.emplace_back().reserve(std::bit_floor(m - offset));
        const std::size_t end = all ? m - first : std::min(m - first, r.split + r.gather_per_tick);
        work_ += end - r.split;
        if (r.split < end) {
          std::size_t piece = 0, piece_end = first + std::bit_floor(m - first);  // index in r.items past the piece
          while (piece_end <= first + r.split) piece_end += std::bit_floor(m - piece_end), ++piece;
          for (; r.split < end; ++r.split) {
            if (first + r.split == piece_end) piece_end += std::bit_floor(m - piece_end), ++piece;
            r.tail[piece].push_back(std::move(r.items[first + r.split]));
          }
        }
        if (r.split < m - first) return false;
        r.items.resize(first);
        r.builders.emplace_back(std::in_place, std::exchange(r.items, {}));
        for (std::vector<Item>& piece : r.tail) r.builders.emplace_back(std::in_place, std::move(piece));
        r.tail = {};
        // Their builds share half of the ticks.
        std::size_t estimate = 0;
        for (const auto& builder : r.builders) estimate += std::size_t(builder->estimated_work());
        r.work_per_tick = estimate / std::max<std::size_t>(1, r.ticks / 2) + 1;
      }
      // Each copy gets at most its estimated work from this tick's budget, the rest goes to the next copy.
      std::size_t left = all ? kAll : r.work_per_tick;
      while (r.built < m && left > 0) {
        auto& builder = *r.builders[r.result.size()];
        const std::size_t estimate = std::size_t(builder.estimated_work());
        const std::size_t due = r.granted < estimate ? estimate - r.granted : left;  // the estimate may be short
        const std::size_t grant = std::min(left, due);
        work_ += all ? due : grant;
        r.granted += grant == kAll ? 0 : grant;
        if (!all) left -= grant;
        if (!builder.step(grant)) continue;
        const std::size_t n = std::bit_floor(m - r.built);
        r.result_offset.push_back(r.built);
        r.result.push_back(Part{builder.finish(), {}, next_serial_++, 0});
        r.result.back().ids.reserve(n);
        r.builders[r.result.size() - 1].reset();  // frees the build's working memory
        r.granted = 0;
        r.built += n;
      }
      if (r.built < m) return false;
      const std::size_t end = all ? m : std::min(m, r.relocated + r.relocate_per_tick);
      work_ += end - r.relocated;
      std::size_t k = 0;
      for (; r.relocated < end; ++r.relocated) {
        const std::size_t j = r.relocated;
        while (k + 1 < r.result.size() && r.result_offset[k + 1] <= j) ++k;
        Part& p = r.result[k];
        const std::size_t slot = j - r.result_offset[k];
        if (locator_.find(r.ids[j])) {
          locator_.set(r.ids[j], Location{kBase, p.serial, std::uint32_t(slot)});
          p.ids.push_back(r.ids[j]);
        } else {  // deleted since it was gathered
          if constexpr (WeakDeletable<S>) p.structure.weak_delete(slot);
          p.ids.push_back(kNoId);
          ++p.dead;
        }
      }
      return r.relocated == m;
    } else {
      return true;
    }
  }

  // The copies replace the old generation, whose memory is returned.
  void install_reconstruction() {
    base_ = std::move(recon_->result);
    recon_.reset();
    dead_ = 0;
    for (const Part& p : base_) dead_ += p.dead;
    for (const auto& level : levels_)
      for (const Part& p : level) dead_ += p.dead;
    ++rebuilds_;
  }

  DynamizeOptions options_;
  std::vector<std::vector<Part>> levels_;         // levels_[i]: complete structures of 2^i slots
  std::vector<std::optional<Pending>> building_;  // building_[i]: a V_{i+1} from level i's first two
  std::vector<Part> base_;                        // worst case: the last reconstruction's copies, largest first
  std::unique_ptr<Reconstruction> recon_;         // worst case: a global reconstruction under way
  Locator locator_;
  std::size_t dead_ = 0;
  Id next_id_ = 0;
  std::uint32_t next_serial_ = 0;
  std::size_t rebuilds_ = 0;
  std::size_t forced_builds_ = 0;
  std::size_t forced_rebuilds_ = 0;
  std::size_t work_ = 0;
};

}  // namespace geods::dynamic
