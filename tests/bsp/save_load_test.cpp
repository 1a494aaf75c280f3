#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include "bsp/meshes.hpp"
#include "geods/bsp/bsp_tree.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"

using namespace geods;
using namespace geods::bsp;
using namespace bsp_test;

// Round trip: the loaded tree has the same grid, planes, nodes, fragments and stats, and
// answers classify, visibility_order and first_hit the same. Wrong kind or version,
// truncated and missing files raise geods::Error.
TEST(BspSaveLoad, RoundTripAndBadFiles) {
  const Triangles m = torus(1.0, 0.4, 16, 10);
  const BspTree a(m.vertices, m.triangles);
  const auto dir = std::filesystem::temp_directory_path() / ("geods_bsp_save_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "t.geods";
  a.save(path);
  const BspTree b = BspTree::load(path);
  b.validate();
  EXPECT_TRUE(b.nodes().mapped());
  EXPECT_EQ(b.grid().shift, a.grid().shift);
  EXPECT_EQ(b.grid().center, a.grid().center);
  ASSERT_EQ(b.planes().size(), a.planes().size());
  for (std::uint32_t i = 0; i < a.planes().size(); ++i) {
    EXPECT_EQ(b.planes()[i].a, a.planes()[i].a);
    EXPECT_EQ(b.planes()[i].d, a.planes()[i].d);
  }
  ASSERT_EQ(b.nodes().size(), a.nodes().size());
  for (std::size_t i = 0; i < a.nodes().size(); ++i) {
    const Node &x = a.nodes()[i], &y = b.nodes()[i];
    EXPECT_TRUE(x.plane == y.plane && x.neg == y.neg && x.pos == y.pos && x.first == y.first && x.count == y.count &&
                x.label == y.label);
  }
  ASSERT_EQ(b.fragments().size(), a.fragments().size());
  for (std::size_t i = 0; i < a.fragments().size(); ++i) {
    EXPECT_EQ(b.fragments()[i].support, a.fragments()[i].support);
    EXPECT_EQ(b.fragments()[i].edges, a.fragments()[i].edges);
    EXPECT_EQ(b.fragments()[i].points, a.fragments()[i].points);
    EXPECT_EQ(b.fragments()[i].source, a.fragments()[i].source);
  }
  EXPECT_EQ(b.stats().nodes, a.stats().nodes);
  EXPECT_EQ(b.stats().depth, a.stats().depth);
  EXPECT_EQ(b.stats().polygons, a.stats().polygons);
  EXPECT_EQ(b.stats().expected_cost, a.stats().expected_cost);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int i = 0; i < 300; ++i) {
    const Vec3d p(u(rng), u(rng), u(rng)), d(u(rng), u(rng), u(rng));
    EXPECT_EQ(b.classify(p), a.classify(p));
    EXPECT_EQ(b.first_hit(p, d).t, a.first_hit(p, d).t);
    EXPECT_EQ(b.first_hit(p, d).triangle, a.first_hit(p, d).triangle);
  }
  EXPECT_EQ(b.visibility_order({3, 2, 1}), a.visibility_order({3, 2, 1}));

  // Wrong version, wrong kind, truncated, missing.
  {
    ArchiveWriter w(BspTree::kArchiveKind, BspTree::kArchiveVersion + 1);
    w.add_value("root", std::uint32_t(0));
    w.write(dir / "v2.geods");
    EXPECT_THROW(BspTree::load(dir / "v2.geods"), Error);
    ArchiveWriter k("spatial.KdTree", 1);
    k.add_value("root", std::uint32_t(0));
    k.write(dir / "kind.geods");
    EXPECT_THROW(BspTree::load(dir / "kind.geods"), Error);
  }
  {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (std::size_t keep : {bytes.size() / 2, bytes.size() - 1, std::size_t(40)}) {
      std::ofstream(dir / "cut.geods", std::ios::binary).write(bytes.data(), std::streamsize(keep));
      EXPECT_THROW(BspTree::load(dir / "cut.geods"), Error) << keep;
    }
  }
  EXPECT_THROW(BspTree::load(dir / "missing.geods"), Error);
  std::filesystem::remove_all(dir);
}
