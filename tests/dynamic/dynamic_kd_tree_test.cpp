// Dyn(k-d) against a brute-force set: long seeded insert/delete/query
// sequences for both variants, with validate() after every step.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <map>
#include <vector>

#include <unistd.h>

#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"

namespace geods::dynamic {
namespace {

using Tree = DynamicKdTree<double, 2>;
using P = Tree::Point;

// The oracle: every live id and its point.
struct Oracle {
  std::map<Id, P> items;

  std::vector<Tree::Neighbor> nearest(const P& q, std::size_t k) const {
    std::vector<Tree::Neighbor> all;
    for (const auto& [id, p] : items) all.push_back({id, squared_distance(q, p)});
    std::sort(all.begin(), all.end());
    if (all.size() > k) all.resize(k);
    return all;
  }
  std::vector<Tree::Neighbor> within(const P& q, double r) const {
    std::vector<Tree::Neighbor> out;
    for (const auto& [id, p] : items)
      if (squared_distance(q, p) <= r * r) out.push_back({id, squared_distance(q, p)});
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<Id> in_box(const P& lo, const P& hi) const {
    std::vector<Id> out;
    for (const auto& [id, p] : items)
      if (lo[0] <= p[0] && p[0] <= hi[0] && lo[1] <= p[1] && p[1] <= hi[1]) out.push_back(id);
    return out;
  }
  // The same sum in the same order as spatial::KdTree, so distances compare exactly.
  static double squared_distance(const P& q, const P& p) {
    double d = 0;
    for (int a = 0; a < 2; ++a) d += (q[a] - p[a]) * (q[a] - p[a]);
    return d;
  }
};

// Coordinates on a coarse grid half of the time, so exact duplicates and distance ties are common.
P random_point(Rng& rng) {
  if (rng.below(2)) return {double(rng.below(20)), double(rng.below(20))};
  return {rng.uniform(0, 20), rng.uniform(0, 20)};
}

// heavy_deletion: as many deletes as inserts, mostly of single ids and no
// big batches, so that the worst-case variant's global reconstructions run in
// steps across many operations (while they are under way, items are inserted,
// deleted before and after being copied, and queried).
struct SequenceResult {
  std::size_t steps_reconstructing = 0;
};

void run_sequence(Variant variant, std::uint64_t seed, int steps, bool heavy_deletion = false,
                  SequenceResult* out = nullptr) {
  Rng rng(seed);
  Tree tree(DynamizeOptions{variant});
  Oracle oracle;
  std::vector<P> removed_points;
  SequenceResult result;
  if (out) *out = result;
  for (int step = 0; step < steps; ++step) {
    const std::uint64_t op = rng.below(10);
    const bool insert = heavy_deletion ? op < 4 || (op < 6 && step % 800 < 400) : op < 5;
    if (insert || oracle.items.empty()) {
      // Insert a batch; sometimes re-insert points removed earlier, sometimes a big batch (bulk build).
      std::vector<double> coords;
      const std::size_t count = heavy_deletion ? (rng.below(20) == 0 ? 1 + rng.below(30) : 1)
                                : rng.below(8) == 0 ? 1 + rng.below(200)
                                                    : 1 + rng.below(6);
      for (std::size_t i = 0; i < count; ++i) {
        const P p = !removed_points.empty() && rng.below(4) == 0 ? removed_points[rng.below(removed_points.size())]
                                                                 : random_point(rng);
        coords.insert(coords.end(), p.begin(), p.end());
      }
      const std::vector<Id> ids = tree.insert(spatial::PointView<double>(coords.data(), count, 2));
      ASSERT_EQ(ids.size(), count);
      for (std::size_t i = 0; i < count; ++i) {
        ASSERT_EQ(oracle.items.count(ids[i]), 0u) << "ids are never reused";
        oracle.items[ids[i]] = {coords[2 * i], coords[2 * i + 1]};
      }
    } else if (op < 8) {
      // Remove a few random live ids (sometimes many, to trigger reconstructions).
      std::vector<Id> live;
      for (const auto& [id, p] : oracle.items) live.push_back(id);
      std::shuffle(live.begin(), live.end(), rng);
      const std::size_t count = std::min(live.size(), heavy_deletion         ? 1 + rng.below(3)
                                                      : rng.below(10) == 0 ? live.size() / 2 + 1
                                                                           : 1 + rng.below(4));
      live.resize(count);
      tree.remove(live);
      for (Id id : live) {
        removed_points.push_back(oracle.items.at(id));
        oracle.items.erase(id);
      }
    } else {
      const P q = random_point(rng);
      const std::size_t k = 1 + rng.below(12);
      ASSERT_EQ(tree.query(q, k), oracle.nearest(q, k)) << "step " << step;
      const double r = rng.uniform(0, 4);
      ASSERT_EQ(tree.query_radius(q, r), oracle.within(q, r)) << "step " << step;
      const P lo = random_point(rng), hi{lo[0] + rng.uniform(0, 8), lo[1] + rng.uniform(0, 8)};
      ASSERT_EQ(tree.query_box(lo, hi), oracle.in_box(lo, hi)) << "step " << step;
    }
    ASSERT_EQ(tree.size(), oracle.items.size());
    ASSERT_NO_THROW(tree.validate()) << "step " << step;
    result.steps_reconstructing += tree.stats().structure.reconstructing;
    if (heavy_deletion && step % 50 == 0) {
      for (const auto& [id, p] : oracle.items) ASSERT_EQ(tree.point(id), p) << "step " << step;
    }
  }
  for (const auto& [id, p] : oracle.items) EXPECT_EQ(tree.point(id), p);
  const DynamizedStats s = tree.stats().structure;
  EXPECT_GE(s.rebuilds, 2u) << "the sequence reaches the reconstruction threshold";
  EXPECT_EQ(s.forced_rebuilds, 0u) << "every reconstruction finished within its schedule";
  if (out) *out = result;
}

TEST(DynamicKdTree, RandomSequenceAmortized) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) run_sequence(Variant::amortized, seed, 3000);
}

TEST(DynamicKdTree, RandomSequenceWorstCase) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) run_sequence(Variant::worst_case, seed, 3000);
}

TEST(DynamicKdTree, HeavyDeletionSequenceWorstCase) {
  for (std::uint64_t seed = 11; seed <= 14; ++seed) {
    SequenceResult r;
    run_sequence(Variant::worst_case, seed, 4000, true, &r);
    EXPECT_GE(r.steps_reconstructing, 100u) << "reconstructions run across many operations";
  }
}

TEST(DynamicKdTree, HeavyDeletionSequenceAmortized) {
  for (std::uint64_t seed = 11; seed <= 12; ++seed) run_sequence(Variant::amortized, seed, 4000, true);
}

// The work a single operation pays (DynamizedStats::work: element visits of
// gathering, building and relocating, a deterministic count) in a
// deletion-heavy sequence: the worst case stays within O(log^2 n) per
// operation, far below n, where the amortized variant's reconstruction costs
// Theta(n log n) in one delete.
std::pair<std::size_t, std::size_t> max_work(Variant variant, std::size_t n) {
  Tree tree(DynamizeOptions{variant});
  Rng rng(21);
  std::vector<Id> live;
  std::size_t worst_insert = 0, worst_delete = 0;
  auto measure = [&](std::size_t& worst, const auto& op) {
    const std::size_t before = tree.stats().structure.work;
    op();
    worst = std::max(worst, tree.stats().structure.work - before);
  };
  for (std::size_t i = 0; i < n; ++i) measure(worst_insert, [&] { live.push_back(tree.insert(random_point(rng))); });
  // Two deletes per insert until a sixteenth is left: several reconstructions.
  while (live.size() > n / 16) {
    for (int d = 0; d < 2; ++d) {
      const std::size_t i = rng.below(live.size());
      measure(worst_delete, [&] { tree.remove(live[i]); });
      live[i] = live.back();
      live.pop_back();
    }
    measure(worst_insert, [&] { live.push_back(tree.insert(random_point(rng))); });
  }
  tree.validate();
  const DynamizedStats s = tree.stats().structure;
  EXPECT_GE(s.rebuilds, 3u);
  EXPECT_EQ(s.forced_rebuilds, 0u);
  EXPECT_EQ(s.forced_builds, 0u);
  return {worst_insert, worst_delete};
}

TEST(DynamicKdTree, WorstCaseBoundsTheWorkOfEveryOperation) {
  constexpr std::size_t n = 1 << 15;
  const double log_n = std::log2(double(n));
  const auto [worst_insert, worst_delete] = max_work(Variant::worst_case, n);
  const auto [amortized_insert, amortized_delete] = max_work(Variant::amortized, n);
  std::printf("max work per operation, n = %zu: worst case insert %zu, delete %zu; amortized insert %zu, delete %zu\n",
              n, worst_insert, worst_delete, amortized_insert, amortized_delete);
  EXPECT_LE(double(worst_delete), 64 * log_n) << "a delete's share of a reconstruction is O(B(n) / n)";
  EXPECT_LE(double(worst_insert), 8 * log_n * log_n) << "an insert's share of the merges is O(log n B(n) / n)";
  EXPECT_LT(worst_delete, n / 8);
  EXPECT_GE(amortized_delete, n) << "the amortized variant rebuilds in one delete";
}

TEST(DynamicKdTree, AmortizedDecompositionFollowsTheBinaryRepresentation) {
  Tree tree;
  Rng rng(7);
  for (std::size_t n = 1; n <= 300; ++n) {
    tree.insert(random_point(rng));
    const DynamizedStats s = tree.stats().structure;
    for (std::size_t i = 0; i < 12; ++i)
      ASSERT_EQ(i < s.per_level.size() ? s.per_level[i] : 0, (n >> i) & 1) << "n = " << n << ", level " << i;
    tree.validate();
  }
}

// A batch (amortized variant) rebuilds only the levels its carry reaches, once:
// the structures above the highest bit where the slot count changes stay as
// they are, the levels still follow the binary representation, and the answers
// are brute force's.
TEST(DynamicKdTree, AmortizedBatchRebuildsOnlyTheCarriedLevels) {
  Tree tree;
  Oracle oracle;
  Rng rng(17);
  auto add = [&](std::size_t count) {
    std::vector<double> coords;
    for (std::size_t i = 0; i < count; ++i) {
      const P p = random_point(rng);
      coords.insert(coords.end(), p.begin(), p.end());
    }
    const std::vector<Id> ids = tree.insert(spatial::PointView<double>(coords.data(), count, 2));
    for (std::size_t i = 0; i < count; ++i) oracle.items[ids[i]] = {coords[2 * i], coords[2 * i + 1]};
  };
  for (std::size_t i = 0; i < 700; ++i) add(1);
  std::vector<Id> gone;
  for (Id id = 0; id < 700; id += 3) gone.push_back(id), oracle.items.erase(id);
  tree.remove(gone);  // dead slots travel with their structures
  for (const std::size_t batch : {2, 5, 37, 64, 1, 300, 129}) {
    const std::size_t slots = tree.size() + tree.structure().dead(), total = slots + batch;
    const std::size_t kept = std::size_t(2) << (std::bit_width(slots ^ total) - 1);  // structures this large stay
    std::vector<const Tree::Block*> before, after;
    tree.structure().for_each([&](const Tree::Block& b, std::span<const Id>) {
      if (b.size() >= kept) before.push_back(&b);
    });
    add(batch);
    tree.structure().for_each([&](const Tree::Block& b, std::span<const Id>) {
      if (b.size() >= kept) after.push_back(&b);
    });
    EXPECT_EQ(after, before) << "batch " << batch;
    const DynamizedStats s = tree.stats().structure;
    for (std::size_t i = 0; i < 12; ++i)
      ASSERT_EQ(i < s.per_level.size() ? s.per_level[i] : 0, (total >> i) & 1) << "batch " << batch << ", level " << i;
    ASSERT_NO_THROW(tree.validate());
    for (int k = 0; k < 20; ++k) {
      const P q = random_point(rng);
      ASSERT_EQ(tree.query(q, 7), oracle.nearest(q, 7));
    }
  }
}

TEST(DynamicKdTree, WorstCaseSpreadsBuildsOverInserts) {
  Tree tree(DynamizeOptions{Variant::worst_case});
  Rng rng(8);
  std::size_t max_building = 0;
  for (int n = 0; n < 20000; ++n) {
    tree.insert(random_point(rng));
    max_building = std::max(max_building, tree.stats().structure.building);
    if (n % 997 == 0) tree.validate();
  }
  tree.validate();
  const DynamizedStats s = tree.stats().structure;
  EXPECT_GE(max_building, 3u) << "builds on several levels run at the same time";
  EXPECT_EQ(s.forced_builds, 0u) << "every build finished within its schedule";
  std::size_t slots = 0;
  for (std::size_t i = 0; i < s.per_level.size(); ++i) {
    EXPECT_LE(s.per_level[i], 3u);
    slots += s.per_level[i] << i;
  }
  EXPECT_EQ(slots, 20000u);
}

// Deletions while builds are under way and while their items are relocated:
// each removal hits a source, a structure being relocated, or a finished one.
TEST(DynamicKdTree, WorstCaseDeletesDuringBuilds) {
  Tree tree(DynamizeOptions{Variant::worst_case});
  Rng rng(9);
  std::vector<Id> live;
  std::size_t max_building = 0;
  for (int step = 0; step < 6000; ++step) {
    live.push_back(tree.insert(random_point(rng)));
    if (step % 3 == 2) {
      const std::size_t i = rng.below(live.size());
      tree.remove(live[i]);
      live[i] = live.back();
      live.pop_back();
    }
    max_building = std::max(max_building, tree.stats().structure.building);
    if (step % 7 == 0 || step > 5900) {
      ASSERT_NO_THROW(tree.validate()) << "step " << step;
    }
  }
  EXPECT_GE(max_building, 3u);
  EXPECT_EQ(tree.size(), live.size());
  for (Id id : live) ASSERT_TRUE(tree.contains(id));
  const P q{10, 10};
  const auto all = tree.query_radius(q, 100);
  EXPECT_EQ(all.size(), live.size());
}

TEST(DynamicKdTree, MemoryReturnsAfterMassDeletion) {
  for (Variant variant : {Variant::amortized, Variant::worst_case}) {
    Tree tree(DynamizeOptions{variant});
    Rng rng(3);
    std::vector<Id> ids;
    for (int i = 0; i < 20000; ++i) ids.push_back(tree.insert(random_point(rng)));
    const std::size_t full = tree.stats().bytes;
    // Delete 95 % in small batches: reconstructions happen on the way, at the latest
    // when more than half of the slots are dead.
    for (std::size_t i = 0; i < 19000; i += 100) tree.remove(std::span<const Id>(ids.data() + i, 100));
    tree.validate();
    EXPECT_LE(tree.stats().structure.dead, 3 * tree.size()) << "at most 3/4 dead while a reconstruction runs";
    // The worst case reconstructs in steps: a few more operations let it finish.
    for (int i = 0; i < 10000 && tree.stats().structure.reconstructing; ++i) tree.remove(tree.insert(random_point(rng)));
    tree.validate();
    const DynamicKdTreeStats after = tree.stats();
    EXPECT_FALSE(after.structure.reconstructing);
    EXPECT_EQ(tree.size(), 1000u);
    EXPECT_GE(after.structure.rebuilds, 1u);
    EXPECT_LE(after.structure.dead, tree.size());
    EXPECT_LT(after.bytes, full / 5) << "full " << full << " bytes, after " << after.bytes;
    tree.rebuild();
    EXPECT_EQ(tree.stats().structure.dead, 0u);
    EXPECT_LT(tree.stats().bytes, full / 10);
    tree.validate();
    for (std::size_t i = 19000; i < ids.size(); ++i) EXPECT_TRUE(tree.contains(ids[i]));
  }
}

TEST(DynamicKdTree, ReinsertingARemovedPointDoesNotDuplicateIt) {
  for (Variant variant : {Variant::amortized, Variant::worst_case}) {
    Tree tree(DynamizeOptions{variant});
    Rng rng(4);
    for (int i = 0; i < 100; ++i) tree.insert(random_point(rng));
    const P p{100.5, -3.25};
    const Id a = tree.insert(p);
    tree.remove(a);
    const Id b = tree.insert(p);
    EXPECT_NE(a, b);
    EXPECT_FALSE(tree.contains(a));
    const auto at_p = tree.query_radius(p, 0.0);
    ASSERT_EQ(at_p.size(), 1u);
    EXPECT_EQ(at_p[0].index, b);
    EXPECT_THROW(tree.remove(a), Error);
    // After a reconstruction, still one copy.
    tree.rebuild();
    EXPECT_EQ(tree.query_radius(p, 0.0).size(), 1u);
    EXPECT_EQ(tree.size(), 101u);
    tree.validate();
  }
}

TEST(DynamicKdTree, BadInputThrowsAndChangesNothing) {
  Tree tree;
  const std::vector<Id> ids = tree.insert(spatial::PointView<double>(std::vector<double>{0, 0, 1, 1}.data(), 2, 2));
  const double nan = std::nan("");
  const std::vector<double> bad{0, 0, nan, 1};
  EXPECT_THROW(tree.insert(spatial::PointView<double>(bad.data(), 2, 2)), Error);
  const std::vector<double> three{0, 0, 0};
  EXPECT_THROW(tree.insert(spatial::PointView<double>(three.data(), 1, 3)), Error);
  EXPECT_EQ(tree.size(), 2u);
  const std::vector<Id> unknown{ids[0], 12345};
  EXPECT_THROW(tree.remove(unknown), Error);
  const std::vector<Id> twice{ids[1], ids[1]};
  EXPECT_THROW(tree.remove(twice), Error);
  EXPECT_EQ(tree.size(), 2u) << "a failed batch removes nothing";
  EXPECT_THROW(tree.query(P{0, 0}, 0), Error);
  EXPECT_THROW(tree.query(std::span<const double>(three), 1), Error);
  const double inf = INFINITY;
  EXPECT_THROW(tree.query(P{inf, 0}, 1), Error);
  EXPECT_THROW(tree.query_radius(P{0, 0}, -1), Error);
  EXPECT_THROW(tree.point(999), Error);
  EXPECT_THROW(Tree(DynamizeOptions{Variant::amortized, 1.5}), Error);
  tree.validate();
}

TEST(DynamicKdTree, EmptyTreeAnswersNothing) {
  Tree tree(DynamizeOptions{Variant::worst_case});
  EXPECT_TRUE(tree.query(P{1, 2}, 3).empty());
  EXPECT_TRUE(tree.query_radius(P{1, 2}, 10).empty());
  tree.validate();
  const Id id = tree.insert(P{1, 2});
  tree.remove(id);
  EXPECT_TRUE(tree.query(P{1, 2}, 3).empty());
  EXPECT_EQ(tree.stats().structure.structures, 0u) << "removing the only item rebuilds to nothing";
  tree.validate();
}

// KnnRequest (eps, max_distance) and a run-time dimension, which the blocks
// (spatial::KdTree) provide: against brute force over the live items, with
// duplicates and deletions, for both variants.
template <int Dim>
void check_requests(Variant variant, std::size_t dim) {
  SCOPED_TRACE("dim " + std::to_string(dim));
  using DTree = DynamicKdTree<double, Dim>;
  Rng rng(30 + dim);
  DTree tree = [&] {
    if constexpr (Dim == spatial::Dynamic)
      return DTree(dim, DynamizeOptions{variant});
    else
      return DTree(DynamizeOptions{variant});
  }();
  EXPECT_EQ(tree.dim(), dim);
  std::map<Id, std::vector<double>> live;
  auto random_row = [&] {
    std::vector<double> p(dim);
    for (double& x : p) x = rng.below(2) ? double(rng.below(5)) : rng.uniform(0, 5);  // duplicates and ties
    return p;
  };
  for (int step = 0; step < 1500; ++step) {
    const std::vector<double> p = random_row();
    typename DTree::Point point{};
    if constexpr (Dim == spatial::Dynamic) point.resize(dim);
    std::copy(p.begin(), p.end(), point.begin());
    live[tree.insert(point)] = p;
    if (step % 3 == 2) {
      auto it = live.begin();
      std::advance(it, rng.below(live.size()));
      tree.remove(it->first);
      live.erase(it);
    }
    if (step % 100 != 99) continue;
    ASSERT_NO_THROW(tree.validate());
    const std::vector<double> q = random_row();
    std::vector<typename DTree::Neighbor> all;
    for (const auto& [id, x] : live) {
      double d = 0;
      for (std::size_t a = 0; a < dim; ++a) d += (q[a] - x[a]) * (q[a] - x[a]);
      all.push_back({id, d});
    }
    std::sort(all.begin(), all.end());
    const std::size_t k = 1 + rng.below(15);
    const auto exact = tree.query(q, spatial::KnnRequest{k});
    ASSERT_EQ(exact, std::vector<typename DTree::Neighbor>(all.begin(), all.begin() + std::min(k, all.size())));
    const double r = rng.uniform(0, 2);
    std::vector<typename DTree::Neighbor> within;
    for (const auto& nb : all)
      if (nb.squared_distance <= r * r) within.push_back(nb);
    ASSERT_EQ(tree.query(q, spatial::KnnRequest{k, 0, r}),
              std::vector<typename DTree::Neighbor>(within.begin(), within.begin() + std::min(k, within.size())));
    ASSERT_EQ(tree.query_radius(q, r), within);
    for (double eps : {0.25, 2.0}) {
      const auto approx = tree.query(q, k, eps);
      ASSERT_EQ(approx.size(), std::min(k, all.size()));
      for (std::size_t j = 0; j < approx.size(); ++j) {
        ASSERT_TRUE(live.count(approx[j].index)) << "a deleted or unknown id";
        ASSERT_LE(std::sqrt(approx[j].squared_distance), (1 + eps) * std::sqrt(all[j].squared_distance) * (1 + 1e-9) + 1e-12);
        if (j > 0) {
          ASSERT_TRUE(approx[j - 1] < approx[j]);
        }
      }
    }
    std::vector<double> lo = random_row(), hi(dim);
    for (std::size_t a = 0; a < dim; ++a) hi[a] = lo[a] + rng.uniform(0, 3);
    std::vector<Id> in_box;
    for (const auto& [id, x] : live) {
      bool in = true;
      for (std::size_t a = 0; a < dim; ++a) in = in && lo[a] <= x[a] && x[a] <= hi[a];
      if (in) in_box.push_back(id);
    }
    ASSERT_EQ(tree.query_box(lo, hi), in_box);
  }
  for (const auto& [id, x] : live) {
    const auto p = tree.point(id);
    ASSERT_TRUE(std::equal(x.begin(), x.end(), p.begin()));
  }
  EXPECT_THROW(tree.query(std::vector<double>(dim + 1, 0.0), 1), Error);
  EXPECT_THROW(tree.query(std::vector<double>(dim, 0.0), spatial::KnnRequest{1, -1}), Error);
  EXPECT_THROW(tree.query(std::vector<double>(dim, 0.0), spatial::KnnRequest{1, 0, -1}), Error);
}

TEST(DynamicKdTree, RequestsAndRunTimeDimensionMatchBruteForce) {
  for (Variant variant : {Variant::amortized, Variant::worst_case}) {
    check_requests<2>(variant, 2);
    check_requests<spatial::Dynamic>(variant, 1);
    check_requests<spatial::Dynamic>(variant, 4);
  }
  EXPECT_THROW((DynamicKdTree<float, spatial::Dynamic>(0)), Error);
  EXPECT_THROW((DynamicKdTree<float, 3>(2)), Error);
}

// save / load: the same answers, ids, points and deletions, for both variants
// (the worst case mid-build and mid-reconstruction); later inserts continue
// the ids; bad files throw.
std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("geods_dynamic_" + name + "_" + std::to_string(::getpid()));
}

// Exact answers only: (1 + eps) ones may differ between two decompositions of one set.
void expect_same_answers(const Tree& a, const Tree& b, Rng& rng) {
  ASSERT_EQ(a.size(), b.size());
  for (int i = 0; i < 40; ++i) {
    const P q = random_point(rng);
    ASSERT_EQ(a.query(q, 7), b.query(q, 7));
    ASSERT_EQ(a.query_radius(q, 2.5), b.query_radius(q, 2.5));
    const P hi{q[0] + 5, q[1] + 3};
    ASSERT_EQ(a.query_box(q, hi), b.query_box(q, hi));
  }
}

TEST(DynamicKdTree, SaveLoadRoundTrip) {
  for (Variant variant : {Variant::amortized, Variant::worst_case}) {
    Tree tree(DynamizeOptions{variant, 0.4});
    Rng rng(40);
    std::vector<Id> live;
    for (int i = 0; i < 3000; ++i) {
      live.push_back(tree.insert(random_point(rng)));
      if (i % 3 == 1) {
        const std::size_t j = rng.below(live.size());
        tree.remove(live[j]);
        live[j] = live.back();
        live.pop_back();
      }
    }
    // Deletions without inserts leave a reconstruction under way in the worst case.
    for (int i = 0; i < 600; ++i) {
      tree.remove(live.back());
      live.pop_back();
    }
    const DynamizedStats before = tree.stats().structure;
    if (variant == Variant::worst_case) {
      EXPECT_TRUE(before.reconstructing || before.building > 0);
    }
    const auto path = temp_path("round_trip");
    tree.save(path);
    Tree loaded = Tree::load(path);
    loaded.validate();
    EXPECT_EQ(loaded.structure().options().variant, variant);
    EXPECT_EQ(loaded.structure().options().max_dead_fraction, 0.4);
    for (Id id : live) ASSERT_EQ(loaded.point(id), tree.point(id));
    EXPECT_EQ(loaded.stats().structure.dead, before.dead);
    // The blocks' trees read their nodes, permutation and slots in place from the file.
    loaded.structure().for_each([](const auto& block, std::span<const Id>) {
      if (block.small()) return;
      EXPECT_TRUE(block.tree().nodes().mapped());
      EXPECT_TRUE(block.tree().permutation().mapped());
      EXPECT_TRUE(block.slots().mapped());
    });
    expect_same_answers(tree, loaded, rng);
    // Both go on the same way: the same ids for the same inserts, the same answers.
    for (int i = 0; i < 500; ++i) {
      const P p = random_point(rng);
      ASSERT_EQ(tree.insert(p), loaded.insert(p));
      if (i % 2) {
        tree.remove(live[i]);
        loaded.remove(live[i]);
      }
    }
    loaded.validate();
    expect_same_answers(tree, loaded, rng);
    // An empty tree round-trips too.
    Tree(DynamizeOptions{variant}).save(path);
    EXPECT_TRUE(Tree::load(path).empty());
    std::filesystem::remove(path);
  }
}

TEST(DynamicKdTree, BadFilesThrow) {
  Tree tree;
  Rng rng(41);
  for (int i = 0; i < 300; ++i) tree.insert(random_point(rng));
  for (Id id = 0; id < 300; id += 3) tree.remove(id);
  const auto path = temp_path("good"), bad = temp_path("bad");
  tree.save(path);
  std::vector<char> good(std::filesystem::file_size(path));
  std::ifstream(path, std::ios::binary).read(good.data(), std::streamsize(good.size()));
  auto write = [&](const std::vector<char>& bytes) {
    std::ofstream(bad, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  };
  for (std::size_t n = 0; n < good.size(); n += 1 + n / 8) {
    write(std::vector<char>(good.begin(), good.begin() + std::ptrdiff_t(n)));
    EXPECT_THROW(Tree::load(bad), Error) << "truncated to " << n << " bytes";
  }
  for (std::size_t at = 0; at < good.size(); at += 1 + at / 16) {
    std::vector<char> flipped = good;
    flipped[at] = char(flipped[at] ^ 0x5a);
    write(flipped);
    try {
      const Tree t = Tree::load(bad);
      t.validate();  // a flip in the padding between sections changes nothing
      EXPECT_EQ(t.size(), tree.size()) << "flipped byte " << at;
    } catch (const Error&) {
    }
  }
  using FloatTree = DynamicKdTree<float, 2>;
  using Tree3 = DynamicKdTree<double, 3>;
  using AnyTree = DynamicKdTree<double, spatial::Dynamic>;
  EXPECT_THROW(FloatTree::load(path), Error) << "float, saved as double";
  EXPECT_THROW(Tree3::load(path), Error) << "another dimension";
  EXPECT_EQ(AnyTree::load(path).size(), tree.size());
  ArchiveWriter other("spatial.KdTree", 1);
  other.add_value("dim", std::uint64_t(2));
  other.write(bad);
  EXPECT_THROW(Tree::load(bad), Error) << "another kind of archive";
  EXPECT_THROW(Tree::load(temp_path("missing")), Error);
  std::filesystem::remove(path);
  std::filesystem::remove(bad);
}

TEST(DynamicKdTree, BatchQueriesMatchSingleOnes) {
  DynamicKdTree<float, 3> tree(DynamizeOptions{Variant::worst_case});
  Rng rng(5);
  std::vector<float> coords(3 * 3000);
  for (float& x : coords) x = float(rng.uniform());
  tree.insert(spatial::PointView<float>(coords.data(), 1000, 3));
  for (std::size_t i = 1000; i < 3000; ++i) tree.insert({coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]});
  std::vector<float> queries(3 * 50);
  for (float& x : queries) x = float(rng.uniform());
  const auto batch = tree.query_batch(spatial::PointView<float>(queries.data(), 50, 3), 4);
  for (std::size_t i = 0; i < 50; ++i) {
    const auto single = tree.query(std::span<const float>(queries.data() + 3 * i, 3), 4);
    ASSERT_EQ(single.size(), 4u);
    for (std::size_t j = 0; j < 4; ++j) EXPECT_EQ(batch[4 * i + j], single[j]);
  }
}

}  // namespace
}  // namespace geods::dynamic
