// The one-tree traversal against brute force (unordered sphere query,
// ordered nearest triangle box, stopping, degenerate trees) and the
// simultaneous traversal against all pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>

#include "bvh_test_util.hpp"
#include "geods/bvh/traversal.hpp"

namespace geods::bvh {
namespace {

AABB3f triangle_box(const TriMesh& m, std::size_t t) {
  AABB3f box;
  for (int k = 0; k < 3; ++k) box.extend(test::corner(m, t, k));
  return box;
}

// Every triangle whose box meets a ball, unordered: exactly the brute-force set.
TEST(Traversal, UnorderedQueryReachesExactlyTheAcceptedLeaves) {
  const TriMesh soup = test::random_soup(3000, 71);
  Rng rng(72);
  for (int arity : {2, 4, 8}) {
    BuildOptions options;
    options.arity = arity;
    options.builder = arity == 2 ? Builder::insertion : Builder::sah;  // insertion: deep trees, heap stack
    const TriangleBvh bvh = TriangleBvh::build(soup, options);
    const auto& boxes = std::get<FlatArray<AABB3f>>(bvh.volumes());
    for (int q = 0; q < 30; ++q) {
      const Vec3f c = test::random_point(rng, -1.2f, 1.2f);
      const float r2 = float(rng.uniform(0.0, 0.3));
      std::vector<std::uint32_t> expected, found;
      for (std::size_t t = 0; t < soup.num_triangles(); ++t)
        if (triangle_box(soup, t).squared_distance(c) <= r2) expected.push_back(std::uint32_t(t));
      TraversalStack<NodeRef> stack(traversal_stack_size(bvh.topology().depth(), arity));
      const bool finished = traverse_topology<false>(
          bvh.topology(), 0, stack, [&](std::uint32_t node, float&) { return boxes[node].squared_distance(c) <= r2; },
          [&](const TopoNode& leaf) {
            for (std::uint32_t i = leaf.prim_first; i < leaf.prim_first + leaf.prim_count; ++i) {
              const std::uint32_t t = bvh.triangle_ids()[i];
              if (triangle_box(soup, t).squared_distance(c) <= r2) found.push_back(t);
            }
          },
          [](float) { return true; });
      EXPECT_TRUE(finished);
      std::sort(found.begin(), found.end());
      ASSERT_EQ(found, expected) << "arity " << arity << " query " << q;
    }
  }
}

// Ordered by distance with pruning: the nearest triangle box; a leaf is only
// visited while it may hold something nearer than the best so far, so most
// leaves are never visited.
TEST(Traversal, OrderedQueryFindsTheNearestAndVisitsLeavesNearFirst) {
  const TriMesh soup = test::random_soup(3000, 73);
  Rng rng(74);
  for (int arity : {2, 4}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(soup, options);
    const auto& boxes = std::get<FlatArray<AABB3f>>(bvh.volumes());
    TraversalStack<NodeRef> stack(traversal_stack_size(bvh.topology().depth(), arity));
    const int total_leaves = int(bvh.stats().leaves);
    for (int q = 0; q < 50; ++q) {
      const Vec3f c = test::random_point(rng, -2, 2);
      float want = std::numeric_limits<float>::infinity();
      for (std::size_t t = 0; t < soup.num_triangles(); ++t) want = std::min(want, triangle_box(soup, t).squared_distance(c));
      float best = std::numeric_limits<float>::infinity();
      int leaves = 0;
      traverse_topology<true>(
          bvh.topology(), 0, stack,
          [&](std::uint32_t node, float& d2) {
            d2 = boxes[node].squared_distance(c);
            return d2 <= best;
          },
          [&](const TopoNode& leaf) {
            ++leaves;
            EXPECT_LE(boxes[std::size_t(&leaf - bvh.topology().nodes.data())].squared_distance(c), best);
            for (std::uint32_t i = leaf.prim_first; i < leaf.prim_first + leaf.prim_count; ++i)
              best = std::min(best, triangle_box(soup, bvh.triangle_ids()[i]).squared_distance(c));
          },
          [&](float d2) { return d2 <= best; });
      ASSERT_EQ(best, want) << q;
      EXPECT_LT(leaves * 4, total_leaves) << "pruning";
    }
  }
}

// Best-first (a heap by key): the nearest triangle box again; the leaves come
// in the order of their keys, none above the answer; a leaf callback
// returning false stops it.
TEST(Traversal, BestFirstQueryVisitsLeavesInKeyOrderUpToTheAnswer) {
  const TriMesh soup = test::random_soup(3000, 75);
  Rng rng(76);
  for (int arity : {2, 4}) {
    BuildOptions options;
    options.arity = arity;
    const TriangleBvh bvh = TriangleBvh::build(soup, options);
    const auto& boxes = std::get<FlatArray<AABB3f>>(bvh.volumes());
    const TopoNode* nodes = bvh.topology().nodes.data();
    std::vector<NodeRef> heap;
    for (int q = 0; q < 50; ++q) {
      const Vec3f c = test::random_point(rng, -2, 2);
      float want = std::numeric_limits<float>::infinity();
      for (std::size_t t = 0; t < soup.num_triangles(); ++t) want = std::min(want, triangle_box(soup, t).squared_distance(c));
      float best = std::numeric_limits<float>::infinity(), last = -1;
      int leaves = 0;
      auto leaf = [&](const NodeRef& e) {
        ++leaves;
        EXPECT_GE(e.key, last) << "key order";
        EXPECT_LE(e.key, want) << "a leaf beyond the answer";
        last = e.key;
        const TopoNode& n = nodes[e.node];
        for (std::uint32_t i = n.prim_first; i < n.prim_first + n.prim_count; ++i)
          best = std::min(best, triangle_box(soup, bvh.triangle_ids()[i]).squared_distance(c));
      };
      auto children = [&](const NodeRef& e, float* keys) {
        unsigned bits = 0;
        for (std::uint32_t k = 0; k < nodes[e.node].num_children; ++k) {
          keys[k] = boxes[nodes[e.node].first_child + k].squared_distance(c);
          if (keys[k] < best) bits |= 1u << k;
        }
        return bits;
      };
      auto child = [&](const NodeRef& e, int k, float key) { return NodeRef{nodes[e.node].first_child + std::uint32_t(k), key}; };
      auto is_leaf = [&](const NodeRef& e) { return nodes[e.node].leaf(); };
      const NodeRef root{0, boxes[0].squared_distance(c)};
      EXPECT_TRUE(traverse_best_first<8>(root, heap, is_leaf, children, child, leaf,
                                         [&](const NodeRef& e) { return e.key < best; }));
      ASSERT_EQ(best, want) << q;
      // Only leaves whose key is at most the answer can be visited (branch and bound at its best).
      int below = 0;
      for (std::size_t n = 0; n < bvh.topology().nodes.size(); ++n) below += nodes[n].leaf() && boxes[n].squared_distance(c) <= want;
      EXPECT_LE(leaves, below) << q;
      // Stopped by the leaf callback after two leaves.
      int calls = 0;
      best = std::numeric_limits<float>::infinity();
      EXPECT_FALSE(traverse_best_first<8>(root, heap, is_leaf, children, child,
                                          [&](const NodeRef&) { return ++calls < 2; },
                                          [](const NodeRef&) { return true; }));
      EXPECT_EQ(calls, 2);
    }
  }
}

TEST(Traversal, StopsWhenTheLeafCallbackSaysSoAndHandlesTinyTrees) {
  const TriMesh soup = test::random_soup(500, 75);
  const TriangleBvh bvh = TriangleBvh::build(soup);
  TraversalStack<NodeRef> stack(traversal_stack_size(bvh.topology().depth(), 4));
  int calls = 0;
  auto all = [](std::uint32_t, float&) { return true; };
  auto keep = [](float) { return true; };
  EXPECT_FALSE(traverse_topology<false>(bvh.topology(), 0, stack, all, [&](const TopoNode&) { return ++calls < 3; }, keep));
  EXPECT_EQ(calls, 3);
  // No nodes, a rejected root, a single leaf.
  calls = 0;
  EXPECT_TRUE(traverse_topology<true>(Topology{}, 0, stack, all, [&](const TopoNode&) { ++calls; }, keep));
  EXPECT_TRUE(traverse_topology<true>(bvh.topology(), 0, stack, [](std::uint32_t, float&) { return false; },
                                      [&](const TopoNode&) { ++calls; }, keep));
  EXPECT_EQ(calls, 0);
  const TriMesh one = test::random_soup(1, 76);
  const TriangleBvh single = TriangleBvh::build(one);
  EXPECT_TRUE(traverse_topology<true>(single.topology(), 0, stack, all, [&](const TopoNode& leaf) { calls += leaf.prim_count; }, keep));
  EXPECT_EQ(calls, 1);
}

// Every pair of triangles whose own fitted volumes overlap must be reached:
// the volumes of their ancestors contain those.
template <typename BV, typename Fit>
void check_all_pairs(BoundingVolume kind, Fit fit) {
  const TriMesh a = test::random_soup(600, 51), b = test::random_soup(500, 52);
  auto volume_of = [&](const TriMesh& m, std::size_t t) {
    const std::array<Vec3f, 3> corners = {test::corner(m, t, 0), test::corner(m, t, 1), test::corner(m, t, 2)};
    return fit(std::span<const Vec3f>(corners));
  };
  std::set<std::pair<std::uint32_t, std::uint32_t>> expected;
  for (std::size_t i = 0; i < a.num_triangles(); ++i)
    for (std::size_t j = 0; j < b.num_triangles(); ++j)
      if (overlaps(volume_of(a, i), volume_of(b, j))) expected.insert({std::uint32_t(i), std::uint32_t(j)});
  ASSERT_GT(expected.size(), 100u);
  for (int arity : {2, 4}) {
    BuildOptions options;
    options.bv = kind;
    options.arity = arity;
    const TriangleBvh ba = TriangleBvh::build(a, options), bb = TriangleBvh::build(b, options);
    const auto& va = std::get<FlatArray<BV>>(ba.volumes());
    const auto& vb = std::get<FlatArray<BV>>(bb.volumes());
    std::set<std::pair<std::uint32_t, std::uint32_t>> found;
    traverse_simultaneously(
        ba.topology(), bb.topology(), [&](std::uint32_t i, std::uint32_t j) { return overlaps(va[i], vb[j]); },
        [&](std::uint32_t i, std::uint32_t j) {
          const TopoNode& la = ba.topology().nodes[i];
          const TopoNode& lb = bb.topology().nodes[j];
          for (std::uint32_t s = la.prim_first; s < la.prim_first + la.prim_count; ++s)
            for (std::uint32_t t = lb.prim_first; t < lb.prim_first + lb.prim_count; ++t) {
              const std::uint32_t ia = ba.triangle_ids()[s], ib = bb.triangle_ids()[t];
              if (overlaps(volume_of(a, ia), volume_of(b, ib))) found.insert({ia, ib});
            }
        });
    EXPECT_EQ(found, expected) << to_string(kind) << " arity " << arity;
  }
}

TEST(SimultaneousTraversal, FindsEveryPairOfOverlappingTriangleVolumes) {
  check_all_pairs<AABB3f>(BoundingVolume::aabb, [](std::span<const Vec3f> p) { return fit_aabb<float>(p); });
  check_all_pairs<Kdop<float, 18>>(BoundingVolume::kdop18, [](std::span<const Vec3f> p) { return fit_kdop<float, 18>(p); });
}

TEST(SimultaneousTraversal, StopsWhenTheLeafCallbackSaysSo) {
  const TriMesh a = test::random_soup(300, 61);
  const TriangleBvh ba = TriangleBvh::build(a);
  const auto& boxes = std::get<FlatArray<AABB3f>>(ba.volumes());
  int calls = 0;
  const bool finished = traverse_simultaneously(
      ba.topology(), ba.topology(), [&](std::uint32_t i, std::uint32_t j) { return boxes[i].overlaps(boxes[j]); },
      [&](std::uint32_t, std::uint32_t) { return ++calls < 3; });
  EXPECT_FALSE(finished);
  EXPECT_EQ(calls, 3);
  EXPECT_TRUE(traverse_simultaneously(Topology{}, ba.topology(), [](auto, auto) { return true; }, [](auto, auto) {}));
}

}  // namespace
}  // namespace geods::bvh
