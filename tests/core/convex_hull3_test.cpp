// convex_hull3 against exact oracles: every point on the inner side of every
// face (orient3d), a closed consistently oriented surface with Euler
// characteristic 2, and the corners found by brute force over all planes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "geods/core/convex_hull3.hpp"
#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"

namespace geods {
namespace {

using Points = std::vector<Vec3d>;

// Faces keep every point on their inner side, no face is degenerate, every
// directed edge has its reverse exactly once, V - E + F = 2, and the listed
// vertices are exactly the face corners.
void check_solid_hull(const Points& p, const ConvexHull3& hull) {
  ASSERT_EQ(hull.dimension, 3);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  std::set<std::uint32_t> corners;
  for (const auto& f : hull.faces) {
    for (std::size_t i = 0; i < p.size(); ++i)
      ASSERT_GE(orient3d(p[f[0]], p[f[1]], p[f[2]], p[i]), 0) << "point " << i << " outside a face";
    bool flat = true;  // exact: all three coordinate projections collinear
    for (int x = 0; x < 3; ++x) {
      const int y = (x + 1) % 3;
      flat = flat && orient2d(Vec2d(p[f[0]][x], p[f[0]][y]), Vec2d(p[f[1]][x], p[f[1]][y]),
                              Vec2d(p[f[2]][x], p[f[2]][y])) == 0;
    }
    ASSERT_FALSE(flat) << "degenerate face";
    for (int e = 0; e < 3; ++e) {
      ++edges[{f[e], f[(e + 1) % 3]}];
      corners.insert(f[e]);
    }
  }
  for (const auto& [e, count] : edges) {
    ASSERT_EQ(count, 1);
    ASSERT_EQ(edges.count({e.second, e.first}), 1u) << "open or inconsistently oriented edge";
  }
  EXPECT_EQ(std::vector<std::uint32_t>(corners.begin(), corners.end()), hull.vertices);
  const long v = long(hull.vertices.size()), e = long(edges.size() / 2), f = long(hull.faces.size());
  EXPECT_EQ(v - e + f, 2);
}

// Corners by brute force for points in general position: i is a corner iff
// some plane through i and two other points has all points on one side.
std::vector<std::uint32_t> brute_corners(const Points& p) {
  std::set<std::uint32_t> out;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t k = j + 1; k < n; ++k) {
        int pos = 0, neg = 0;
        for (std::size_t m = 0; m < n; ++m) {
          const double o = orient3d(p[i], p[j], p[k], p[m]);
          pos += o > 0, neg += o < 0;
        }
        if (pos == 0 || neg == 0) out.insert({std::uint32_t(i), std::uint32_t(j), std::uint32_t(k)});
      }
  return {out.begin(), out.end()};
}

TEST(ConvexHull3, RandomCloudsMatchBruteForce) {
  Rng rng(31);
  for (int trial = 0; trial < 30; ++trial) {
    Points p;
    const int n = 4 + int(rng.uniform() * 40);
    for (int i = 0; i < n; ++i) p.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const ConvexHull3 hull = convex_hull3(p);
    check_solid_hull(p, hull);
    EXPECT_EQ(hull.vertices, brute_corners(p));
  }
}

TEST(ConvexHull3, PointsOnASphereAreAllCorners) {
  Rng rng(32);
  Points p;
  for (int i = 0; i < 2000; ++i) {
    Vec3d v(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    p.push_back(v.normalized());
  }
  const ConvexHull3 hull = convex_hull3(p);
  check_solid_hull(p, hull);
  // Unit vectors rounded to doubles are in convex position except for rare
  // rounding ties; nearly all must be corners.
  EXPECT_GE(hull.vertices.size(), 1990u);
}

TEST(ConvexHull3, LatticeCubeHasEightCorners) {
  // Many points on the faces, edges and inside: only the corners remain.
  Points p;
  for (int z = 0; z <= 4; ++z)
    for (int y = 0; y <= 4; ++y)
      for (int x = 0; x <= 4; ++x) p.emplace_back(x, y, z);
  for (int i = 0; i < 10; ++i) p.push_back(p[std::size_t(i * 7)]);  // duplicates
  const ConvexHull3 hull = convex_hull3(p);
  check_solid_hull(p, hull);
  ASSERT_EQ(hull.vertices.size(), 8u);
  for (std::uint32_t v : hull.vertices)
    for (int a = 0; a < 3; ++a) EXPECT_TRUE(p[v][a] == 0 || p[v][a] == 4);
}

TEST(ConvexHull3, ExtremePointsInRandomDirectionsAreCorners) {
  Rng rng(33);
  Points p;
  for (int i = 0; i < 5000; ++i) {
    // A clustered, flattened cloud with many near-coplanar points.
    p.emplace_back(rng.uniform(-1, 1), 0.01 * rng.uniform(-1, 1), std::round(rng.uniform(-3, 3)));
  }
  const ConvexHull3 hull = convex_hull3(p);
  check_solid_hull(p, hull);
  const std::set<std::uint32_t> corners(hull.vertices.begin(), hull.vertices.end());
  for (int k = 0; k < 200; ++k) {
    const Vec3d d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    std::uint32_t best = 0;
    for (std::uint32_t i = 1; i < p.size(); ++i)
      if (d.dot(p[i]) > d.dot(p[best])) best = i;
    // The maximizer is unique for a generic direction unless it ties exactly.
    std::size_t ties = 0;
    for (const Vec3d& q : p) ties += d.dot(q) == d.dot(p[best]);
    if (ties == 1) {
      EXPECT_TRUE(corners.count(best)) << "extreme point " << best << " is not a corner";
    }
  }
}

TEST(ConvexHull3, HugeAndTinyCoordinates) {
  for (double scale : {1e-300, 1e200}) {
    Rng rng(34);
    Points p;
    for (int i = 0; i < 25; ++i) p.emplace_back(scale * rng.uniform(-1, 1), scale * rng.uniform(-1, 1), scale * rng.uniform(-1, 1));
    const ConvexHull3 hull = convex_hull3(p);
    check_solid_hull(p, hull);
    EXPECT_EQ(hull.vertices, brute_corners(p));
  }
}

TEST(ConvexHull3, LowerDimensions) {
  EXPECT_EQ(convex_hull3(Points{}).dimension, -1);
  const ConvexHull3 one = convex_hull3(Points{{1, 2, 3}, {1, 2, 3}});
  EXPECT_EQ(one.dimension, 0);
  EXPECT_EQ(one.vertices, std::vector<std::uint32_t>{0});
  const ConvexHull3 line = convex_hull3(Points{{1, 1, 1}, {3, 3, 3}, {0, 0, 0}, {2, 2, 2}});
  EXPECT_EQ(line.dimension, 1);
  EXPECT_EQ(line.vertices, (std::vector<std::uint32_t>{1, 2}));
  // Coplanar: z = x + 2 y exactly, corners against a 2D brute force.
  Rng rng(35);
  Points p;
  for (int i = 0; i < 60; ++i) {
    const double x = std::round(rng.uniform(-20, 20)), y = std::round(rng.uniform(-20, 20));
    p.emplace_back(x, y, x + 2 * y);
  }
  const ConvexHull3 plane = convex_hull3(p);
  EXPECT_EQ(plane.dimension, 2);
  EXPECT_TRUE(plane.faces.empty());
  std::set<std::uint32_t> expected;
  for (std::size_t i = 0; i < p.size(); ++i) {
    // i is a corner iff it is not in a closed triangle of three other points
    // and not on the open segment between two others.
    bool covered = false;
    const Vec2d pi(p[i][0], p[i][1]);
    for (std::size_t j = 0; j < p.size() && !covered; ++j)
      for (std::size_t k = 0; k < p.size() && !covered; ++k) {
        if (j == i || k == i || p[j] == p[i] || p[k] == p[i]) continue;
        const Vec2d a(p[j][0], p[j][1]), b(p[k][0], p[k][1]);
        if (orient2d(a, b, pi) == 0 && (pi - a).dot(pi - b) < 0) covered = true;
        for (std::size_t m = 0; m < p.size() && !covered; ++m) {
          if (m == i || p[m] == p[i]) continue;
          const Vec2d c(p[m][0], p[m][1]);
          const double o1 = orient2d(a, b, pi), o2 = orient2d(b, c, pi), o3 = orient2d(c, a, pi);
          if (orient2d(a, b, c) != 0 && ((o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0)))
            covered = true;
        }
      }
    if (!covered) expected.insert(std::uint32_t(i));
  }
  // Of duplicate corners the hull names one; compare positions.
  std::set<std::pair<double, double>> got_pos, want_pos;
  for (std::uint32_t v : plane.vertices) got_pos.insert({p[v][0], p[v][1]});
  for (std::uint32_t v : expected) want_pos.insert({p[v][0], p[v][1]});
  EXPECT_EQ(got_pos, want_pos);
  EXPECT_EQ(plane.vertices.size(), got_pos.size());
}

TEST(ConvexHull3, NonFiniteRaises) {
  EXPECT_THROW(convex_hull3(Points{{0, 0, 0}, {1, std::nan(""), 0}}), Error);
  EXPECT_THROW(convex_hull3(Points{{0, 0, std::numeric_limits<double>::infinity()}}), Error);
}

}  // namespace
}  // namespace geods
