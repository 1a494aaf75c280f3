#include "geods/bsp/bsp_tree.hpp"

#include <gtest/gtest.h>

#include <random>

#include "bsp/meshes.hpp"
#include "geods/bsp/csg.hpp"
#include "geods/core/error.hpp"

using namespace geods;
using namespace geods::bsp;
using namespace bsp_test;

TEST(BspExact, Int256MatchesInt128) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 2000; ++i) {
    const __int128 a = static_cast<std::int64_t>(rng()) >> (rng() % 40);
    const __int128 b = static_cast<std::int64_t>(rng()) >> (rng() % 40);
    const __int128 p = (a >> 1) * (b >> 2);
    const Int256 x = Int256::from(a >> 1) * Int256::from(b >> 2);
    EXPECT_EQ(x.sign(), (p > 0) - (p < 0));
    const Int256 d = Int256::from(a) - Int256::from(b);
    EXPECT_EQ(d.sign(), (a > b) - (a < b));
  }
}

// Oracle: with small coefficients the homogeneous point and the plane value fit __int128.
TEST(BspExact, SideMatchesSmallIntegerOracle) {
  std::mt19937_64 rng(2);
  PlaneSet ps;
  auto rnd = [&](int r) { return static_cast<std::int64_t>(rng() % (2 * r + 1)) - r; };
  int zeros = 0;
  for (int it = 0; it < 3000; ++it) {
    Plane P[4];
    for (auto& p : P) p = {rnd(3), rnd(3), rnd(3), rnd(6)};
    auto det3 = [](__int128 a, __int128 b, __int128 c, __int128 d, __int128 e, __int128 f, __int128 g, __int128 h,
                   __int128 i) { return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g); };
    const __int128 W = det3(P[0].a, P[0].b, P[0].c, P[1].a, P[1].b, P[1].c, P[2].a, P[2].b, P[2].c);
    if (W == 0) continue;
    const __int128 X = -det3(P[0].d, P[0].b, P[0].c, P[1].d, P[1].b, P[1].c, P[2].d, P[2].b, P[2].c);
    const __int128 Y = -det3(P[0].a, P[0].d, P[0].c, P[1].a, P[1].d, P[1].c, P[2].a, P[2].d, P[2].c);
    const __int128 Z = -det3(P[0].a, P[0].b, P[0].d, P[1].a, P[1].b, P[1].d, P[2].a, P[2].b, P[2].d);
    const __int128 V = P[3].a * X + P[3].b * Y + P[3].c * Z + P[3].d * W;
    const int expect = ((V > 0) - (V < 0)) * ((W > 0) - (W < 0));
    std::uint32_t id[4];
    for (int k = 0; k < 4; ++k) id[k] = ps.add(P[k]);
    EXPECT_EQ(ps.side(id[3], id[0], id[1], id[2]), expect);
    EXPECT_EQ(ps.side(id[3] | kFlip, id[0], id[1], id[2]), -expect);
    zeros += expect == 0;
  }
  EXPECT_GT(zeros, 10);  // degenerate cases were exercised
}

// At the full grid range the filter cannot decide zeros: a snapped triangle's corner lies
// exactly on its support and edge planes and on any plane through it.
TEST(BspExact, ZerosAtFullGridRange) {
  std::mt19937_64 rng(3);
  const std::int64_t R = std::int64_t{1} << kGridBits;
  auto rnd = [&] { return static_cast<std::int64_t>(rng() % (2 * R + 1)) - R; };
  PlaneSet ps;
  for (int it = 0; it < 500; ++it) {
    std::array<std::int64_t, 3> p{rnd(), rnd(), rnd()}, q{rnd(), rnd(), rnd()}, r{rnd(), rnd(), rnd()},
        s{rnd(), rnd(), rnd()}, t{rnd(), rnd(), rnd()};
    const auto a = ps.add(PlaneSet::through(p, q, r));
    const auto b = ps.add(PlaneSet::through(p, q, s));
    const auto c = ps.add(PlaneSet::through(p, r, s));
    const auto d = ps.add(PlaneSet::through(p, s, t));
    const auto e = ps.add(PlaneSet::through(q, r, t));
    EXPECT_EQ(ps.side(d, a, b, c), 0);
    // The sign at p of a plane through q, r, t is orient3d of integer points (exact in long double? no:
    // compare with __int128 orientation).
    const __int128 u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]},
                   w[3] = {t[0] - p[0], t[1] - p[1], t[2] - p[2]};
    // plane e through q, r, t with normal (r-q) x (t-q); value at p = n . (p - q)
    const __int128 rq[3] = {r[0] - q[0], r[1] - q[1], r[2] - q[2]}, tq[3] = {t[0] - q[0], t[1] - q[1], t[2] - q[2]};
    const __int128 n[3] = {rq[1] * tq[2] - rq[2] * tq[1], rq[2] * tq[0] - rq[0] * tq[2], rq[0] * tq[1] - rq[1] * tq[0]};
    const __int128 val = n[0] * (p[0] - q[0]) + n[1] * (p[1] - q[1]) + n[2] * (p[2] - q[2]);
    (void)u, (void)v, (void)w;
    EXPECT_EQ(ps.side(e, a, b, c), (val > 0) - (val < 0));
  }
}

TEST(BspTree, CubeClassifyAndStats) {
  const Triangles cube = box({0, 0, 0}, {1, 1, 1});
  for (Heuristic h : {Heuristic::cost, Heuristic::random, Heuristic::balanced}) {
    BuildOptions o;
    o.heuristic = h;
    const BspTree t(cube.vertices, cube.triangles, o);
    t.validate();
    EXPECT_EQ(t.stats().polygons, 12u);
    EXPECT_GE(t.stats().fragments, 12u);
    EXPECT_EQ(t.classify({0.5, 0.5, 0.5}), -1);
    EXPECT_EQ(t.classify({1.5, 0.5, 0.5}), 1);
    EXPECT_EQ(t.classify({1.0, 0.5, 0.5}), 0);
    EXPECT_EQ(t.classify({0.0, 0.0, 0.0}), 0);
    EXPECT_EQ(t.classify({-1e-12, 0.5, 0.5}), 1);
    EXPECT_GT(t.stats().expected_cost, 1.0);
  }
}

TEST(BspTree, ClassifyMatchesWindingNumber) {
  const Triangles shapes[] = {torus(1.0, 0.4, 16, 8), sphere(1.0, 8, 12, {0.1, 0.2, 0.3}),
                              transformed(torus(0.7, 0.3, 12, 8), 0.3, {0.1, 0, 0})};
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  for (const auto& m : shapes) {
    ASSERT_GT(signed_volume(m), 0);
    for (Heuristic h : {Heuristic::cost, Heuristic::random, Heuristic::balanced}) {
      BuildOptions o;
      o.heuristic = h;
      const BspTree t(m.vertices, m.triangles, o);
      t.validate();
      int disagreements = 0, checked = 0;
      for (int i = 0; i < 400; ++i) {
        const Vec3d p{u(rng), u(rng), u(rng)};
        const double w = winding_number(m, p);
        if (std::fabs(w - std::round(w)) > 1e-3) continue;  // too close to the surface for the oracle
        ++checked;
        disagreements += t.classify(p) != (std::round(w) > 0.5 ? -1 : 1);
      }
      EXPECT_GT(checked, 300);
      EXPECT_EQ(disagreements, 0) << heuristic_name(h);
    }
  }
}

TEST(BspTree, FirstHitMatchesBruteForce) {
  const Triangles m = torus(1.0, 0.4, 20, 10);
  const BspTree t(m.vertices, m.triangles);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  int hits = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3d o{2.5 * g(rng), 2.5 * g(rng), 2.5 * g(rng)};
    const Vec3d d = (Vec3d{0.3 * g(rng), 0.3 * g(rng), 0.3 * g(rng)} - o).normalized();
    // Brute force: Moller-Trumbore over all triangles.
    double best = std::numeric_limits<double>::infinity();
    for (const auto& tr : m.triangles) {
      const Vec3d a = m.vertices[tr[0]], e1 = m.vertices[tr[1]] - a, e2 = m.vertices[tr[2]] - a;
      const Vec3d pv = d.cross(e2);
      const double det = e1.dot(pv);
      if (std::fabs(det) < 1e-14) continue;
      const Vec3d tv = o - a;
      const double uu = tv.dot(pv) / det;
      const Vec3d qv = tv.cross(e1);
      const double vv = d.dot(qv) / det;
      const double tt = e2.dot(qv) / det;
      if (uu >= 0 && vv >= 0 && uu + vv <= 1 && tt >= 0) best = std::min(best, tt);
    }
    const auto h = t.first_hit(o, d);
    if (std::isinf(best)) {
      EXPECT_TRUE(std::isinf(h.t) || h.t > 0);
    } else {
      ++hits;
      EXPECT_NEAR(h.t, best, 8 * t.grid().step());  // the tree holds the snapped mesh
    }
  }
  EXPECT_GT(hits, 30);
}

// Oracle: exact occlusion sampled by rays. Along every ray from the eye, a fragment hit
// farther must come before a fragment hit nearer in back-to-front order.
TEST(BspTree, VisibilityOrderMatchesRayOcclusion) {
  Triangles scene;
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 12; ++i) {
    const Vec3d lo{3.0 * (i % 4) + u(rng), 3.0 * (i / 4) + u(rng), 2 * u(rng)};
    const Triangles b = transformed(box(lo, lo + Vec3d{1 + u(rng), 1 + u(rng), 1 + u(rng)}), 0.0, {0, 0, 0});
    const auto base = std::uint32_t(scene.vertices.size());
    scene.vertices.insert(scene.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (auto t : b.triangles) scene.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  scene = transformed(scene, 0.4, {0, 0, 0});
  const BspTree t(scene.vertices, scene.triangles);
  t.validate();
  // Fragment polygons in world coordinates.
  std::vector<std::vector<Vec3d>> polys;
  for (const auto& f : t.fragments()) {
    std::vector<Vec3d> p;
    for (std::size_t k = 0; k < f.size(); ++k) p.push_back(t.grid().to_world(t.planes().point(f.vertex(k))));
    polys.push_back(p);
  }
  for (int view = 0; view < 3; ++view) {
    const Vec3d eye{-5 + 25 * u(rng), -5 + 20 * u(rng), 6 + 4 * u(rng)};
    for (bool b2f : {true, false}) {
      const auto order = t.visibility_order(eye, b2f);
      ASSERT_EQ(order.size(), t.fragments().size());
      std::vector<std::size_t> pos(order.size());
      for (std::size_t i = 0; i < order.size(); ++i) pos[order[i]] = b2f ? i : order.size() - 1 - i;
      int pairs = 0;
      for (int r = 0; r < 500; ++r) {
        const Vec3d target{12 * u(rng), 9 * u(rng), 3 * u(rng)};
        const Vec3d d = (transformed(Triangles{{target}, {}}, 0.4, {0, 0, 0}).vertices[0] - eye).normalized();
        std::vector<std::pair<double, std::size_t>> hits;
        for (std::size_t f = 0; f < polys.size(); ++f)
          for (std::size_t k = 1; k + 1 < polys[f].size(); ++k) {
            const Vec3d a = polys[f][0], e1 = polys[f][k] - a, e2 = polys[f][k + 1] - a;
            const Vec3d pv = d.cross(e2);
            const double det = e1.dot(pv);
            if (std::fabs(det) < 1e-12) continue;
            const Vec3d tv = eye - a;
            const double uu = tv.dot(pv) / det, vv = d.dot(tv.cross(e1)) / det, tt = e2.dot(tv.cross(e1)) / det;
            if (uu > 1e-9 && vv > 1e-9 && uu + vv < 1 - 1e-9 && tt > 0) hits.push_back({tt, f});
          }
        std::sort(hits.begin(), hits.end());
        for (std::size_t i = 1; i < hits.size(); ++i) {
          if (hits[i].first - hits[i - 1].first < 1e-9) continue;
          ++pairs;
          EXPECT_LT(pos[hits[i].second], pos[hits[i - 1].second]);
        }
      }
      EXPECT_GT(pairs, 100);
    }
  }
  // A frustum around one box: every fragment listed is on the frustum's side of some plane.
  const Vec3d eye{1.5, 1.5, 20};
  const auto all = t.visibility_order(eye);
  const auto culled = t.visibility_order(eye, true, {eye, {0, 0, -1}, {0.2, 0, -1}, {0.2, 0.2, -1}, {0, 0.2, -1}});
  EXPECT_LT(culled.size(), all.size());
}

TEST(BspTree, BadInput) {
  const Triangles cube = box({0, 0, 0}, {1, 1, 1});
  EXPECT_THROW(BspTree({}, {}), Error);
  auto bad = cube;
  bad.vertices[3][1] = std::nan("");
  EXPECT_THROW(BspTree(bad.vertices, bad.triangles), Error);
  bad = cube;
  bad.triangles[2][0] = 99;
  EXPECT_THROW(BspTree(bad.vertices, bad.triangles), Error);
  bad = cube;
  for (auto& t : bad.triangles) t[1] = t[0];  // all degenerate
  EXPECT_THROW(BspTree(bad.vertices, bad.triangles), Error);
  BuildOptions o;
  o.alpha = -1;
  EXPECT_THROW(BspTree(cube.vertices, cube.triangles, o), Error);
  EXPECT_THROW(parse_heuristic("best"), Error);
  // An open mesh (a cube without its top) builds; labels are a best effort.
  auto open = cube;
  open.triangles.resize(10);
  const BspTree t(open.vertices, open.triangles);
  t.validate();
}
