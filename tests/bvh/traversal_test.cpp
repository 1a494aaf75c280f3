// Simultaneous traversal against all pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>

#include "bvh_test_util.hpp"
#include "geods/bvh/traversal.hpp"

namespace geods::bvh {
namespace {

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
