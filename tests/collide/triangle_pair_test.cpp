// The exact triangle-triangle test against an independent oracle: the
// separating axis theorem in exact integer arithmetic on small integer
// coordinates (which makes touching, coplanar, collinear and point triangles
// common), and the double distance against the same oracle's verdict.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "geods/collide/triangle_pair.hpp"
#include "geods/core/rng.hpp"

namespace geods::collide {
namespace {

using I3 = std::array<std::int64_t, 3>;
using ITri = std::array<I3, 3>;

I3 sub(const I3& a, const I3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
I3 cross(const I3& a, const I3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
std::int64_t dot(const I3& a, const I3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
bool zero(const I3& a) { return a[0] == 0 && a[1] == 0 && a[2] == 0; }

// Two compact convex sets are disjoint iff the direction between their
// closest points separates them; that direction is a face normal, an edge
// cross product, a vertex difference, or (e x w) x e for an edge e and a vertex
// difference w (vertex-edge and parallel edge-edge closest pairs). Testing a
// superset of candidates is still exact: a separating candidate separates.
bool sat_disjoint(const ITri& s, const ITri& t) {
  std::vector<I3> axes;
  const I3 es[3] = {sub(s[1], s[0]), sub(s[2], s[1]), sub(s[0], s[2])};
  const I3 et[3] = {sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])};
  axes.push_back(cross(es[0], es[1]));
  axes.push_back(cross(et[0], et[1]));
  for (const I3& e : es)
    for (const I3& f : et) axes.push_back(cross(e, f));
  for (const I3& p : s)
    for (const I3& q : t) {
      const I3 w = sub(p, q);
      axes.push_back(w);
      for (const I3& e : es) axes.push_back(cross(cross(e, w), e));
      for (const I3& e : et) axes.push_back(cross(cross(e, w), e));
    }
  for (const I3& ax : axes) {
    if (zero(ax)) continue;
    std::int64_t smin = INT64_MAX, smax = INT64_MIN, tmin = INT64_MAX, tmax = INT64_MIN;
    for (const I3& p : s) smin = std::min(smin, dot(p, ax)), smax = std::max(smax, dot(p, ax));
    for (const I3& p : t) tmin = std::min(tmin, dot(p, ax)), tmax = std::max(tmax, dot(p, ax));
    if (smax < tmin || tmax < smin) return true;
  }
  return false;
}

TriangleD to_double(const ITri& t, double scale = 1, Vec3d shift = Vec3d::Zero()) {
  TriangleD d;
  for (int i = 0; i < 3; ++i) d[i] = Vec3d(double(t[i][0]), double(t[i][1]), double(t[i][2])) * scale + shift;
  return d;
}

ITri random_itri(Rng& rng, int range) {
  ITri t;
  for (auto& p : t)
    for (auto& c : p) c = std::int64_t(rng.below(2 * range + 1)) - range;
  // Often make it flat on an axis plane (coplanar pairs) or collinear.
  switch (rng.below(8)) {
    case 0:
      t[1][2] = t[0][2], t[2][2] = t[0][2];
      break;
    case 1:  // a segment
      for (int k = 0; k < 3; ++k) t[2][k] = 2 * t[1][k] - t[0][k];
      break;
    case 2:  // a point
      t[1] = t[0], t[2] = t[0];
      break;
    default: break;
  }
  return t;
}

TEST(TrianglePair, EqualsSeparatingAxisOracleOnIntegerGrids) {
  Rng rng(7);
  std::size_t hits = 0, checked = 0;
  for (int iter = 0; iter < 40000; ++iter) {
    const int range = iter % 3 == 0 ? 1 : 3;
    ITri s = random_itri(rng, range), t = random_itri(rng, range);
    if (iter % 5 == 0) t[0][2] = 0, t[1][2] = 0, t[2][2] = 0, s[0][2] = 0, s[1][2] = 0, s[2][2] = 0;  // coplanar
    const bool expect = !sat_disjoint(s, t);
    const TriangleD ds = to_double(s), dt = to_double(t);
    ASSERT_EQ(triangles_intersect(ds, dt), expect) << "iteration " << iter;
    ASSERT_EQ(triangles_intersect(dt, ds), expect) << "swapped, iteration " << iter;
    // Any corner order, and an exact change of scale and origin.
    const TriangleD ps = {ds[2], ds[0], ds[1]}, pt = {dt[1], dt[0], dt[2]};
    ASSERT_EQ(triangles_intersect(ps, pt), expect) << "permuted, iteration " << iter;
    const Vec3d shift(0.375, -1024, 3.5);
    ASSERT_EQ(triangles_intersect(to_double(s, 0.125, shift), to_double(t, 0.125, shift)), expect);
    hits += expect;
    ++checked;
  }
  // Both answers are common (the test would be weak otherwise).
  EXPECT_GT(hits, checked / 10);
  EXPECT_LT(hits, checked * 9 / 10);
}

TEST(TrianglePair, TouchingConfigurations) {
  const TriangleD base = {Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0)};
  // Vertex on the face, edge on edge, shared vertex, shared edge (coplanar and not).
  EXPECT_TRUE(triangles_intersect(base, {Vec3d(0.25, 0.25, 0), Vec3d(0, 0, 1), Vec3d(1, 1, 1)}));
  EXPECT_TRUE(triangles_intersect(base, {Vec3d(1, 0, 0), Vec3d(2, 0, 1), Vec3d(2, 1, 1)}));
  EXPECT_TRUE(triangles_intersect(base, {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(1, 1, 0)}));
  EXPECT_TRUE(triangles_intersect(base, {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(1, 1, 1)}));
  EXPECT_TRUE(triangles_intersect(base, {Vec3d(0.5, -1, 0), Vec3d(0.5, 1, 0), Vec3d(0.5, 0, 1)}));
  // Just apart: the smallest double gap.
  const double up = std::nextafter(0.0, 1.0);
  EXPECT_FALSE(triangles_intersect(base, {Vec3d(0.25, 0.25, up), Vec3d(0, 0, 1), Vec3d(1, 1, 1)}));
  EXPECT_FALSE(triangles_intersect(base, {Vec3d(std::nextafter(1.0, 2.0), 0, 0), Vec3d(2, 0, 0), Vec3d(2, 1, 0)}));
  // Coplanar, one inside the other without touching edges.
  EXPECT_TRUE(triangles_intersect(base, {Vec3d(0.1, 0.1, 0), Vec3d(0.2, 0.1, 0), Vec3d(0.1, 0.2, 0)}));
  // Identical triangles.
  EXPECT_TRUE(triangles_intersect(base, base));
}

TEST(TrianglePair, DistanceAgreesWithTheExactTest) {
  Rng rng(11);
  for (int iter = 0; iter < 5000; ++iter) {
    const ITri s = random_itri(rng, 3), t = random_itri(rng, 3);
    const TriangleD ds = to_double(s), dt = to_double(t);
    const bool meet = !sat_disjoint(s, t);
    const TrianglePairDistance d = triangle_distance(ds, dt);
    const TrianglePairDistance e = triangle_distance(dt, ds);
    ASSERT_EQ(d.distance == 0, meet) << iter;
    ASSERT_NEAR(d.distance, e.distance, 1e-12);
    ASSERT_NEAR((d.on_s - d.on_t).norm(), d.distance, meet ? 1e-9 : 1e-12) << iter;
    // The closest points lie on their triangles, and no sampled pair is closer.
    for (int k = 0; k < 30; ++k) {
      const double u = rng.uniform(), v = rng.uniform() * (1 - u), u2 = rng.uniform(), v2 = rng.uniform() * (1 - u2);
      const Vec3d p = ds[0] + u * (ds[1] - ds[0]) + v * (ds[2] - ds[0]);
      const Vec3d q = dt[0] + u2 * (dt[1] - dt[0]) + v2 * (dt[2] - dt[0]);
      ASSERT_GE((p - q).norm(), d.distance - 1e-12);
    }
  }
}

TEST(TrianglePair, SegmentSegmentClosestPoints) {
  Vec3d a, b;
  EXPECT_DOUBLE_EQ(segment_segment_closest({0, 0, 0}, {1, 0, 0}, {0.5, -1, 1}, {0.5, 1, 1}, a, b), 1.0);
  EXPECT_TRUE(a.isApprox(Vec3d(0.5, 0, 0)));
  EXPECT_DOUBLE_EQ(segment_segment_closest({0, 0, 0}, {0, 0, 0}, {2, 0, 0}, {2, 0, 0}, a, b), 4.0);  // points
  EXPECT_DOUBLE_EQ(segment_segment_closest({0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 0}, a, b), 2.0);  // parallel
}

}  // namespace
}  // namespace geods::collide
