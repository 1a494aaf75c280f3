// Collision and distance queries against brute force over all triangle
// pairs (the exact triangle test and the double triangle distance on the
// world coordinates), for every bounding volume, the boxtree and every
// descend rule, on random soups, degenerate soups, touching configurations
// and the meshes of data/ under random poses.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/data_files.hpp"
#include "geods/collide/collide.hpp"
#include "geods/collide/triangle_pair.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"

namespace geods::collide {
namespace {

constexpr CollisionVolume kAllVolumes[] = {CollisionVolume::aabb,   CollisionVolume::sphere, CollisionVolume::kdop6,
                                           CollisionVolume::kdop14, CollisionVolume::kdop18, CollisionVolume::kdop26,
                                           CollisionVolume::obb,    CollisionVolume::obb_hull,
                                           CollisionVolume::boxtree, CollisionVolume::rss};

TriMesh soup(std::size_t n, double size, std::uint64_t seed, bool degenerate = false) {
  Rng rng(seed);
  TriMesh m;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3f c(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)));
    const auto base = std::uint32_t(m.vertices.size());
    for (int k = 0; k < 3; ++k)
      m.vertices.push_back(c + Vec3f(float(rng.uniform(-size, size)), float(rng.uniform(-size, size)),
                                     float(rng.uniform(-size, size))));
    m.triangles.push_back({base, base + 1, base + 2});
    if (degenerate) {
      switch (i % 4) {
        case 0: m.triangles.push_back({base, base, base + 1}); break;        // repeated corner
        case 1: m.triangles.push_back({base + 2, base + 1, base}); break;    // duplicate, flipped
        case 2: m.vertices[base + 2] = m.vertices[base]; break;              // a segment
        default: break;
      }
    }
  }
  return m;
}

Posed random_pose(Rng& rng, double shift) {
  Posed p;
  p.rotation = Eigen::Quaterniond(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  p.translation = Vec3d(rng.uniform(-shift, shift), rng.uniform(-shift, shift), rng.uniform(-shift, shift));
  return p;
}

TriangleD world(const TriMesh& m, std::size_t t, const Posed& pose) {
  const Eigen::Matrix3d r = pose.rotation.normalized().toRotationMatrix();
  TriangleD w;
  for (int k = 0; k < 3; ++k) w[k] = r * m.vertices[m.triangles[t][k]].cast<double>() + pose.translation;
  return w;
}

std::vector<TriangleD> world_all(const TriMesh& m, const Posed& pose) {
  std::vector<TriangleD> w;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) w.push_back(world(m, t, pose));
  return w;
}

// Every pair; the exact test decides, after a box test on the same doubles
// (exact too: triangles whose boxes are apart cannot meet).
std::vector<Contact> brute_contacts(const TriMesh& a, const Posed& pa, const TriMesh& b, const Posed& pb) {
  const auto wa = world_all(a, pa), wb = world_all(b, pb);
  auto box = [](const TriangleD& t) { return AABB3d(t[0].cwiseMin(t[1]).cwiseMin(t[2]), t[0].cwiseMax(t[1]).cwiseMax(t[2])); };
  std::vector<AABB3d> bb;
  for (const auto& t : wb) bb.push_back(box(t));
  std::vector<Contact> out;
  for (std::size_t i = 0; i < wa.size(); ++i) {
    const AABB3d ba = box(wa[i]);
    for (std::size_t j = 0; j < wb.size(); ++j)
      if (ba.overlaps(bb[j]) && triangles_intersect(wa[i], wb[j])) out.push_back({std::uint32_t(i), std::uint32_t(j)});
  }
  return out;
}

double brute_distance(const TriMesh& a, const Posed& pa, const TriMesh& b, const Posed& pb) {
  double best = std::numeric_limits<double>::infinity();
  const auto wa = world_all(a, pa), wb = world_all(b, pb);
  // Pairs whose boxes are at least `best` apart are skipped (a lower bound).
  for (const auto& s : wa) {
    const AABB3d bs(s[0].cwiseMin(s[1]).cwiseMin(s[2]), s[0].cwiseMax(s[1]).cwiseMax(s[2]));
    for (const auto& t : wb) {
      const AABB3d bt(t[0].cwiseMin(t[1]).cwiseMin(t[2]), t[0].cwiseMax(t[1]).cwiseMax(t[2]));
      if ((bs.lo - bt.hi).cwiseMax(bt.lo - bs.hi).cwiseMax(0.0).norm() >= best) continue;
      best = std::min(best, triangle_distance(s, t).distance);
    }
  }
  return best;
}

std::vector<Contact> swapped(std::vector<Contact> v) {
  for (auto& c : v) std::swap(c.a, c.b);
  std::sort(v.begin(), v.end());
  return v;
}

TEST(Collide, EveryVolumeEqualsBruteForceOnSoups) {
  Rng rng(3);
  const TriMesh ma = soup(120, 0.12, 1), mb = soup(90, 0.15, 2, true);
  std::size_t colliding = 0, poses = 0;
  for (const CollisionVolume bv : kAllVolumes) {
    CollisionMeshOptions o;
    o.bv = bv;
    o.leaf_size = bv == CollisionVolume::aabb ? 1 : 3;
    o.arity = bv == CollisionVolume::sphere ? 4 : 2;
    const CollisionMesh a(ma, o), b(mb, o);
    for (int k = 0; k < 4; ++k) {
      const Posed pa = random_pose(rng, 0.5), pb = random_pose(rng, k < 2 ? 1.0 : 2.5);
      const auto expect = brute_contacts(ma, pa, mb, pb);
      for (const DescendRule rule : {DescendRule::larger, DescendRule::count, DescendRule::a_first, DescendRule::b_first}) {
        CollideRequest all{CollideMode::all, rule};
        const CollideResult r = collide(a, pa, b, pb, all);
        ASSERT_EQ(r.pairs, expect) << to_string(bv) << " " << to_string(rule);
        ASSERT_EQ(r.colliding, !expect.empty());
        const CollideResult first = collide(a, pa, b, pb, {CollideMode::first, rule});
        ASSERT_EQ(first.colliding, !expect.empty());
        if (first.colliding) {
          ASSERT_EQ(first.pairs.size(), 1u);
          ASSERT_TRUE(std::binary_search(expect.begin(), expect.end(), first.pairs[0]));
        }
        // Swapped arguments: the same pairs, swapped.
        ASSERT_EQ(swapped(collide(b, pb, a, pa, all).pairs), expect);
      }
      colliding += !expect.empty();
      ++poses;
    }
  }
  EXPECT_GT(colliding, 0u);
  EXPECT_LT(colliding, poses);  // both outcomes occur
}

TEST(Collide, MixedVolumesAndFloatPoses) {
  const TriMesh ma = soup(80, 0.3, 5), mb = soup(80, 0.3, 6);
  CollisionMeshOptions oa, ob;
  oa.bv = CollisionVolume::obb;
  ob.bv = CollisionVolume::kdop18;
  const CollisionMesh a(ma, oa), b(mb, ob);
  Rng rng(9);
  for (int k = 0; k < 5; ++k) {
    const Posed pd = random_pose(rng, 0.8);
    Posef pf;
    pf.rotation = pd.rotation.cast<float>();
    pf.translation = pd.translation.cast<float>();
    Posed back;  // what the float pose is, in double
    back.rotation = pf.rotation.cast<double>();
    back.translation = pf.translation.cast<double>();
    EXPECT_EQ(collide(a, Posef{}, b, pf, {CollideMode::all}).pairs, brute_contacts(ma, Posed{}, mb, back));
  }
}

TEST(Collide, TouchingAndCoplanarMeshes) {
  // Two unit squares (two triangles each): stacked on the same plane sharing
  // an edge, and one on top of the other touching along a face.
  TriMesh sq;
  sq.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  sq.triangles = {{0, 1, 2}, {0, 2, 3}};
  for (const CollisionVolume bv : kAllVolumes) {
    CollisionMeshOptions o;
    o.bv = bv;
    o.leaf_size = 1;
    const CollisionMesh m(sq, o);
    Posed next;
    next.translation = Vec3d(1, 0, 0);  // shares the edge x = 1
    EXPECT_EQ(collide(m, Posed{}, m, next, {CollideMode::all}).pairs, brute_contacts(sq, Posed{}, sq, next));
    EXPECT_TRUE(collide(m, Posed{}, m, next).colliding) << to_string(bv);
    next.translation = Vec3d(std::nextafter(1.0, 2.0), 0, 0);
    EXPECT_FALSE(collide(m, Posed{}, m, next).colliding) << to_string(bv);
    // Rotated a quarter turn about z around (0.5, 0.5): the same square, coplanar overlap.
    Posed turn;
    turn.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3d::UnitZ()));
    EXPECT_EQ(collide(m, Posed{}, m, turn, {CollideMode::all}).pairs, brute_contacts(sq, Posed{}, sq, turn));
    EXPECT_EQ(distance(m, Posed{}, m, turn).distance, 0.0);
  }
}

TEST(Collide, DataMeshesUnderRandomPoses) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const TriMesh teapot = test::data_mesh("teapot.obj");
  // Scale the teapot to the bunny's size.
  TriMesh pot = teapot;
  const AABB3f bb = bunny.bounds(), tb = teapot.bounds();
  const float s = (bb.hi - bb.lo).norm() / (tb.hi - tb.lo).norm();
  for (auto& v : pot.vertices) v = (v - tb.center()) * s + bb.center();
  CollisionMeshOptions o;
  const CollisionMesh a(bunny, o), b(pot, o);
  o.bv = CollisionVolume::boxtree;
  const CollisionMesh a2(bunny, o), b2(pot, o);
  Rng rng(21);
  const double d = (bb.hi - bb.lo).norm();
  int hit = 0;
  for (int k = 0; k < 3; ++k) {
    Posed pb = random_pose(rng, 0.4 * d);
    pb.translation += bb.center().cast<double>() - pb.rotation.normalized() * bb.center().cast<double>();
    const auto expect = brute_contacts(bunny, Posed{}, pot, pb);
    EXPECT_EQ(collide(a, Posed{}, b, pb, {CollideMode::all}).pairs, expect);
    EXPECT_EQ(collide(a2, Posed{}, b2, pb, {CollideMode::all}).pairs, expect);
    hit += !expect.empty();
    if (k == 0) {
      Posed far = pb;
      far.translation += Vec3d(0.7 * d, 0, 0);
      EXPECT_NEAR(distance(a, Posed{}, b, far).distance, brute_distance(bunny, Posed{}, pot, far), 1e-9 * d);
    }
  }
  EXPECT_GT(hit, 0);
}

TEST(Distance, EqualsBruteForceForEveryVolume) {
  Rng rng(4);
  const TriMesh ma = soup(60, 0.2, 11), mb = soup(50, 0.2, 12, true);
  for (const CollisionVolume bv : kAllVolumes) {
    CollisionMeshOptions o;
    o.bv = bv;
    const CollisionMesh a(ma, o), b(mb, o);
    for (int k = 0; k < 4; ++k) {
      const Posed pa = random_pose(rng, 0.2);
      Posed pb = random_pose(rng, 0.5);
      pb.translation += Vec3d(k * 0.8, 0, 0);  // from overlapping to apart
      const double expect = brute_distance(ma, pa, mb, pb);
      for (const DescendRule rule : {DescendRule::larger, DescendRule::count, DescendRule::b_first}) {
        const DistanceResult r = distance(a, pa, b, pb, {rule});
        ASSERT_NEAR(r.distance, expect, 1e-12) << to_string(bv);
        ASSERT_NEAR((r.point_a - r.point_b).norm(), r.distance, 1e-9);
        // The reported triangles hold the points at that distance.
        const auto d = triangle_distance(world(ma, r.triangle_a, pa), world(mb, r.triangle_b, pb));
        ASSERT_NEAR(d.distance, r.distance, 1e-12);
        ASSERT_EQ(r.distance == 0, collide(a, pa, b, pb).colliding);
      }
      // Tolerance queries: within d iff the distance is at most d.
      for (const double tol : {expect * 0.9, expect * 1.1 + 1e-9}) {
        const DistanceResult w = distance(a, pa, b, pb, {DescendRule::larger, tol});
        ASSERT_EQ(w.within, expect <= tol);
        ASSERT_GE(w.distance, expect - 1e-12);
      }
    }
  }
}

TEST(Collide, BadInputAndEmptyMeshes) {
  const TriMesh m = soup(10, 0.2, 1);
  const CollisionMesh a(m);
  Posed nan_pose;
  nan_pose.translation[1] = std::nan("");
  EXPECT_THROW(collide(a, Posed{}, a, nan_pose), Error);
  EXPECT_THROW(distance(a, nan_pose, a, Posed{}), Error);
  Posed zero;
  zero.rotation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_THROW(collide(a, zero, a, Posed{}), Error);
  TriMesh bad = m;
  bad.vertices[3][0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(CollisionMesh{bad}, Error);
  EXPECT_THROW(parse_collision_volume("cube"), Error);
  EXPECT_EQ(parse_collision_volume("boxtree"), CollisionVolume::boxtree);
  const CollisionMesh empty(TriMesh{});
  EXPECT_FALSE(collide(a, Posed{}, empty, Posed{}).colliding);
  EXPECT_EQ(distance(empty, Posed{}, a, Posed{}).distance, std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace geods::collide
