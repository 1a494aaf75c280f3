#include "common/data_files.hpp"
#include "geods/bsp/csg.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "bsp/meshes.hpp"
#include "geods/core/error.hpp"

using namespace geods;
using namespace geods::bsp;
using namespace bsp_test;

namespace {

// Every undirected edge has as many uses in each direction (closed, consistently oriented).
void expect_closed(const Triangles& m) {
  EXPECT_TRUE(is_closed(m));
  for (const auto& t : m.triangles) {
    EXPECT_NE(t[0], t[1]);
    EXPECT_NE(t[1], t[2]);
    EXPECT_NE(t[0], t[2]);
  }
}

bool member(CsgOp op, bool a, bool b) {
  switch (op) {
    case CsgOp::union_: return a || b;
    case CsgOp::intersection: return a && b;
    case CsgOp::difference: return a && !b;
    case CsgOp::xor_: return a != b;
  }
  return false;
}

// Checks closedness, the volume identities and random-point membership (winding numbers of
// the inputs and of the output, away from the surfaces).
void check_pair(const Triangles& a, const Triangles& b, double tol, int points = 150,
                CsgMethod method = CsgMethod::local) {
  std::map<CsgOp, double> vol;
  std::map<CsgOp, Triangles> out;
  double va = 0, vb = 0;  // the snapped operands' volumes
  for (CsgOp op : {CsgOp::union_, CsgOp::intersection, CsgOp::difference, CsgOp::xor_}) {
    const CsgResult r = csg(a, b, op, {}, method);
    SCOPED_TRACE(std::string(csg_op_name(op)) + " " + std::string(csg_method_name(method)));
    expect_closed(r.mesh);
    EXPECT_TRUE(r.stats.closed);
    EXPECT_NEAR(r.stats.volume, signed_volume(r.mesh), 1e-12);
    vol[op] = r.stats.volume;
    va = r.stats.volume_a, vb = r.stats.volume_b;
    out[op] = r.mesh;
  }
  const double scale = std::max(va, vb);
  EXPECT_NEAR(vol[CsgOp::union_] + vol[CsgOp::intersection], va + vb, tol * scale);
  EXPECT_NEAR(vol[CsgOp::difference], va - vol[CsgOp::intersection], tol * scale);
  EXPECT_NEAR(vol[CsgOp::xor_], vol[CsgOp::union_] - vol[CsgOp::intersection], tol * scale);
  Vec3d lo = a.vertices[0], hi = lo;
  for (const auto* m : {&a, &b})
    for (const auto& v : m->vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  int checked = 0;
  for (int i = 0; i < points; ++i) {
    Vec3d p;
    for (int c = 0; c < 3; ++c) p[c] = lo[c] - 0.1 + (hi[c] - lo[c] + 0.2) * u(rng);
    const double wa = winding_number(a, p), wb = winding_number(b, p);
    if (std::fabs(wa - std::round(wa)) > 1e-3 || std::fabs(wb - std::round(wb)) > 1e-3) continue;
    for (CsgOp op : {CsgOp::union_, CsgOp::intersection, CsgOp::difference, CsgOp::xor_}) {
      const double w = winding_number(out[op], p);
      if (std::fabs(w - std::round(w)) > 1e-3) continue;
      ++checked;
      EXPECT_EQ(std::round(w) > 0.5, member(op, std::round(wa) > 0.5, std::round(wb) > 0.5)) << csg_op_name(op);
    }
  }
  if (points > 0) {
    EXPECT_GT(checked, points);
  }
}

}  // namespace

TEST(Csg, OverlappingBoxesExactVolumes) {
  const Triangles a = box({0, 0, 0}, {2, 2, 2}), b = box({1, 1, 1}, {3, 3.5, 3});
  EXPECT_NEAR(csg(a, b, CsgOp::union_).stats.volume, 8 + 10 - 1, 1e-12);
  EXPECT_NEAR(csg(a, b, CsgOp::intersection).stats.volume, 1, 1e-12);
  EXPECT_NEAR(csg(a, b, CsgOp::difference).stats.volume, 7, 1e-12);
  EXPECT_NEAR(csg(a, b, CsgOp::xor_).stats.volume, 7 + 9, 1e-12);
  check_pair(a, b, 1e-12);
}

TEST(Csg, CurvedSolids) {
  const Triangles a = torus(1.0, 0.4, 16, 8);
  const Triangles b = transformed(sphere(0.8, 6, 10), 0.2, {0.9, 0.1, 0.2});
  check_pair(a, b, 1e-9);
  const Triangles c = transformed(torus(1.0, 0.4, 12, 6), 1.0, {0.3, 0.2, 0.1});
  check_pair(a, c, 1e-9, 60);
  check_pair(a, b, 1e-9, 60, CsgMethod::bsp_merge);
}

// The local method and the merge of the seed give the same solid: equal volumes (to
// rounding) and equal membership of random points (winding numbers of both outputs), on
// the bunny of data/ against a ball across its surface, and on a torus against a
// sphere plus two small spheres far from the torus's surface, one inside the torus and one
// in its hole (components labelled by the whole-operand fallback).
TEST(Csg, LocalMatchesMerge) {
  const Triangles bunny = from_tri_mesh(test::data_mesh("bunny.ply"));
  Vec3d lo = bunny.vertices[0], hi = lo;
  for (const auto& v : bunny.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double size = (hi - lo).maxCoeff();
  const Triangles ball = sphere(0.3 * size, 8, 12, 0.5 * (lo + hi) + Vec3d{0.3 * size, 0.1 * size, 0});
  Triangles three = transformed(sphere(0.8, 6, 10), 0.2, {0.9, 0.1, 0.2});
  for (const Vec3d& c : {Vec3d{0, 0, 0}, Vec3d{-1, 0, 0}}) {
    const Triangles s = sphere(0.1, 4, 6, c);
    const auto base = static_cast<std::uint32_t>(three.vertices.size());
    three.vertices.insert(three.vertices.end(), s.vertices.begin(), s.vertices.end());
    for (auto t : s.triangles) three.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  struct Pair {
    const char* name;
    Triangles a, b;
    CsgOp op;
  };
  const std::vector<Pair> pairs = {
      {"bunny union ball", bunny, ball, CsgOp::union_},
      {"torus xor three spheres", torus(1.0, 0.4, 16, 8), three, CsgOp::xor_},
      {"torus minus three spheres", torus(1.0, 0.4, 16, 8), three, CsgOp::difference},
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (const auto& p : pairs) {
    SCOPED_TRACE(p.name);
    const CsgResult l = csg(p.a, p.b, p.op, {}, CsgMethod::local);
    const CsgResult m = csg(p.a, p.b, p.op, {}, CsgMethod::bsp_merge);
    EXPECT_TRUE(l.stats.closed);
    EXPECT_TRUE(m.stats.closed);
    EXPECT_NEAR(l.stats.volume, m.stats.volume, 1e-9 * std::fabs(m.stats.volume_a));
    EXPECT_LE(l.mesh.triangles.size(), m.mesh.triangles.size());
    Vec3d blo = l.mesh.vertices[0], bhi = blo;
    for (const auto& v : m.mesh.vertices) blo = blo.cwiseMin(v), bhi = bhi.cwiseMax(v);
    int checked = 0;
    for (int i = 0; i < 40; ++i) {
      Vec3d q;
      for (int c = 0; c < 3; ++c) q[c] = blo[c] + (bhi[c] - blo[c]) * u(rng);
      const double wl = winding_number(l.mesh, q), wm = winding_number(m.mesh, q);
      if (std::fabs(wl - std::round(wl)) > 1e-3 || std::fabs(wm - std::round(wm)) > 1e-3) continue;
      ++checked;
      EXPECT_EQ(std::round(wl), std::round(wm));
    }
    EXPECT_GT(checked, 30);
  }
}

// The fuzz corpus of coplanar, touching and near-coplanar pairs (where csg.js-style BSP
// booleans loop or crack): each terminates with closed outputs satisfying the identities.
TEST(Csg, AdversarialCorpus) {
  const Triangles cube = box({0, 0, 0}, {1, 1, 1});
  struct Case {
    const char* name;
    Triangles b;
  };
  std::vector<Case> cases = {
      {"identical", cube},
      {"shifted 1e-9", transformed(cube, 0.0, {1e-9, 1e-9, 0})},
      {"rotated 1e-9", transformed(cube, 1e-9, {0, 0, 0})},
      {"face to face", box({1, 0, 0}, {2, 1, 1})},
      {"shared face part", box({1, 0.25, 0.25}, {2, 0.75, 0.75})},
      {"edge touching", box({1, 1, 0}, {2, 2, 1})},
      {"corner touching", box({1, 1, 1}, {2, 2, 2})},
      {"coplanar inside", box({0.25, 0.25, 0}, {0.75, 0.75, 1})},
      {"sliver", box({0.5, -1, -1}, {0.5 + 2e-5, 2, 2})},  // a few grid steps thick
      {"coplanar rotated", transformed(box({-0.5, -0.5, 0}, {0.5, 0.5, 1}), 0.3, {0.5, 0.5, 0})},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    for (CsgMethod method : {CsgMethod::local, CsgMethod::bsp_merge}) check_pair(cube, c.b, 1e-9, 60, method);
  }
  // A slab thinner than half a grid step is flattened by the snapping: its two big faces
  // cancel (local method), the other operand is unchanged.
  const Triangles flat = box({0.5, -1, -1}, {0.5 + 1e-8, 2, 2});
  check_pair(cube, flat, 1e-9, 60);
  EXPECT_NEAR(csg(cube, flat, CsgOp::union_).stats.volume, 1, 1e-12);
  EXPECT_EQ(csg(flat, cube, CsgOp::difference).mesh.triangles.size(), 0u);
  // Identities with exact expected values.
  EXPECT_NEAR(csg(cube, cube, CsgOp::union_).stats.volume, 1, 1e-12);
  EXPECT_NEAR(csg(cube, cube, CsgOp::intersection).stats.volume, 1, 1e-12);
  EXPECT_EQ(csg(cube, cube, CsgOp::difference).mesh.triangles.size(), 0u);
  EXPECT_NEAR(csg(cube, box({1, 0, 0}, {2, 1, 1}), CsgOp::union_).stats.volume, 2, 1e-12);
  EXPECT_EQ(csg(cube, box({1, 0, 0}, {2, 1, 1}), CsgOp::intersection).mesh.triangles.size(), 0u);
}

TEST(Csg, BadInput) {
  const Triangles cube = box({0, 0, 0}, {1, 1, 1});
  EXPECT_THROW(csg(cube, Triangles{}, CsgOp::union_), Error);
  auto bad = cube;
  bad.vertices[0][0] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(csg(bad, cube, CsgOp::union_), Error);
  EXPECT_THROW(parse_csg_op("plus"), Error);
  // Far from the origin relative to its size.
  EXPECT_THROW(csg(transformed(cube, 0, {1e30, 0, 0}), cube, CsgOp::union_), Error);
}
