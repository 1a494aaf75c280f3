// Incremental collision detection equals queries from scratch on every frame
// of smooth motions, and the broad phase equals the narrow phase on all pairs.
#include <gtest/gtest.h>

#include "common/data_files.hpp"
#include "geods/collide/incremental.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"

namespace geods::collide {
namespace {

Posed motion(double s, const Vec3d& center, double size, double speed) {
  Posed p;
  p.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(speed * 3.0 * s, Vec3d(0.3, 1, 0.2).normalized()));
  p.translation = center - p.rotation * center + Vec3d((2.4 * s - 1.2) * size, 0.1 * size, 0.05 * size);
  return p;
}

// The bunny and the teapot scaled to 0.8 of its size, centred on it.
struct Scene {
  TriMesh bunny, pot;
  AABB3f bb;
  double size;
  Scene()
      : bunny(test::data_mesh("bunny.ply")),
        pot(test::data_mesh("teapot.obj")) {
    bb = bunny.bounds();
    const AABB3f tb = pot.bounds();
    const float scale = 0.8f * (bb.hi - bb.lo).maxCoeff() / (tb.hi - tb.lo).maxCoeff();
    for (auto& v : pot.vertices) v = (v - tb.center()) * scale + bb.center();
    size = (bb.hi - bb.lo).maxCoeff();
  }
};

TEST(Incremental, EqualsFromScratchOnEveryFrame) {
  const Scene scene;
  const TriMesh& bunny = scene.bunny;
  const TriMesh& pot = scene.pot;
  const AABB3f bb = scene.bb;
  const double size = scene.size;
  for (const auto& [bv, rule] : {std::pair{CollisionVolume::obb, DescendRule::larger},
                                std::pair{CollisionVolume::boxtree, DescendRule::count},
                                std::pair{CollisionVolume::kdop18, DescendRule::b_first}}) {
    CollisionMeshOptions o;
    o.bv = bv;
    const CollisionMesh a(bunny, o), b(pot, o);
    {
      IncrementalCollide inc(a, b, rule);
      int frames_in_contact = 0;
      std::size_t largest_slice = 0;
      const int frames = 40;
      for (int k = 0; k < frames; ++k) {
        const Posed pose = motion(double(k) / (frames - 1), bb.center().cast<double>(), size, 1.0);
        const CollideResult scratch = collide(a, Posed{}, b, pose, {CollideMode::all, rule});
        const CollideResult r = inc.update(Posed{}, pose);
        ASSERT_EQ(r.pairs, scratch.pairs) << to_string(bv) << " frame " << k;
        ASSERT_EQ(r.colliding, scratch.colliding);
        frames_in_contact += r.colliding;
        largest_slice = std::max(largest_slice, inc.slice_size());
      }
      EXPECT_GT(frames_in_contact, 5);
      EXPECT_LT(frames_in_contact, frames);
      // Going up keeps the slice from only growing: once apart again it shrinks.
      EXPECT_LT(inc.slice_size(), largest_slice);
      // A jump (not smooth) still gives the right answer.
      const Posed jump = motion(0.5, bb.center().cast<double>(), size, 7.0);
      EXPECT_EQ(inc.update(Posed{}, jump).pairs, collide(a, Posed{}, b, jump, {CollideMode::all}).pairs);
    }
  }
}

// Not timed: the work counted. On a slow smooth motion (200 frames over the
// path) the pairs whose motion stays below their gap are skipped, so the
// incremental queries test fewer volume pairs in all than queries from
// scratch, with the same contacts.
TEST(Incremental, SkipsPairsThatCannotHaveMovedIntoContact) {
  const Scene scene;
  const AABB3f bb = scene.bb;
  const double size = scene.size;
  const CollisionMesh a(scene.bunny), b(scene.pot);
  IncrementalCollide inc(a, b);
  std::size_t scratch_tests = 0, inc_tests = 0, skipped = 0;
  const int frames = 200;
  for (int k = 0; k < frames; ++k) {
    const Posed pose = motion(double(k) / (frames - 1), bb.center().cast<double>(), size, 1.0);
    const CollideResult scratch = collide(a, Posed{}, b, pose, {CollideMode::all});
    const CollideResult r = inc.update(Posed{}, pose);
    ASSERT_EQ(r.pairs, scratch.pairs) << "frame " << k;
    scratch_tests += scratch.stats.volume_tests;
    inc_tests += r.stats.volume_tests;
    skipped += inc.skipped();
  }
  EXPECT_GT(skipped, 0u);
  EXPECT_LT(inc_tests, scratch_tests);
}

TEST(BroadPhase, EqualsAllPairs) {
  Rng rng(17);
  // Small soups (clusters of triangles) moving around in a box.
  std::vector<TriMesh> meshes;
  for (int m = 0; m < 12; ++m) {
    TriMesh t;
    for (int i = 0; i < 20; ++i) {
      const Vec3f c(float(rng.uniform(-0.3, 0.3)), float(rng.uniform(-0.3, 0.3)), float(rng.uniform(-0.3, 0.3)));
      const auto base = std::uint32_t(t.vertices.size());
      for (int k = 0; k < 3; ++k)
        t.vertices.push_back(c + Vec3f(float(rng.uniform(-0.2, 0.2)), float(rng.uniform(-0.2, 0.2)),
                                       float(rng.uniform(-0.2, 0.2))));
      t.triangles.push_back({base, base + 1, base + 2});
    }
    meshes.push_back(t);
  }
  std::vector<CollisionMesh> cm;
  for (const auto& m : meshes) cm.emplace_back(m);
  std::vector<const CollisionMesh*> ptrs;
  for (const auto& c : cm) ptrs.push_back(&c);
  BroadPhase broad(ptrs);
  std::vector<Vec3d> start, velocity;
  for (std::size_t i = 0; i < cm.size(); ++i) {
    start.emplace_back(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
    velocity.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  }
  std::size_t total = 0;
  for (int frame = 0; frame < 30; ++frame) {
    std::vector<Posed> poses(cm.size());
    for (std::size_t i = 0; i < cm.size(); ++i) {
      poses[i].rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * frame + double(i), Vec3d::UnitZ()));
      poses[i].translation = start[i] + 0.12 * frame * velocity[i];
    }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> expect;
    for (std::uint32_t i = 0; i < cm.size(); ++i)
      for (std::uint32_t j = i + 1; j < cm.size(); ++j)
        if (collide(cm[i], poses[i], cm[j], poses[j]).colliding) expect.push_back({i, j});
    ASSERT_EQ(broad.update(poses), expect) << "frame " << frame;
    EXPECT_LE(broad.candidates(), cm.size() * (cm.size() - 1) / 2);
    total += expect.size();
  }
  EXPECT_GT(total, 3u);
  EXPECT_THROW(broad.update({}), Error);
}

}  // namespace
}  // namespace geods::collide
