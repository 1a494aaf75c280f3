// TriangleBvh::save / load: a loaded hierarchy views the file in place and
// answers every query bit for bit like the one that was saved, for every
// bounding volume and arity, on real meshes and degenerate ones; truncated,
// corrupt, foreign and inconsistent files give geods::Error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "common/archive_files.hpp"
#include "bvh_test_util.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"

namespace geods::bvh {
namespace {

// Every query of the two hierarchies gives identical bits.
void expect_same_answers(const TriangleBvh& a, const TriangleBvh& b, const TriMesh& mesh, std::uint64_t seed) {
  for (const Ray3f& ray : test::test_rays(mesh, 300, seed)) {
    const RayHit ha = a.intersect(ray), hb = b.intersect(ray);
    ASSERT_EQ(std::memcmp(&ha, &hb, sizeof ha), 0) << "t " << ha.t << " vs " << hb.t;
    ASSERT_EQ(a.occluded(ray), b.occluded(ray));
  }
  Rng rng(seed);
  const AABB3f box = mesh.bounds();
  const float size = std::max(box.extent().maxCoeff(), 1e-3f);
  for (int i = 0; i < 100; ++i) {
    const Vec3f p = box.center() + size * test::random_point(rng, -0.8f, 0.8f);
    const ClosestPoint ca = a.closest_point(p), cb = b.closest_point(p);
    ASSERT_EQ(ca.prim, cb.prim);
    ASSERT_EQ(ca.distance, cb.distance);
    ASSERT_TRUE(ca.point == cb.point);
    ASSERT_EQ(a.contains(p), b.contains(p));
    const Vec3f q = box.center() + size * test::random_point(rng, -0.8f, 0.8f);
    const AABB3f cull(p.cwiseMin(q), p.cwiseMax(q));
    ASSERT_EQ(a.cull_box(cull), b.cull_box(cull));
    const std::vector<Plane3f> planes = {Plane3f::from_point_normal(p, test::random_direction(rng)),
                                         Plane3f::from_point_normal(q, test::random_direction(rng))};
    ASSERT_EQ(a.cull_frustum(planes), b.cull_frustum(planes));
  }
}

TriangleBvh round_trip(const TriangleBvh& bvh, const std::string& name) {
  const auto path = geods::test::temp_archive(name);
  bvh.save(path);
  TriangleBvh loaded = TriangleBvh::load(path);
  std::filesystem::remove(path);  // the mapping keeps the pages
  return loaded;
}

TEST(TriangleBvhArchive, EveryVolumeAndArityRoundTripsBitForBitInPlace) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const BoundingVolume volumes[] = {BoundingVolume::aabb,   BoundingVolume::sphere, BoundingVolume::kdop6,
                                    BoundingVolume::kdop14, BoundingVolume::kdop18, BoundingVolume::kdop26,
                                    BoundingVolume::obb,    BoundingVolume::obb_hull,
                                       BoundingVolume::rss};
  for (BoundingVolume bv : volumes)
    for (int arity : {2, 4, 8}) {
      if (bv != BoundingVolume::aabb && arity != 4) continue;  // the wide layouts are the AABB ones
      BuildOptions options;
      options.bv = bv;
      options.arity = arity;
      const TriangleBvh built = TriangleBvh::build(bunny, options);
      const TriangleBvh loaded = round_trip(built, "bvh_roundtrip");
      SCOPED_TRACE(std::string(to_string(bv)) + " arity " + std::to_string(arity));
      EXPECT_TRUE(loaded.triangles().mapped());
      EXPECT_TRUE(loaded.topology().nodes.mapped());
      EXPECT_TRUE(loaded.triangle_ids().mapped());
      EXPECT_TRUE(std::visit([](const auto& v) { return v.mapped(); }, loaded.volumes()));
      EXPECT_FALSE(built.triangles().mapped());
      EXPECT_EQ(loaded.options().bv, bv);
      EXPECT_EQ(loaded.options().arity, arity);
      EXPECT_EQ(loaded.options().builder, options.builder);
      EXPECT_EQ(loaded.triangle_ids(), built.triangle_ids());
      EXPECT_EQ(loaded.topology().depth(), built.topology().depth());
      expect_same_answers(built, loaded, bunny, 7 + arity);
    }
}

TEST(TriangleBvhArchive, TeapotAndDegenerateMeshesRoundTrip) {
  TriMesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  TriMesh flat = test::random_soup(300, 5);
  for (Vec3f& v : flat.vertices) v.z() = 0.25f;
  TriMesh duplicated = test::random_soup(50, 6);
  const std::size_t n = duplicated.num_triangles();
  for (int copy = 0; copy < 4; ++copy)
    for (std::size_t i = 0; i < n; ++i) duplicated.triangles.push_back(duplicated.triangles[i]);
  const std::pair<const char*, TriMesh> meshes[] = {
      {"teapot", test::data_mesh("teapot.obj")}, {"one", one}, {"flat", flat}, {"duplicated", duplicated},
      {"soup", test::random_soup(2000, 9)}};
  for (const auto& [name, mesh] : meshes)
    for (BoundingVolume bv : {BoundingVolume::aabb, BoundingVolume::kdop14}) {
      SCOPED_TRACE(name);
      BuildOptions options;
      options.bv = bv;
      const TriangleBvh built = TriangleBvh::build(mesh, options);
      expect_same_answers(built, round_trip(built, "bvh_degenerate"), mesh, 3);
    }
}

TEST(TriangleBvhArchive, EmptyHierarchyRoundTrips) {
  const TriangleBvh loaded = round_trip(TriangleBvh::build(TriMesh{}), "bvh_empty");
  EXPECT_EQ(loaded.num_triangles(), 0u);
  Ray3f ray;
  ray.direction = {0, 0, 1};
  EXPECT_FALSE(loaded.intersect(ray).hit());
  EXPECT_EQ(loaded.closest_point({0, 0, 0}).prim, RayHit::no_hit);
}

TEST(TriangleBvhArchive, TruncatedCorruptAndOtherVersionFilesAreRefused) {
  const auto path = geods::test::temp_archive("bvh_bad");
  TriangleBvh::build(test::random_soup(400, 11)).save(path);
  geods::test::expect_bad_copies_refused(path, [](const auto& p) { TriangleBvh::load(p); });
  std::filesystem::remove(path);
  EXPECT_THROW(TriangleBvh::load(geods::test::temp_archive("does_not_exist")), Error);
}

TEST(TriangleBvhArchive, AnotherKindIsRefused) {
  const auto path = geods::test::temp_archive("bvh_kind");
  ArchiveWriter other("spatial.KdTree", 1);
  other.add_value("dim", std::uint32_t(3));
  other.write(path);
  geods::test::expect_load_error(path, [](const auto& p) { TriangleBvh::load(p); }, {path.string(), "spatial.KdTree"});
  std::filesystem::remove(path);
}

// Archives written section by section as save() does, with one inconsistency
// each: the checksums are right, so the hierarchy's own checks must refuse them.
TEST(TriangleBvhArchive, FilesWithAnotherVolumeTypeOrBrokenNodesAreRefused) {
  const TriMesh soup = test::random_soup(300, 13);
  BuildOptions options;
  options.bv = BoundingVolume::sphere;
  const TriangleBvh bvh = TriangleBvh::build(soup, options);
  const auto& spheres = std::get<FlatArray<Sphere3f>>(bvh.volumes());
  const auto path = geods::test::temp_archive("bvh_inconsistent");
  auto write = [&](std::uint32_t bv, int arity, const std::vector<TopoNode>& nodes, const std::vector<std::uint32_t>& ids) {
    ArchiveWriter out(TriangleBvh::kArchiveKind, TriangleBvh::kArchiveVersion);
    out.add_value("builder", std::uint32_t(options.builder));
    out.add_value("bv", bv);
    out.add_value("leaf_size", std::int32_t(options.leaf_size));
    out.add_value("arity", std::int32_t(arity));
    out.add_value("sah_bins", std::int32_t(options.sah_bins));
    out.add("nodes", nodes);
    out.add("triangle_ids", ids);
    out.add("volumes", spheres);
    out.add("triangles", bvh.triangles());
    out.add("groups", std::vector<TriangleGroup>{});
    out.write(path);
  };
  const std::vector<TopoNode> nodes = bvh.topology().nodes.to_vector();
  const std::vector<std::uint32_t> ids = bvh.triangle_ids().to_vector();
  auto refused = [&](const std::string& expected_words) {
    geods::test::expect_load_error(path, [](const auto& p) { TriangleBvh::load(p); }, {path.string(), expected_words});
  };
  write(std::uint32_t(BoundingVolume::sphere), 4, nodes, ids);
  EXPECT_NO_THROW(TriangleBvh::load(path));  // the writer is right
  write(std::uint32_t(BoundingVolume::aabb), 4, nodes, ids);  // spheres under an AABB label
  refused("volumes");
  write(std::uint32_t(BoundingVolume::kdop26), 4, nodes, ids);
  refused("volumes");
  write(99, 4, nodes, ids);
  refused("bounding volume");
  write(std::uint32_t(BoundingVolume::sphere), 3, nodes, ids);
  refused("arity");
  std::vector<TopoNode> bad = nodes;
  bad[0].first_child = std::uint32_t(nodes.size());  // children past the end
  write(std::uint32_t(BoundingVolume::sphere), 4, bad, ids);
  refused("child");
  bad = nodes;
  bad[0].first_child = 0;  // the root its own child: a cycle
  write(std::uint32_t(BoundingVolume::sphere), 4, bad, ids);
  refused("node 0");
  std::vector<std::uint32_t> bad_ids = ids;
  bad_ids[0] = std::uint32_t(ids.size());
  write(std::uint32_t(BoundingVolume::sphere), 4, nodes, bad_ids);
  refused("permutation");
  std::filesystem::remove(path);
}

TEST(TriangleBvhArchive, ChangedTriangleGroupsAreRefused) {
  // The groups the wide traversal reads must hold the triangles as built,
  // a zero-area triangle's NaN corners included (lane_holds).
  TriMesh soup = test::random_soup(200, 17);
  soup.vertices[soup.triangles[5][2]] = soup.vertices[soup.triangles[5][1]];  // triangle 5: zero area
  BuildOptions options;
  options.arity = 8;  // the wide layout the ray kernels read
  const TriangleBvh bvh = TriangleBvh::build(soup, options);
  ASSERT_FALSE(bvh.wide8_nodes().empty());
  const auto path = geods::test::temp_archive("bvh_groups");
  auto write = [&](const std::vector<TriangleGroup>& groups) {
    ArchiveWriter out(TriangleBvh::kArchiveKind, TriangleBvh::kArchiveVersion);
    const BuildOptions& o = bvh.options();
    out.add_value("builder", std::uint32_t(o.builder));
    out.add_value("bv", std::uint32_t(o.bv));
    out.add_value("leaf_size", std::int32_t(o.leaf_size));
    out.add_value("arity", std::int32_t(o.arity));
    out.add_value("sah_bins", std::int32_t(o.sah_bins));
    out.add("nodes", bvh.topology().nodes);
    out.add("triangle_ids", bvh.triangle_ids());
    out.add("volumes", std::get<FlatArray<AABB3f>>(bvh.volumes()));
    out.add("triangles", bvh.triangles());
    out.add("wide8", bvh.wide8_nodes());
    out.add("groups", groups);
    out.write(path);
  };
  const std::vector<TriangleGroup> groups = bvh.triangle_groups().to_vector();
  write(groups);
  EXPECT_NO_THROW(TriangleBvh::load(path));  // the writer is right
  // The lane of triangle 5 (NaN corners) and of another one.
  int zero_group = -1, zero_lane = -1;
  for (std::size_t g = 0; g < groups.size() && zero_group < 0; ++g)
    for (int lane = 0; lane < 4; ++lane)
      if (std::isnan(groups[g].corner[0][0][lane])) zero_group = int(g), zero_lane = lane;
  ASSERT_GE(zero_group, 0);
  std::vector<TriangleGroup> changed = groups;
  changed[zero_group].corner[1][2][zero_lane] = 0.5f;  // a NaN corner given a value
  write(changed);
  geods::test::expect_load_error(path, [](const auto& p) { TriangleBvh::load(p); }, {"triangle group"});
  changed = groups;
  const int other_group = zero_group == 0 ? 1 : 0;
  changed[other_group].corner[2][0][0] = std::nextafter(changed[other_group].corner[2][0][0], 1e30f);  // one ulp
  write(changed);
  geods::test::expect_load_error(path, [](const auto& p) { TriangleBvh::load(p); }, {"triangle group"});
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace geods::bvh
