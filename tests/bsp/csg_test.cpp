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
void check_pair(const Triangles& a, const Triangles& b, double tol, int points = 150) {
  std::map<CsgOp, double> vol;
  std::map<CsgOp, Triangles> out;
  double va = 0, vb = 0;  // the snapped operands' volumes
  for (CsgOp op : {CsgOp::union_, CsgOp::intersection, CsgOp::difference, CsgOp::xor_}) {
    const CsgResult r = csg(a, b, op);
    SCOPED_TRACE(std::string(csg_op_name(op)));
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
    check_pair(cube, c.b, 1e-9, 60);
  }
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
