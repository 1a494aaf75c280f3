// Morphing with distance fields (seed §6.2.1): the endpoints of the morph are
// the inputs (fields exactly, surfaces as meshes), the least-squares rigid fit
// recovers a known motion, the RBF warp interpolates the correspondences, and
// the warped morph of two perpendicular sticks does not vanish halfway (the
// seed's example of what plain interpolation does).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/modeling.hpp"
#include "geods/field/morph.hpp"

namespace geods::field {
namespace {

// An axis-aligned box as 12 outward triangles.
TriMesh box_mesh(const Vec3f& lo, const Vec3f& hi) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

Eigen::Matrix3d random_rotation(Rng& rng) {
  const Vec3d axis = Vec3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized();
  return Eigen::AngleAxisd(rng.uniform(0.1, 3.0), axis).toRotationMatrix();
}

TEST(Morph, BoxMeshIsClosedAndOutward) {
  const TriMesh b = box_mesh(Vec3f(0, 0, 0), Vec3f(1, 2, 3));
  EXPECT_TRUE(b.validate().closed_manifold());
  EXPECT_NEAR(b.signed_volume(), 6.0, 1e-9);
}

TEST(Morph, RigidFitRecoversAKnownMotion) {
  Rng rng(2);
  for (int round = 0; round < 20; ++round) {
    const Eigen::Matrix3d r = random_rotation(rng);
    const Vec3d c(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    std::vector<Vec3d> from, to;
    for (int i = 0; i < 3 + round; ++i) {
      from.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      to.push_back(r * from.back() + c);
    }
    const RigidTransform t = fit_rigid(from, to);
    EXPECT_LT((t.rotation - r).norm(), 1e-9);
    EXPECT_NEAR(t.rotation.determinant(), 1.0, 1e-12);
    for (std::size_t i = 0; i < from.size(); ++i) EXPECT_LT((t.apply(from[i]) - to[i]).norm(), 1e-9);
    const Vec3d x(0.3, -2, 7);
    EXPECT_LT((t.apply(x) - (r * x + c)).norm(), 1e-8);
  }
  // A mirror image: the best proper rotation, never a reflection.
  std::vector<Vec3d> from{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, to;
  for (const Vec3d& p : from) to.emplace_back(p.x(), p.y(), -p.z());
  EXPECT_NEAR(fit_rigid(from, to).rotation.determinant(), 1.0, 1e-12);
  // One pair: a translation.
  const std::vector<Vec3d> a{{1, 2, 3}}, b{{2, 2, 5}};
  const RigidTransform one = fit_rigid(a, b);
  EXPECT_LT((one.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_LT((one.apply(a[0]) - b[0]).norm(), 1e-15);
}

TEST(Morph, RbfWarpInterpolatesTheCorrespondences) {
  Rng rng(4);
  for (const RbfKernel kernel : {RbfKernel::thin_plate, RbfKernel::gaussian}) {
    for (const int n : {1, 2, 3, 4, 9, 30}) {
      std::vector<Vec3d> centres, targets;
      for (int i = 0; i < n; ++i) {
        centres.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        targets.push_back(centres.back() + Vec3d(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)));
      }
      const RbfWarp w = RbfWarp::fit(centres, targets, kernel);
      for (int i = 0; i < n; ++i) EXPECT_LT((w(centres[i]) - targets[i]).norm(), 1e-9) << to_string(kernel) << " " << n;
    }
  }
  // Thin plates reproduce an affine map exactly (its affine part takes it all).
  std::vector<Vec3d> centres, targets;
  Eigen::Matrix3d a;
  a << 1.1, 0.1, 0, -0.2, 0.9, 0.05, 0, 0.1, 1.2;
  const Vec3d b(0.3, -0.1, 0.2);
  for (int i = 0; i < 12; ++i) {
    centres.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    targets.push_back(a * centres.back() + b);
  }
  const RbfWarp w = RbfWarp::fit(centres, targets);
  for (int i = 0; i < 20; ++i) {
    const Vec3d p(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
    EXPECT_LT((w(p) - (a * p + b)).norm(), 1e-9);
  }
  // Coplanar centres (no affine part along the normal): still interpolated.
  std::vector<Vec3d> flat{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.3, 0}}, moved;
  for (const Vec3d& p : flat) moved.push_back(p + Vec3d(0, 0, p.x() * p.y()));
  const RbfWarp f = RbfWarp::fit(flat, moved);
  for (std::size_t i = 0; i < flat.size(); ++i) EXPECT_LT((f(flat[i]) - moved[i]).norm(), 1e-9);
}

TEST(Morph, WarpStartsAtTheIdentityAndEndsOnTheTargets) {
  Rng rng(8);
  std::vector<Vec3d> from, to;
  const Eigen::Matrix3d r = random_rotation(rng);
  for (int i = 0; i < 6; ++i) {
    from.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    to.push_back(r * from.back() + Vec3d(1, 2, 3) + 0.05 * Vec3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
  }
  const MorphWarp w = MorphWarp::fit(from, to);
  for (int i = 0; i < 20; ++i) {
    const Vec3d x(rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-3, 3));
    EXPECT_EQ(w.apply(0, x), x);
  }
  for (std::size_t i = 0; i < from.size(); ++i) EXPECT_LT((w.apply(1, from[i]) - to[i]).norm(), 1e-9);
  // A purely rigid correspondence: every in-between is rigid (distances kept) and turns by t theta.
  std::vector<Vec3d> rigid;
  for (const Vec3d& p : from) rigid.push_back(r * p + Vec3d(1, 2, 3));
  const MorphWarp rw = MorphWarp::fit(from, rigid);
  for (const double t : {0.25, 0.5, 0.75})
    for (std::size_t i = 1; i < from.size(); ++i)
      EXPECT_NEAR((rw.apply(t, from[i]) - rw.apply(t, from[0])).norm(), (from[i] - from[0]).norm(), 1e-9);
}

TEST(Morph, EndpointsAreTheInputs) {
  const TriMesh a = box_mesh(Vec3f(-1, -0.25f, -0.25f), Vec3f(1, 0.25f, 0.25f));  // a stick along x
  const TriMesh b = box_mesh(Vec3f(-0.3f, -1.2f, -0.3f), Vec3f(0.3f, 1.2f, 0.3f));  // a fatter one along y
  MorphOptions options;
  options.res = 24;
  for (const bool warp : {false, true}) {
    if (warp) {
      options.from = {{1, 0, 0}, {-1, 0, 0}, {0, 0.25, 0}, {0, 0, 0.25}};
      options.to = {{0, 1.2, 0}, {0, -1.2, 0}, {-0.3, 0, 0}, {0, 0, 0.3}};
    }
    const Morph m = Morph::build(a, b, options);
    EXPECT_EQ(m.warped(), warp);
    const Grid3<float> da = sdf_grid(a, m.grid()).distance, db = sdf_grid(b, m.grid()).distance;
    EXPECT_EQ(m.field(0).data, da.data);
    EXPECT_EQ(m.field(1).data, db.data);
    for (const auto& [t, mesh, field] : {std::tuple{0.0, &a, &da}, std::tuple{1.0, &b, &db}}) {
      const TriMesh s = m.surface(t), expected = field_surface(*field);
      EXPECT_EQ(s.vertices, expected.vertices);
      EXPECT_EQ(s.triangles, expected.triangles);
      EXPECT_TRUE(s.validate().closed_manifold());
      // And it is the input's surface, to within the grid's resolution.
      const std::vector<MeshPointDistance> d = signed_distance(*mesh, s.vertices);
      for (const MeshPointDistance& q : d) EXPECT_LT(std::abs(q.distance), 0.75f * m.grid().spacing.x());
      EXPECT_NEAR(s.signed_volume(), mesh->signed_volume(), 0.15 * mesh->signed_volume());
    }
    if (warp) {
      EXPECT_EQ(m.warped_source(0).vertices, a.vertices);
      EXPECT_NEAR(m.stats().rotation_angle, M_PI / 2, 1e-9);
    }
  }
}

TEST(Morph, WarpedMorphOfPerpendicularSticksDoesNotVanish) {
  // The seed's example: plain interpolation between two perpendicular sticks nearly
  // vanishes halfway; with the tips as correspondences the in-between is a turned stick.
  const TriMesh a = box_mesh(Vec3f(-1, -0.2f, -0.2f), Vec3f(1, 0.2f, 0.2f));
  const TriMesh b = box_mesh(Vec3f(-0.2f, -1, -0.2f), Vec3f(0.2f, 1, 0.2f));
  MorphOptions options;
  options.res = 28;
  const double stick = a.signed_volume();
  const double plain = Morph::build(a, b, options).surface(0.5).signed_volume();
  options.from = {{1, 0, 0}, {-1, 0, 0}, {0, 0, 0.2}};
  options.to = {{0, 1, 0}, {0, -1, 0}, {0, 0, 0.2}};
  const Morph warped = Morph::build(a, b, options);
  const TriMesh mid = warped.surface(0.5);
  EXPECT_LT(plain, 0.35 * stick);
  EXPECT_GT(mid.signed_volume(), 0.75 * stick);
  // Halfway, the stick lies along the diagonal of x and y.
  const AABB3f box = mid.bounds();
  EXPECT_NEAR(box.hi.x(), box.hi.y(), 0.1);
  EXPECT_GT(box.hi.x(), 0.75f);
}

TEST(Morph, BadInput) {
  const TriMesh a = box_mesh(Vec3f(0, 0, 0), Vec3f(1, 1, 1));
  MorphOptions options;
  options.res = 12;
  EXPECT_THROW(Morph::build(TriMesh{}, a, options), Error);
  TriMesh nan = a;
  nan.vertices[0].x() = NAN;
  EXPECT_THROW(Morph::build(a, nan, options), Error);
  options.from = {{0, 0, 0}};
  EXPECT_THROW(Morph::build(a, a, options), Error);  // unequal lists
  options.to = {{NAN, 0, 0}};
  EXPECT_THROW(Morph::build(a, a, options), Error);
  options.from = {{0, 0, 0}, {0, 0, 0}};
  options.to = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(Morph::build(a, a, options), Error);  // two starts at one point
  options.from.clear(), options.to.clear();
  options.res = 0;
  EXPECT_THROW(Morph::build(a, a, options), Error);
  options.res = 12;
  const Morph m = Morph::build(a, a, options);
  EXPECT_THROW(m.field(1.5), Error);
  EXPECT_THROW(m.field(NAN), Error);
  EXPECT_THROW(parse_rbf_kernel("cubic"), Error);
  EXPECT_THROW(fit_rigid(std::vector<Vec3d>{}, std::vector<Vec3d>{}), Error);
}

}  // namespace
}  // namespace geods::field
