// Delaunay2 against independent oracles: the empty-circle property by brute
// force with exact incircle, Euler's formula, the convex hull by Andrew's
// monotone chain, point location and nearest points by brute force; on seeded
// uniform, clustered and degenerate sets (duplicates, collinear, integer grids,
// exactly co-circular points, tiny/huge/mixed magnitudes); insert and remove.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/delaunay2.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = Delaunay2::no_edge;

bool lex_less(const Vec2d& a, const Vec2d& b) { return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]); }

// Strictly convex hull vertices, counter-clockwise from the lexicographically smallest.
std::vector<Vec2d> monotone_chain(std::vector<Vec2d> p) {
  std::sort(p.begin(), p.end(), lex_less);
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  std::vector<Vec2d> hull(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && orient2d(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && orient2d(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k - 1);
  return hull;
}

// The strictly convex corners of the triangulation's hull, from the smallest.
std::vector<Vec2d> hull_corners(const Delaunay2& dt) {
  const auto& h = dt.hull();
  std::vector<Vec2d> corners;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const Vec2d& a = dt.points()[h[(i + h.size() - 1) % h.size()]];
    const Vec2d& b = dt.points()[h[i]];
    const Vec2d& c = dt.points()[h[(i + 1) % h.size()]];
    if (orient2d(a, b, c) > 0) corners.push_back(b);
  }
  if (corners.empty()) return corners;
  std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end(), lex_less), corners.end());
  return corners;
}

// Everything a Delaunay triangulation of `points` must satisfy, checked
// without trusting the structure (besides its own validate()).
void check_delaunay(const Delaunay2& dt, std::span<const Vec2d> points, bool brute_force_circles = true) {
  ASSERT_NO_THROW(dt.validate());
  const auto& tri = dt.triangles();
  std::vector<std::uint32_t> distinct;
  std::map<std::pair<double, double>, std::uint32_t> first;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    const std::uint32_t r = dt.representative(i);
    const auto [it, is_first] = first.insert({{points[i][0], points[i][1]}, i});
    ASSERT_EQ(r, it->second) << "first occurrence";
    if (is_first) distinct.push_back(i);
  }
  // Collinear or fewer than 3 distinct points: no triangles.
  const std::vector<Vec2d> chain = monotone_chain(std::vector<Vec2d>(points.begin(), points.end()));
  if (chain.size() < 3) {
    EXPECT_TRUE(dt.degenerate());
    EXPECT_EQ(dt.hull().size(), distinct.size());
    return;
  }
  const std::size_t n = distinct.size(), h = dt.hull().size();
  ASSERT_EQ(tri.size() / 3, 2 * n - h - 2) << "Euler";
  std::vector<char> used(points.size(), 0);
  for (std::size_t t = 0; t < tri.size(); t += 3) {
    const Vec2d &a = points[tri[t]], &b = points[tri[t + 1]], &c = points[tri[t + 2]];
    ASSERT_GT(orient2d(a, b, c), 0) << "counter-clockwise";
    for (int s = 0; s < 3; ++s) used[tri[t + s]] = 1;
    if (brute_force_circles) {
      for (std::uint32_t v : distinct) ASSERT_LE(incircle(a, b, c, points[v]), 0) << "empty circle";
    }
  }
  for (std::uint32_t v : distinct) ASSERT_TRUE(used[v]) << "vertex " << v << " missing";
  for (std::size_t e = 0; e < tri.size(); ++e) {
    const std::uint32_t f = dt.halfedges()[e];
    if (f == kNone) continue;
    ASSERT_EQ(dt.halfedges()[f], e);
    ASSERT_EQ(tri[f], tri[Delaunay2::next(std::uint32_t(e))]);
  }
  EXPECT_EQ(hull_corners(dt), chain);
  // Every hull vertex is on the boundary of the independent hull.
  for (std::uint32_t v : dt.hull()) {
    bool on_boundary = false;
    for (std::size_t i = 0; i < chain.size() && !on_boundary; ++i)
      on_boundary = orient2d(chain[i], chain[(i + 1) % chain.size()], points[v]) == 0;
    EXPECT_TRUE(on_boundary);
  }
}

enum class Shape { uniform, clustered, duplicates, grid, circle, line, tiny, huge, mixed };

std::vector<Vec2d> make_points(Shape shape, std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec2d> p;
  switch (shape) {
    case Shape::uniform:
      for (std::size_t i = 0; i < n; ++i) p.emplace_back(rng.uniform(), rng.uniform());
      break;
    case Shape::clustered:
      for (std::size_t i = 0; i < n; ++i) {
        const double cx = double(rng.below(4)), cy = double(rng.below(3));
        p.emplace_back(cx + 1e-3 * rng.normal(), cy + 1e-3 * rng.normal());
      }
      break;
    case Shape::duplicates:
      for (std::size_t i = 0; i < n / 4; ++i) p.emplace_back(rng.uniform(), rng.uniform());
      while (p.size() < n) p.push_back(p[rng.below(p.size())]);
      break;
    case Shape::grid: {
      const std::size_t side = std::size_t(std::sqrt(double(n)));
      for (std::size_t i = 0; i < side * side; ++i) p.emplace_back(double(i % side), double(i / side));
      break;
    }
    case Shape::circle: {
      // Every integer point on x^2 + y^2 = 5^2 * 13^2 * 17^2: exactly co-circular, plus the centre.
      const long r2 = 5L * 5 * 13 * 13 * 17 * 17;
      const long r = long(std::sqrt(double(r2)));
      for (long x = -r; x <= r; ++x) {
        const long y = long(std::llround(std::sqrt(double(r2 - x * x))));
        if (x * x + y * y != r2) continue;
        p.emplace_back(double(x), double(y));
        if (y != 0) p.emplace_back(double(x), double(-y));
      }
      p.emplace_back(0.0, 0.0);
      break;
    }
    case Shape::line:
      for (std::size_t i = 0; i < n; ++i) {
        const double t = double(rng.below(n));
        p.emplace_back(3 + 2 * t, -1 + 5 * t);
      }
      break;
    case Shape::tiny:
      for (std::size_t i = 0; i < n; ++i) p.emplace_back(1e-300 * rng.uniform(), 1e-300 * rng.uniform());
      break;
    case Shape::huge:
      for (std::size_t i = 0; i < n; ++i) p.emplace_back(1e300 * rng.uniform(-1, 1), 1e300 * rng.uniform(-1, 1));
      break;
    case Shape::mixed:
      for (std::size_t i = 0; i < n; ++i) {
        const double scale = std::ldexp(1.0, int(rng.below(200)) - 100);
        p.emplace_back(scale * rng.uniform(-1, 1), scale * rng.uniform(-1, 1));
      }
      break;
  }
  return p;
}

const Shape kShapes[] = {Shape::uniform, Shape::clustered, Shape::duplicates, Shape::grid, Shape::circle,
                         Shape::line,    Shape::tiny,      Shape::huge,       Shape::mixed};

TEST(Delaunay2, EmptyCircleOnEveryShape) {
  for (Shape shape : kShapes)
    for (std::uint64_t seed : {1, 2, 3}) {
      SCOPED_TRACE("shape " + std::to_string(int(shape)) + " seed " + std::to_string(seed));
      // Tiny and huge coordinates take the predicates' slow exact path: fewer points.
      const bool slow = shape == Shape::tiny || shape == Shape::huge || shape == Shape::mixed;
      const std::vector<Vec2d> p = make_points(shape, slow ? 120 : 400, seed);
      const Delaunay2 dt(p);
      check_delaunay(dt, p);
    }
}

TEST(Delaunay2, LargerSetsAreValid) {
  for (Shape shape : {Shape::uniform, Shape::clustered, Shape::grid, Shape::duplicates}) {
    const std::vector<Vec2d> p = make_points(shape, 40000, 7);
    const Delaunay2 dt(p);
    check_delaunay(dt, p, false);
  }
}

TEST(Delaunay2, SmallAndDegenerateSets) {
  const std::vector<std::vector<Vec2d>> sets = {
      {},
      {{1, 2}},
      {{1, 2}, {1, 2}},
      {{0, 0}, {1, 1}, {2, 2}, {1, 1}},
      {{0, 0}, {1, 0}, {0, 1}},
      {{0, 0}, {0, 1}, {1, 0}},
      {{0, 0}, {1, 0}, {1, 1}, {0, 1}},  // co-circular square
      {{0, 0}, {2, 0}, {1, 0}, {3, 0}, {1, 1}},  // collinear points then one off the line
      {{5, 5}, {5, 5}, {0, 0}, {0, 0}, {1, 0}, {0, 1}},
  };
  for (const auto& p : sets) {
    const Delaunay2 dt(p);
    check_delaunay(dt, p);
  }
  const Delaunay2 line(std::vector<Vec2d>{{2, 2}, {0, 0}, {1, 1}, {0, 0}, {3, 3}});
  EXPECT_TRUE(line.degenerate());
  EXPECT_EQ(line.hull(), (std::vector<std::uint32_t>{1, 2, 0, 4}));
  EXPECT_EQ(line.representative(3), 1u);
  EXPECT_EQ(line.duplicate_count(), 1u);
  EXPECT_EQ(line.locate({1, 1}), kNone);
  EXPECT_EQ(line.nearest({2.9, 3}), 4u);
}

TEST(Delaunay2, DuplicatesMapToFirstOccurrence) {
  std::vector<Vec2d> p = make_points(Shape::uniform, 300, 11);
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; i += 3) p.push_back(p[i]);
  std::reverse(p.begin(), p.end());  // the copies come first now
  const Delaunay2 dt(p);
  check_delaunay(dt, p);
  EXPECT_EQ(dt.duplicate_count(), p.size() - n);
  for (std::uint32_t i = 0; i < p.size(); ++i)
    for (std::uint32_t j = 0; j < i; ++j)
      if (p[j] == p[i]) {
        EXPECT_EQ(dt.representative(i), dt.representative(j));
        break;
      }
}

TEST(Delaunay2, DifferentInsertionOrdersAreValid) {
  const std::vector<Vec2d> p = make_points(Shape::grid, 900, 1);
  for (std::uint64_t seed : {1, 2, 99}) {
    const Delaunay2 dt(p, {seed});
    check_delaunay(dt, p);
  }
}

// Sorted triangles with their smallest vertex first: equal for equal triangulations.
std::vector<std::array<std::uint32_t, 3>> canonical(const Delaunay2& dt) {
  std::vector<std::array<std::uint32_t, 3>> out;
  const auto& t = dt.triangles();
  for (std::size_t k = 0; k < t.size(); k += 3) {
    std::array<std::uint32_t, 3> tri{t[k], t[k + 1], t[k + 2]};
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Delaunay2, HistoryDagLocationGivesTheSameTriangulation) {
  for (Shape shape : kShapes) {
    SCOPED_TRACE("shape " + std::to_string(int(shape)));
    const bool slow = shape == Shape::tiny || shape == Shape::huge || shape == Shape::mixed;
    const std::vector<Vec2d> p = make_points(shape, slow ? 120 : 3000, 21);
    Delaunay2::Options options;
    options.location = Delaunay2Location::history_dag;
    const Delaunay2 dag(p, options);
    check_delaunay(dag, p, p.size() <= 500);
    const Delaunay2 walk(p);
    // No DAG for collinear sets (no triangles), nor for mixed magnitudes whose
    // first triangle's rounded centroid is not inside it (then the walk locates).
    if (shape != Shape::line && shape != Shape::mixed) {
      EXPECT_GT(dag.stats().dag_nodes, p.size() / 2);
    }
    EXPECT_EQ(walk.stats().dag_nodes, 0u);
    // Without four co-circular points the Delaunay triangulation is unique.
    if (shape == Shape::uniform || shape == Shape::clustered || shape == Shape::duplicates) {
      EXPECT_EQ(canonical(dag), canonical(walk));
    }
  }
}

TEST(Delaunay2, RejectsNonFinitePoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(Delaunay2(std::vector<Vec2d>{{0, 0}, {nan, 1}, {1, 1}}), Error);
  EXPECT_THROW(Delaunay2(std::vector<Vec2d>{{0, 0}, {1, -inf}, {1, 1}}), Error);
  Delaunay2 dt(std::vector<Vec2d>{{0, 0}, {1, 0}, {0, 1}});
  EXPECT_THROW(dt.insert({nan, 0}), Error);
  EXPECT_THROW(dt.locate({inf, 0}), Error);
  EXPECT_THROW(dt.remove(7), Error);
}

// Is q in the closed triangle t?
bool in_triangle(const Delaunay2& dt, std::uint32_t t, const Vec2d& q) {
  const auto& tri = dt.triangles();
  const auto p = dt.points();
  for (int s = 0; s < 3; ++s)
    if (orient2d(p[tri[3 * t + s]], p[tri[3 * t + (s + 1) % 3]], q) < 0) return false;
  return true;
}

bool inside_hull(const std::vector<Vec2d>& hull, const Vec2d& q) {
  for (std::size_t i = 0; i < hull.size(); ++i)
    if (orient2d(hull[i], hull[(i + 1) % hull.size()], q) < 0) return false;
  return true;
}

TEST(Delaunay2, LocateAndNearestAgreeWithBruteForce) {
  for (Shape shape : {Shape::uniform, Shape::clustered, Shape::grid, Shape::duplicates}) {
    const std::vector<Vec2d> p = make_points(shape, 2000, 5);
    const Delaunay2 dt(p);
    const std::vector<Vec2d> hull = monotone_chain(p);
    Rng rng(9);
    std::vector<Vec2d> queries;
    for (int i = 0; i < 300; ++i) queries.emplace_back(rng.uniform(-0.5, 4.5), rng.uniform(-0.5, 3.5));
    for (int i = 0; i < 100; ++i) queries.push_back(p[rng.below(p.size())]);  // on vertices
    for (const Vec2d& q : queries) {
      const std::uint32_t t = dt.locate(q);
      if (inside_hull(hull, q)) {
        ASSERT_NE(t, kNone);
        ASSERT_TRUE(in_triangle(dt, t, q));
        ASSERT_TRUE(in_triangle(dt, dt.locate(q, 0), q));
      } else {
        ASSERT_EQ(t, kNone);
      }
      double best = INFINITY;
      for (const Vec2d& x : p) best = std::min(best, (x - q).squaredNorm());
      const std::uint32_t v = dt.nearest(q);
      ASSERT_EQ((p[v] - q).squaredNorm(), best);
      ASSERT_EQ(dt.representative(v), v);
    }
  }
}

// The triangulation takes any finite coordinates, and so does its nearest
// vertex: squared distances of 1e300 or 1e-300 differences used to overflow
// to inf or underflow to 0 and pick an arbitrary vertex.
TEST(Delaunay2, NearestAtExtremeScales) {
  const std::vector<Vec2d> p = make_points(Shape::uniform, 300, 8);
  Rng rng(10);
  std::vector<Vec2d> queries;
  for (int i = 0; i < 100; ++i) queries.emplace_back(rng.uniform(-0.5, 4.5), rng.uniform(-0.5, 3.5));
  std::vector<std::uint32_t> want;
  for (const Vec2d& q : queries) {
    std::uint32_t best = 0;
    for (std::uint32_t i = 1; i < p.size(); ++i)
      if ((p[i] - q).squaredNorm() < (p[best] - q).squaredNorm()) best = i;
    want.push_back(best);
  }
  for (int e : {-1020, -1000, 1000, 1020}) {
    const auto scaled = [&](const Vec2d& x) { return Vec2d(std::ldexp(x[0], e), std::ldexp(x[1], e)); };
    std::vector<Vec2d> q = p;
    for (Vec2d& x : q) x = scaled(x);
    const Delaunay2 dt(q);
    for (std::size_t i = 0; i < queries.size(); ++i) EXPECT_EQ(dt.nearest(scaled(queries[i])), want[i]) << e;
  }
}

TEST(Delaunay2, NeighborsAreTheEdges) {
  const std::vector<Vec2d> p = make_points(Shape::uniform, 500, 3);
  const Delaunay2 dt(p);
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t e = 0; e < dt.triangles().size(); ++e)
    edges.insert({dt.triangles()[e], dt.triangles()[Delaunay2::next(std::uint32_t(e))]});
  std::size_t total = 0;
  for (std::uint32_t v = 0; v < p.size(); ++v) {
    const auto nb = dt.neighbors(v);
    total += nb.size();
    for (std::uint32_t w : nb) EXPECT_TRUE(edges.count({v, w}) || edges.count({w, v}));
    for (std::size_t k = 0; k + 1 < nb.size(); ++k) EXPECT_GE(orient2d(p[v], p[nb[k]], p[nb[k + 1]]), 0) << "ccw";
  }
  // Each undirected edge counted from both ends.
  std::set<std::pair<std::uint32_t, std::uint32_t>> undirected;
  for (auto [a, b] : edges) undirected.insert({std::min(a, b), std::max(a, b)});
  EXPECT_EQ(total, 2 * undirected.size());
}

TEST(Delaunay2, InsertKeepsDelaunay) {
  for (Shape shape : {Shape::uniform, Shape::grid, Shape::circle, Shape::line}) {
    std::vector<Vec2d> all = make_points(shape, 300, 4);
    Delaunay2 dt(std::span<const Vec2d>(all.data(), all.size() / 2));
    for (std::size_t i = all.size() / 2; i < all.size(); ++i) {
      EXPECT_EQ(dt.insert(all[i]), i);
      if (i % 17 == 0) check_delaunay(dt, std::span<const Vec2d>(all.data(), i + 1));
    }
    check_delaunay(dt, all);
    // Outside the hull, on the hull, a duplicate.
    all.push_back({-10, 7});
    all.push_back(all[0]);
    for (std::size_t i = all.size() - 2; i < all.size(); ++i) dt.insert(all[i]);
    check_delaunay(dt, all);
    EXPECT_EQ(dt.representative(std::uint32_t(all.size() - 1)), dt.representative(0));
  }
}

// The Inserter gives the same arrays as insert() point by point (it walks from
// the same place when given no triangle), and after each insertion its changed()
// list is exactly the triangles with the new point as a corner (brute force over
// every handle), while every other handle keeps its triangle.
TEST(Delaunay2, InserterMatchesInsertAndReportsTheStar) {
  for (Shape shape : {Shape::uniform, Shape::grid, Shape::circle, Shape::line, Shape::duplicates}) {
    SCOPED_TRACE(int(shape));
    const std::vector<Vec2d> all = make_points(shape, 200, 9);
    const std::span<const Vec2d> first(all.data(), shape == Shape::line ? 0 : 20);
    Delaunay2 one_by_one(first), batched(first);
    for (std::size_t i = first.size(); i < all.size(); ++i) one_by_one.insert(all[i]);
    {
      Delaunay2::Inserter ins(batched);
      std::map<std::uint32_t, std::array<std::uint32_t, 3>> before;
      for (std::uint32_t h = 0; h < ins.handle_count(); ++h)
        if (ins.is_triangle(h)) before[h] = ins.triangle(h);
      for (std::size_t i = first.size(); i < all.size(); ++i) {
        ASSERT_EQ(ins.insert(all[i]), i);
        std::set<std::uint32_t> star, listed;
        for (std::uint32_t h = 0; h < ins.handle_count(); ++h) {
          if (!ins.is_triangle(h)) continue;
          const auto t = ins.triangle(h);
          if (t[0] == i || t[1] == i || t[2] == i) star.insert(h);
        }
        for (const auto& t : ins.changed()) {
          listed.insert(t.handle);
          const auto corners = ins.triangle(t.handle);
          for (int k = 0; k < 3; ++k) ASSERT_EQ(t.corners[k], ins.points()[corners[k]]);
        }
        if (before.empty()) {  // the first triangles: all of them are new
          std::set<std::uint32_t> every;
          for (std::uint32_t h = 0; h < ins.handle_count(); ++h)
            if (ins.is_triangle(h)) every.insert(h);
          ASSERT_EQ(listed, every);
        } else {  // empty for a duplicate, which is no corner
          ASSERT_EQ(listed, star) << "point " << i;
        }
        for (const auto& [h, t] : before)
          if (!listed.count(h)) {
            ASSERT_TRUE(ins.is_triangle(h) && ins.triangle(h) == t) << "handle " << h;
          }
        before.clear();
        for (std::uint32_t h = 0; h < ins.handle_count(); ++h)
          if (ins.is_triangle(h)) before[h] = ins.triangle(h);
      }
    }
    check_delaunay(batched, all);
    ASSERT_EQ(std::vector<std::uint32_t>(batched.triangles().begin(), batched.triangles().end()),
              std::vector<std::uint32_t>(one_by_one.triangles().begin(), one_by_one.triangles().end()));
    ASSERT_EQ(std::vector<std::uint32_t>(batched.hull().begin(), batched.hull().end()),
              std::vector<std::uint32_t>(one_by_one.hull().begin(), one_by_one.hull().end()));
  }
}

// Inserting at a known triangle (the handle holding the point) walks no steps
// and gives a valid triangulation; a bad handle or a NaN is a geods::Error.
TEST(Delaunay2, InserterAtKnownTriangles) {
  Rng rng(12);
  std::vector<Vec2d> p = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  Delaunay2 dt(p);
  {
    Delaunay2::Inserter ins(dt);
    ins.reserve(300);
    for (int k = 0; k < 300; ++k) {
      const Vec2d q{rng.uniform(0, 1), rng.uniform(0, 1)};
      std::uint32_t holder = kNone;
      for (std::uint32_t h = 0; h < ins.handle_count() && holder == kNone; ++h) {
        if (!ins.is_triangle(h)) continue;
        const auto t = ins.triangle(h);
        if (orient2d(p[t[0]], p[t[1]], q) >= 0 && orient2d(p[t[1]], p[t[2]], q) >= 0 && orient2d(p[t[2]], p[t[0]], q) >= 0)
          holder = h;
      }
      ASSERT_NE(holder, kNone);
      ins.prefetch(holder);  // hints: no effect on the result (and no reads outside the arrays, under asan)
      ins.prefetch_neighbors(holder);
      ins.insert(q, holder);
      p.push_back(q);
    }
    ins.prefetch(ins.handle_count());  // out of range: ignored
    ins.prefetch_neighbors(ins.handle_count());
    EXPECT_THROW(ins.insert({0.5, 0.5}, ins.handle_count()), Error);
    EXPECT_THROW(ins.insert({std::nan(""), 0.5}), Error);
    EXPECT_THROW(ins.triangle(ins.handle_count()), Error);
  }
  check_delaunay(dt, p);
}

// A constrained triangulation keeps its segments through an Inserter.
TEST(Delaunay2Constrained, InserterKeepsConstraints) {
  const std::vector<Vec2d> p = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const std::vector<Delaunay2::Segment> segments = {{0, 2}};
  Delaunay2 dt(p, segments);
  Rng rng(5);
  {
    Delaunay2::Inserter ins(dt);
    for (int i = 0; i < 100; ++i) ins.insert({rng.uniform(0, 10), rng.uniform(0, 10)});
    for (int i = 1; i < 10; ++i) ins.insert({double(i), double(i)});  // on the segment
  }
  ASSERT_NO_THROW(dt.validate());
  EXPECT_EQ(dt.constrained_edges().size(), 10u);
}

// After removals: a Delaunay triangulation of the points still present.
void check_after_removal(const Delaunay2& dt, const std::vector<char>& removed) {
  ASSERT_NO_THROW(dt.validate());
  std::vector<Vec2d> left;
  for (std::uint32_t i = 0; i < removed.size(); ++i) {
    if (removed[i]) {
      ASSERT_EQ(dt.representative(i), kNone);
    } else {
      left.push_back(dt.points()[i]);
      ASSERT_NE(dt.representative(i), kNone);
    }
  }
  const Delaunay2 fresh(left);
  ASSERT_EQ(dt.triangle_count(), fresh.triangle_count());
  ASSERT_EQ(hull_corners(dt), hull_corners(fresh));
  const auto p = dt.points();
  for (std::size_t t = 0; t < dt.triangles().size(); t += 3)
    for (const Vec2d& x : left)
      ASSERT_LE(incircle(p[dt.triangles()[t]], p[dt.triangles()[t + 1]], p[dt.triangles()[t + 2]], x), 0);
}

TEST(Delaunay2, RemoveKeepsDelaunay) {
  for (Shape shape : {Shape::uniform, Shape::grid, Shape::circle, Shape::duplicates, Shape::clustered}) {
    SCOPED_TRACE("shape " + std::to_string(int(shape)));
    const std::vector<Vec2d> p = make_points(shape, 300, 8);
    Delaunay2 dt(p);
    std::vector<char> removed(p.size(), 0);
    Rng rng(3);
    // Remove all but two points, in random order, hull vertices included.
    std::vector<std::uint32_t> order(p.size());
    for (std::uint32_t i = 0; i < p.size(); ++i) order[i] = i;
    for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
    for (std::size_t k = 0; k + 2 < order.size(); ++k) {
      dt.remove(order[k]);
      removed[order[k]] = 1;
      if (k % 13 == 0 || k + 10 > order.size()) check_after_removal(dt, removed);
    }
    EXPECT_THROW(dt.remove(order[0]), Error);
  }
}

TEST(Delaunay2, RemoveHullVerticesOnly) {
  const std::vector<Vec2d> p = make_points(Shape::uniform, 200, 12);
  Delaunay2 dt(p);
  std::vector<char> removed(p.size(), 0);
  for (int k = 0; k < 150; ++k) {
    const std::uint32_t v = dt.hull()[std::size_t(k) % dt.hull().size()];
    dt.remove(v);
    removed[v] = 1;
    check_after_removal(dt, removed);
  }
}

TEST(Delaunay2, StatsCountWhatIsThere) {
  std::vector<Vec2d> p = make_points(Shape::uniform, 1000, 2);
  p.push_back(p[3]);
  const Delaunay2 dt(p);
  const Delaunay2Stats s = dt.stats();
  EXPECT_EQ(s.points, p.size());
  EXPECT_EQ(s.vertices, p.size() - 1);
  EXPECT_EQ(s.duplicates, 1u);
  EXPECT_EQ(s.triangles, dt.triangle_count());
  EXPECT_EQ(s.hull, dt.hull().size());
  EXPECT_GT(s.flips, 0u);
  EXPECT_GT(s.bytes, p.size() * sizeof(Vec2d));
}

// ------------------------------------------------------------------ constrained

// Do segments pq and rs cross at a point interior to both?
bool properly_cross(const Vec2d& p, const Vec2d& q, const Vec2d& r, const Vec2d& s) {
  const double a = orient2d(p, q, r), b = orient2d(p, q, s), c = orient2d(r, s, p), d = orient2d(r, s, q);
  return ((a > 0 && b < 0) || (a < 0 && b > 0)) && ((c > 0 && d < 0) || (c < 0 && d > 0));
}

// The constrained Delaunay property by brute force: a vertex inside a
// triangle's circle is hidden by a constrained edge from a point inside the
// triangle (not its centroid: on grid inputs the line from the centroid to a
// vertex often passes through the end of a constrained edge, which
// properly_cross does not count). Triangles too thin for the rounded point
// to lie inside (between crossings rounded an ulp apart) are left out.
void check_constrained(const Delaunay2& dt) {
  ASSERT_NO_THROW(dt.validate());
  const auto p = dt.points();
  const auto& tri = dt.triangles();
  const std::vector<Delaunay2::Segment> fixed = dt.constrained_edges();
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t i = 0; i < p.size(); ++i)
    if (dt.representative(i) == i) vertices.push_back(i);
  for (std::size_t t = 0; t < tri.size(); t += 3) {
    const Vec2d &a = p[tri[t]], &b = p[tri[t + 1]], &c = p[tri[t + 2]];
    ASSERT_GT(orient2d(a, b, c), 0);
    const Vec2d inside = 0.3071 * a + 0.3617 * b + 0.3312 * c;
    if (!(orient2d(a, b, inside) > 0 && orient2d(b, c, inside) > 0 && orient2d(c, a, inside) > 0)) continue;
    for (std::uint32_t v : vertices) {
      if (incircle(a, b, c, p[v]) <= 0) continue;
      bool hidden = false;
      for (const auto& s : fixed) hidden = hidden || properly_cross(inside, p[v], p[s[0]], p[s[1]]);
      ASSERT_TRUE(hidden) << "vertex " << v << " visible inside the circle of triangle " << t / 3;
    }
  }
  // No constrained edge is crossed by any edge.
  for (const auto& s : fixed)
    for (std::size_t e = 0; e < tri.size(); ++e)
      ASSERT_FALSE(properly_cross(p[s[0]], p[s[1]], p[tri[e]], p[tri[Delaunay2::next(std::uint32_t(e))]]));
}

// Is the edge (a, b) in the triangulation, constrained?
bool has_constrained_edge(const Delaunay2& dt, std::uint32_t a, std::uint32_t b) {
  for (const auto& s : dt.constrained_edges())
    if ((s[0] == a && s[1] == b) || (s[0] == b && s[1] == a)) return true;
  return false;
}

TEST(Delaunay2Constrained, RandomNonCrossingSegmentsArePresent) {
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    Rng rng(seed);
    std::vector<Vec2d> p;
    for (int i = 0; i < 300; ++i) p.emplace_back(rng.uniform(), rng.uniform());
    // Long segments that do not cross each other: chords of horizontal strips.
    std::vector<Delaunay2::Segment> segments;
    for (int k = 0; k < 8; ++k) {
      const double y = (k + 0.5) / 8;
      p.emplace_back(rng.uniform(0, 0.3), y + rng.uniform(-0.04, 0.04));
      p.emplace_back(rng.uniform(0.7, 1), y + rng.uniform(-0.04, 0.04));
      segments.push_back({std::uint32_t(p.size() - 2), std::uint32_t(p.size() - 1)});
    }
    const Delaunay2 dt(p, segments);
    check_constrained(dt);
    EXPECT_TRUE(dt.intersection_points().empty());
    EXPECT_EQ(dt.points().size(), p.size());
    for (const auto& s : segments) {
      // Present as one edge or as a chain through vertices exactly on it; here none are.
      EXPECT_TRUE(has_constrained_edge(dt, s[0], s[1]));
    }
    EXPECT_EQ(dt.constrained_edges().size(), segments.size());
  }
}

TEST(Delaunay2Constrained, CrossingSegmentsAreSplit) {
  const std::vector<Vec2d> p = {{0, 0}, {4, 4}, {0, 4}, {4, 0}, {2, 7}, {-3, 1}, {6, 2}};
  const std::vector<Delaunay2::Segment> segments = {{0, 1}, {2, 3}};
  const Delaunay2 dt(p, segments);
  check_constrained(dt);
  ASSERT_EQ(dt.intersection_points().size(), 1u);
  const std::uint32_t x = dt.intersection_points()[0];
  EXPECT_EQ(x, p.size());
  EXPECT_EQ(dt.points()[x], Vec2d(2, 2));
  for (std::uint32_t v : {0u, 1u, 2u, 3u}) EXPECT_TRUE(has_constrained_edge(dt, v, x));
  EXPECT_EQ(dt.constrained_edges().size(), 4u);
}

TEST(Delaunay2Constrained, ManyRandomCrossingSegments) {
  Rng rng(5);
  std::vector<Vec2d> p;
  for (int i = 0; i < 200; ++i) p.emplace_back(rng.uniform(), rng.uniform());
  std::vector<Delaunay2::Segment> segments;
  for (int k = 0; k < 15; ++k) segments.push_back({std::uint32_t(rng.below(200)), std::uint32_t(rng.below(200))});
  segments.erase(std::remove_if(segments.begin(), segments.end(), [](const auto& s) { return s[0] == s[1]; }),
                 segments.end());
  const Delaunay2 dt(p, segments);
  check_constrained(dt);
  EXPECT_GT(dt.intersection_points().size(), 0u);
}

// Crossing points used to be computed from determinants that overflow at
// 1e300 ("internal error") and underflow at 1e-300 (a lost segment): scaled by
// a power of two, the triangulation is the same and the crossings scale exactly.
TEST(Delaunay2Constrained, CrossingsAtExtremeScales) {
  Rng rng(6);
  std::vector<Vec2d> p;
  for (int i = 0; i < 60; ++i) p.emplace_back(rng.uniform(), rng.uniform());
  std::vector<Delaunay2::Segment> segments;
  for (int k = 0; k < 6; ++k) segments.push_back({std::uint32_t(2 * k), std::uint32_t(2 * k + 30)});
  const Delaunay2 reference(p, segments);
  ASSERT_GT(reference.intersection_points().size(), 0u);
  for (int e : {-1060, -1000, 1000, 1020}) {
    std::vector<Vec2d> q = p;
    for (Vec2d& x : q) x = Vec2d(std::ldexp(x[0], e), std::ldexp(x[1], e));
    const Delaunay2 dt(q, segments);
    if (e > -1060) check_constrained(dt);  // 2^-1060: subnormal inputs; valid, checked below
    ASSERT_NO_THROW(dt.validate()) << e;
    if (e == -1060) continue;
    EXPECT_EQ(dt.triangles().to_vector(), reference.triangles().to_vector()) << e;
    for (std::uint32_t x : reference.intersection_points())
      EXPECT_EQ(dt.points()[x], Vec2d(std::ldexp(reference.points()[x][0], e), std::ldexp(reference.points()[x][1], e)));
  }
}

// Random segments between points of a 7 x 7 grid: many crossings, vertices on
// segments, crossing points rounded next to other points. A crossing point
// rounded outside the two triangles of the edge it splits (beside a sliver
// along that edge) used to leave that edge, no longer constrained, not Delaunay.
// Also scaled by 2^-1000 and 2^1000, where products of coordinates underflow
// or overflow.
TEST(Delaunay2Constrained, RandomSegmentsOnACoarseGrid) {
  for (std::uint64_t seed = 0; seed < 360; ++seed) {  // the extreme scales take the predicates' slow paths: fewer
    Rng rng(seed);
    const int exponent = seed < 300 ? 0 : seed % 2 ? -1000 : 1000;
    std::vector<Vec2d> p;
    for (int i = 0; i < 30; ++i)
      p.emplace_back(std::ldexp(double(rng.below(7)), exponent), std::ldexp(double(rng.below(7)), exponent));
    std::vector<Delaunay2::Segment> segments;
    for (int k = 0; k < 12; ++k) segments.push_back({std::uint32_t(rng.below(30)), std::uint32_t(rng.below(30))});
    std::erase_if(segments, [](const auto& s) { return s[0] == s[1]; });
    check_constrained(Delaunay2(p, segments));
  }
}

// The same 1e6 from the origin with x moved by up to 1e-10: crossing points
// rounded by far more than the noise. Besides the case above, pieces of split
// segments pass exactly through vertices that the whole segment misses by
// their rounding (validate() refused such paths), and a segment's crossed
// triangles can surround a vertex (next test).
TEST(Delaunay2Constrained, SegmentsFarFromTheOriginWithTinyNoise) {
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Rng rng(seed);
    std::vector<Vec2d> p;
    for (int i = 0; i < 30; ++i)
      p.emplace_back(1e6 + double(rng.below(7)) + rng.uniform(-1e-10, 1e-10), 1e6 + double(rng.below(7)));
    std::vector<Delaunay2::Segment> segments;
    for (int k = 0; k < 12; ++k) segments.push_back({std::uint32_t(rng.below(30)), std::uint32_t(rng.below(30))});
    std::erase_if(segments, [](const auto& s) { return s[0] == s[1]; });
    check_constrained(Delaunay2(p, segments));
  }
}

// Segment 6-5 passes point 5 of segment 7-2 by its rounding, and the triangles
// it crosses surround a vertex on one side (a crossing point of degree 3): the
// sides of the cavity are no polygons then, and retriangulating them lost the
// constrained edges to that vertex. Such segments are flipped in instead.
TEST(Delaunay2Constrained, CrossedTrianglesAroundAVertex) {
  const std::vector<Vec2d> p = {{1000003, 1000000},          {1000004.9999999999, 1000001}, {1000005.9999999999, 1000002},
                                {1000005.9999999999, 1000002}, {1000000, 1000000},            {1000003.9999999999, 1000001},
                                {1000001.9999999999, 1000003}, {1000002.0000000001, 1000000}};
  const Delaunay2 dt(p, std::vector<Delaunay2::Segment>{{4, 3}, {6, 5}, {7, 2}});
  check_constrained(dt);
}

// 1e15 from the origin, where doubles are 1/8 apart: segment 3-6 crosses 5-2 at
// (3, 1.9), rounded onto point 5 at (3, 2); the vertex of point 5 then stands for
// the crossing too.
TEST(Delaunay2Constrained, CrossingRoundedOntoAPoint) {
  std::vector<Vec2d> p = {{6, 0}, {6, 1}, {3, 0}, {6, 2.5}, {2, 3}, {3, 2}, {1, 1.5}, {5, 2}, {3, 2.5}};
  for (Vec2d& x : p) x += Vec2d(1e15, 1e15);
  const Delaunay2 dt(p, std::vector<Delaunay2::Segment>{{3, 5}, {5, 2}, {3, 6}});
  check_constrained(dt);
  ASSERT_EQ(dt.intersection_points().size(), 1u);
  EXPECT_EQ(dt.points()[dt.intersection_points()[0]], p[5]);
}

TEST(Delaunay2Constrained, SegmentThroughVerticesIsSplit) {
  std::vector<Vec2d> p = {{0, 0}, {4, 0}, {1, 0}, {3, 0}, {2, 3}, {2, -3}, {2, 0.5}, {2, -0.5}};
  const std::vector<Delaunay2::Segment> segments = {{0, 1}};
  const Delaunay2 dt(p, segments);
  check_constrained(dt);
  EXPECT_TRUE(has_constrained_edge(dt, 0, 2));
  EXPECT_TRUE(has_constrained_edge(dt, 2, 3));
  EXPECT_TRUE(has_constrained_edge(dt, 3, 1));
  EXPECT_TRUE(dt.intersection_points().empty());
}

TEST(Delaunay2Constrained, PolygonWithHoleInsideOutside) {
  // Outer square 0..10, hole 3..7 (a diamond, so it is not aligned with the grid of points).
  std::vector<Vec2d> p = {{0, 0}, {10, 0}, {10, 10}, {0, 10}, {5, 3}, {7, 5}, {5, 7}, {3, 5}};
  std::vector<Delaunay2::Segment> segments = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
  Rng rng(2);
  for (int i = 0; i < 200; ++i) p.emplace_back(rng.uniform(-2, 12), rng.uniform(-2, 12));
  const Delaunay2 dt(p, segments);
  check_constrained(dt);
  const std::vector<std::uint8_t> inside = dt.inside();
  ASSERT_EQ(inside.size(), dt.triangle_count());
  const auto in_polygon = [](const Vec2d& c) {
    const bool in_outer = c[0] > 0 && c[0] < 10 && c[1] > 0 && c[1] < 10;
    const bool in_hole = std::abs(c[0] - 5) + std::abs(c[1] - 5) < 2;
    return in_outer && !in_hole;
  };
  double area = 0;
  for (std::size_t t = 0; t < inside.size(); ++t) {
    const auto& tri = dt.triangles();
    const Vec2d &a = dt.points()[tri[3 * t]], &b = dt.points()[tri[3 * t + 1]], &c = dt.points()[tri[3 * t + 2]];
    EXPECT_EQ(bool(inside[t]), in_polygon((a + b + c) / 3));
    if (inside[t]) area += orient2d(a, b, c) / 2;
  }
  EXPECT_DOUBLE_EQ(area, 100.0 - 8.0);
}

TEST(Delaunay2Constrained, InsertKeepsConstraints) {
  std::vector<Vec2d> p = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const std::vector<Delaunay2::Segment> segments = {{0, 2}};
  Delaunay2 dt(p, segments);
  Rng rng(4);
  for (int i = 0; i < 100; ++i) dt.insert({rng.uniform(0, 10), rng.uniform(0, 10)});
  for (int i = 1; i < 10; ++i) dt.insert({double(i), double(i)});  // on the segment
  check_constrained(dt);
  EXPECT_TRUE(has_constrained_edge(dt, 0, std::uint32_t(dt.points().size() - 9)));
  EXPECT_EQ(dt.constrained_edges().size(), 10u);
  EXPECT_THROW(dt.remove(5), Error);
}

TEST(Delaunay2Constrained, RejectsBadSegments) {
  const std::vector<Vec2d> p = {{0, 0}, {1, 0}, {0, 1}};
  EXPECT_THROW(Delaunay2(p, std::vector<Delaunay2::Segment>{{0, 3}}), Error);
  EXPECT_THROW(Delaunay2(p, std::vector<Delaunay2::Segment>{{1, 1}}), Error);
  // Equal end points (duplicates) are fine: nothing to constrain.
  const std::vector<Vec2d> q = {{0, 0}, {1, 0}, {0, 1}, {1, 0}};
  const Delaunay2 dt(q, std::vector<Delaunay2::Segment>{{1, 3}, {0, 1}});
  check_constrained(dt);
}

}  // namespace
}  // namespace geods::voronoi
