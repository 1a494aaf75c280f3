// The generic wrapper with other static structures, and the k-d tree block on its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/dynamic/dynamized.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/dynamic/locator.hpp"

namespace geods::dynamic {
namespace {

// The smallest static structure: a sorted copy of the items for membership
// queries, with neither weak delete nor a stepped build.
struct SortedArray {
  using Item = int;
  std::vector<int> items;   // slot order
  std::vector<int> sorted;  // for queries

  static SortedArray build(std::vector<int> items) {
    SortedArray s{std::move(items), {}};
    s.sorted = s.items;
    std::sort(s.sorted.begin(), s.sorted.end());
    return s;
  }
  std::size_t size() const { return items.size(); }
  std::vector<int> extract() const { return items; }
  bool contains(int x) const { return std::binary_search(sorted.begin(), sorted.end(), x); }
};

static_assert(StaticStructure<SortedArray>);
static_assert(!WeakDeletable<SortedArray>);
static_assert(WeakDeletable<KdTreeBlock<float, 3>> && SteppedBuild<KdTreeBlock<float, 3>>);
static_assert(WeakDeletable<KdTreeBlock<double, spatial::Dynamic>> && SteppedBuild<KdTreeBlock<double, spatial::Dynamic>>);

TEST(Dynamized, InsertOnlyStructureAnswersDecomposedQueries) {
  Dynamized<SortedArray> set;
  std::vector<Id> ids;
  for (int x = 0; x < 1000; ++x) ids.push_back(set.insert(3 * x));
  set.validate();
  auto member = [&](int x) {
    bool found = false;
    set.for_each([&](const SortedArray& s, std::span<const Id>) { found = found || s.contains(x); });
    return found;
  };
  EXPECT_TRUE(member(2997));
  EXPECT_FALSE(member(2998));
  EXPECT_EQ(set.stats().structures, 6u);  // 1000 = 0b1111101000
  EXPECT_THROW(Dynamized<SortedArray>(DynamizeOptions{Variant::worst_case}), Error);
  const auto [items, item_ids] = set.live_items();
  EXPECT_EQ(std::set<int>(items.begin(), items.end()).size(), 1000u);
  EXPECT_EQ(std::set<Id>(item_ids.begin(), item_ids.end()), std::set<Id>(ids.begin(), ids.end()));
}

TEST(KdTreeBlock, SteppedBuildGivesTheSameTree) {
  Rng rng(11);
  std::vector<KdTreeBlock<double, 3>::Item> items(5000);
  for (auto& p : items) p = {rng.uniform(), double(rng.below(4)), rng.normal()};
  const KdTreeBlock<double, 3> whole = KdTreeBlock<double, 3>::build(items);
  KdTreeBlock<double, 3>::Builder builder(items);
  std::size_t steps = 0;
  while (!builder.step(97)) ++steps;
  EXPECT_GT(steps, builder.estimated_work() / 97 / 4) << "the build really runs in many small steps";
  const KdTreeBlock<double, 3> stepped = builder.finish();
  whole.validate();
  stepped.validate();
  EXPECT_EQ(stepped.extract(), items);
  EXPECT_EQ(whole.extract(), items);
  // The whole build (no steps: KdTree's recursion) may order points of equal
  // coordinates (axis 1 has four values) differently: the same answers.
  const double q[3] = {0.5, 1, 0};
  const double lo[3] = {0.2, 0, -1}, hi[3] = {0.6, 2, 1};
  std::vector<std::size_t> a, b, brute;
  whole.search_box(lo, hi, [&](std::uint32_t slot) { a.push_back(slot); });
  stepped.search_box(lo, hi, [&](std::uint32_t slot) { b.push_back(slot); });
  for (std::size_t i = 0; i < items.size(); ++i)
    if (items[i][0] >= lo[0] && items[i][0] <= hi[0] && items[i][1] >= lo[1] && items[i][1] <= hi[1] &&
        items[i][2] >= lo[2] && items[i][2] <= hi[2])
      brute.push_back(i);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, brute);
  EXPECT_EQ(b, brute);
  std::vector<std::size_t> near;
  stepped.search_radius(q, 0.01, [&](std::uint32_t slot, double) { near.push_back(slot); });
  std::size_t expected = 0;
  for (const auto& p : items)
    expected += (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]) <= 0.01;
  EXPECT_EQ(near.size(), expected);
}

TEST(KdTreeBlock, WeakDeleteHidesSlots) {
  std::vector<KdTreeBlock<float, 2>::Item> items;
  for (int i = 0; i < 100; ++i) items.push_back({float(i % 10), float(i / 10)});
  KdTreeBlock<float, 2> block = KdTreeBlock<float, 2>::build(items);
  for (std::size_t slot = 0; slot < 100; slot += 2) block.weak_delete(slot);
  EXPECT_THROW(block.weak_delete(0), Error);
  EXPECT_EQ(block.dead(), 50u);
  block.validate();
  const float lo[2] = {0, 0}, hi[2] = {9, 9};
  std::size_t count = 0;
  block.search_box(lo, hi, [&](std::uint32_t slot) {
    EXPECT_EQ(slot % 2, 1u);
    ++count;
  });
  EXPECT_EQ(count, 50u);
  EXPECT_EQ(block.extract().size(), 100u) << "dead slots stay until a rebuild";
}

// Blocks of at most kLeafSize items keep only their points; their searches
// answer as the tree of a larger block does, and the two kinds meet at kLeafSize.
TEST(KdTreeBlock, SmallBlocksAnswerAsTrees) {
  using Block = KdTreeBlock<double, spatial::Dynamic>;
  Rng rng(5);
  for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(3), Block::kLeafSize, Block::kLeafSize + 1,
                        std::size_t(40)}) {
    SCOPED_TRACE("n=" + std::to_string(n));
    std::vector<Block::Item> items(n);
    for (auto& p : items) p = {double(rng.below(3)), rng.uniform(), rng.normal()};  // ties on the first axis
    Block block = Block::build(items);
    EXPECT_EQ(block.small(), n <= Block::kLeafSize);
    for (std::size_t slot = 1; slot < n; slot += 3) block.weak_delete(slot);
    block.validate();
    EXPECT_EQ(block.extract(), items);
    for (std::size_t slot = 0; slot < n; ++slot) {
      EXPECT_EQ(block.item(slot), items[slot]);
      EXPECT_EQ(block.is_dead(slot), slot % 3 == 1);
    }
    for (int t = 0; t < 20; ++t) {
      const double q[3] = {double(rng.below(3)), rng.uniform(), rng.normal()};
      const double lo[3] = {q[0] - 1, q[1] - 0.3, q[2] - 0.5}, hi[3] = {q[0] + 0.5, q[1] + 0.3, q[2] + 1};
      std::vector<spatial::Neighbor<double>> near, want_near;
      std::vector<std::uint32_t> box, want_box;
      std::vector<spatial::Neighbor<double>> best(3);
      spatial::KnnResultSet<double> result(best.data(), 3, std::numeric_limits<double>::infinity());
      block.search_nearest(q, result);
      result.finish();
      best.resize(result.size());
      block.search_radius(q, 0.5, [&](std::uint32_t slot, double d) { near.push_back({slot, d}); });
      block.search_box(lo, hi, [&](std::uint32_t slot) { box.push_back(slot); });
      std::vector<spatial::Neighbor<double>> all;
      for (std::uint32_t slot = 0; slot < n; ++slot) {
        if (slot % 3 == 1) continue;
        const double d = spatial::squared_distance(q, items[slot].data(), 3);
        all.push_back({slot, d});
        if (d <= 0.5) want_near.push_back({slot, d});
        bool in = true;
        for (int a = 0; a < 3; ++a) in = in && lo[a] <= items[slot][a] && items[slot][a] <= hi[a];
        if (in) want_box.push_back(slot);
      }
      std::sort(all.begin(), all.end());
      all.resize(std::min<std::size_t>(3, all.size()));
      std::sort(near.begin(), near.end());
      std::sort(want_near.begin(), want_near.end());
      std::sort(box.begin(), box.end());
      EXPECT_EQ(best, all);
      EXPECT_EQ(near, want_near);
      EXPECT_EQ(box, want_box);
    }
  }
  std::vector<Block::Item> bad = {{0, 0, 0}, {1, std::nan(""), 1}};
  EXPECT_THROW(Block::build(bad), Error);
  bad = {{0, 0, 0}, {1, 1}};
  EXPECT_THROW(Block::build(bad), Error);
}

TEST(Locator, FindsEveryEntryAcrossGenerations) {
  Locator locator;
  for (Id id = 0; id < 50000; ++id) {
    locator.set(id, {1, std::uint32_t(id % 7), std::uint32_t(id)});
    if (id % 3 == 0) locator.erase(id / 3);
    if (id % 5 == 0 && locator.find(id / 5)) locator.set(id / 5, {2, 0, 0});  // moves an entry
  }
  std::size_t count = 0;
  for (Id id = 0; id < 50000; ++id) {
    const Location* at = locator.find(id);
    const bool erased = id <= 49999 / 3;
    ASSERT_EQ(at == nullptr, erased) << id;
    if (at) {
      ++count;
      EXPECT_EQ(at->slot, at->level == 2 ? 0u : std::uint32_t(id));
    }
  }
  EXPECT_EQ(count, locator.size());
  std::size_t visited = 0;
  locator.for_each([&](Id, const Location&) { ++visited; });
  EXPECT_EQ(visited, count);
  EXPECT_EQ(locator.find(50000), nullptr);
}

TEST(Locator, FarAndSparseIdsGoToTheMap) {
  Locator locator;
  for (Id id = 0; id < 5000; ++id) locator.set(id, {0, 0, std::uint32_t(id)});
  const Id far = Id(1) << 50;  // e.g. from a corrupt file: no page table up to it
  locator.set(far, {1, 1, 1});
  EXPECT_EQ(locator.spilled(), 1u);
  EXPECT_LT(locator.bytes(), std::size_t(1) << 20);
  EXPECT_EQ(locator.find(far)->slot, 1u);
  EXPECT_EQ(locator.find(far + 1), nullptr);
  for (Id id = 5000; id < 20000; ++id) locator.set(id, {0, 0, std::uint32_t(id)});  // in order: pages
  EXPECT_EQ(locator.spilled(), 1u);
  EXPECT_EQ(locator.size(), 20001u);
  locator.erase(far);
  EXPECT_EQ(locator.find(far), nullptr);
  EXPECT_EQ(locator.size(), 20000u);

  // 100 entries of ids below 10^6 (too sparse for pages), then ids from there on in order.
  Locator sparse(100, 1000000);
  for (Id id = 0; id < 1000000; id += 10000) sparse.set(id, {2, 0, std::uint32_t(id)});
  EXPECT_EQ(sparse.spilled(), 100u);
  for (Id id = 1000000; id < 1010000; ++id) sparse.set(id, {3, 0, 0});
  EXPECT_EQ(sparse.spilled(), 100u);
  EXPECT_EQ(sparse.size(), 10100u);
  EXPECT_EQ(sparse.find(990000)->level, 2u);
  EXPECT_EQ(sparse.find(1005000)->level, 3u);
  EXPECT_EQ(sparse.find(990001), nullptr);
  std::size_t visited = 0;
  sparse.for_each([&](Id id, const Location& at) {
    ++visited;
    EXPECT_EQ(at.level, id < 1000000 ? 2u : 3u);
  });
  EXPECT_EQ(visited, 10100u);

  // Dense ids below the bound: one page table for all of them at once.
  Locator dense(500000, 1000000);
  for (Id id = 1; id < 1000000; id += 2) dense.set(id, {4, 0, 0});
  EXPECT_EQ(dense.spilled(), 0u);
  EXPECT_EQ(dense.size(), 500000u);
}

TEST(Locator, ReturnsMemoryAsEntriesDie) {
  Locator locator;
  constexpr Id n = 40960;  // ten pages
  for (Id id = 0; id < n; ++id) locator.set(id, {0, 0, std::uint32_t(id)});
  const std::size_t full = locator.bytes();
  EXPECT_LT(full, n * 16) << "about 12 bytes an entry";
  for (Id id = 0; id < n; ++id)
    if (id % 16 != 0) locator.erase(id);
  EXPECT_EQ(locator.size(), n / 16);
  EXPECT_EQ(locator.spilled(), n / 16) << "a page an eighth full hands its entries to the map";
  EXPECT_LT(locator.bytes(), full / 3);
  for (Id id = 0; id < n - 1600; id += 16) locator.erase(id);
  const std::size_t before = locator.bytes();
  locator.shrink();
  EXPECT_EQ(locator.migrating(), 100u) << "the map's entries move to one of the right size in steps";
  std::size_t steps = 0;
  while (locator.migrate(16) > 0) ++steps;
  EXPECT_EQ(steps, 100u / 16 + 1);
  EXPECT_LT(locator.bytes(), before / 10);
  for (Id id = 0; id < n; ++id) ASSERT_EQ(locator.find(id) != nullptr, id % 16 == 0 && id >= n - 1600) << id;
  EXPECT_EQ(locator.find(n - 16)->slot, std::uint32_t(n - 16));
  locator.shrink();
  EXPECT_EQ(locator.migrating(), 0u) << "a map of the right size stays";
  locator.set(n + 5, {1, 2, 3});  // a fresh page
  locator.set(n - 16, {4, 5, 6});  // moves an entry of a spilled page
  EXPECT_EQ(locator.find(n + 5)->slot, 3u);
  EXPECT_EQ(locator.find(n - 16)->level, 4u);
  EXPECT_EQ(locator.spilled(), 100u);
  EXPECT_EQ(locator.size(), 101u);
  for (Id id = n - 1600; id < n; id += 16) locator.erase(id);
  locator.erase(n + 5);
  EXPECT_EQ(locator.size(), 0u);
  EXPECT_EQ(locator.find(n + 5), nullptr);
}

}  // namespace
}  // namespace geods::dynamic
