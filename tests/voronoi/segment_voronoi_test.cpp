// Voronoi diagram of segments and points against brute force: every sampled
// point of every edge is equidistant to the edge's two sites and no site is
// nearer (soundness); from random query points, the ray away from the nearest
// site first meets the boundary of that site's cell (found by brute force over
// all sites) on an edge of the diagram with the right pair of sites
// (completeness: the cells cover the box). Random, polygonal, collinear,
// nearly parallel and integer-grid inputs; bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/segment_voronoi.hpp"

namespace geods::voronoi {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Distance to an elementary site: a point, or a segment's open interior
// (distance to its line where the foot is inside, infinite elsewhere).
double elementary_distance(const SegmentVoronoi& v, std::uint32_t site, const Vec2d& x) {
  if (!v.is_segment(site)) return (x - v.point(site)).norm();
  const auto s = v.segment(static_cast<std::uint32_t>(site - v.num_points()));
  const Vec2d a = v.point(s[0]), b = v.point(s[1]);
  const double t = (x - a).dot(b - a) / (b - a).squaredNorm();
  if (t < 0 || t > 1) return kInf;
  const Vec2d d = b - a;
  return std::abs(d[0] * (x - a)[1] - d[1] * (x - a)[0]) / d.norm();
}

double extent(const SegmentVoronoi& v) {
  AABB2d b;
  for (std::uint32_t p = 0; p < v.num_points(); ++p) b.extend(v.point(p));
  return std::max(1.0, (b.hi - b.lo).maxCoeff());
}

AABB2d sites_box(const SegmentVoronoi& v, double margin) {
  AABB2d b;
  for (std::uint32_t p = 0; p < v.num_points(); ++p) b.extend(v.point(p));
  const Vec2d m = Vec2d::Constant(margin * std::max(1.0, (b.hi - b.lo).maxCoeff()));
  return AABB2d(b.lo - m, b.hi + m);
}

// Soundness: samples of every edge are equidistant to its sites, and no site is nearer.
void expect_edges_sound(const SegmentVoronoi& v, int samples_per_edge = 24) {
  v.validate();
  const double tol = 1e-9 * extent(v);
  const AABB2d box = sites_box(v, 0.5);
  for (std::uint32_t e = 0; e < v.edges().size(); ++e) {
    const auto& ed = v.edges()[e];
    const auto c = v.edge_curve(e);
    ASSERT_LE(c.t0, c.t1 + tol) << "edge " << e;
    const auto pts = v.sample_edge(e, std::max(1e-9, extent(v) / samples_per_edge), box);
    for (const Vec2d& x : pts) {
      const double d0 = v.site_distance(ed.site[0], x), d1 = v.site_distance(ed.site[1], x);
      ASSERT_NEAR(d0, d1, tol * (1 + d0 / extent(v))) << "edge " << e << " at " << x.transpose();
      for (std::uint32_t s = 0; s < v.num_sites(); ++s)
        ASSERT_GE(v.site_distance(s, x), d0 - tol * (1 + d0 / extent(v)))
            << "edge " << e << " (sites " << ed.site[0] << ", " << ed.site[1] << ") at " << x.transpose()
            << ": site " << s << " is nearer";
    }
  }
}

// Completeness: the ray from q away from its nearest site meets the cell
// boundary at a point of an edge between that site and the first site that
// becomes as near.
void expect_cells_complete(const SegmentVoronoi& v, std::uint64_t seed, int queries = 300, int min_checked = 75) {
  Rng rng(seed);
  AABB2d box;
  for (std::uint32_t p = 0; p < v.num_points(); ++p) box.extend(v.point(p));
  const Vec2d margin = 0.1 * (box.hi - box.lo) + Vec2d::Constant(1e-3 * extent(v));
  box = AABB2d(box.lo - margin, box.hi + margin);
  const double scale = extent(v);
  int checked = 0;
  for (int k = 0; k < queries; ++k) {
    const Vec2d q(rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1]));
    std::uint32_t s = 0;
    double d0 = kInf;
    for (std::uint32_t i = 0; i < v.num_sites(); ++i) {
      const double d = elementary_distance(v, i, q);
      if (d < d0) d0 = d, s = i;
    }
    if (!(d0 > 1e-6 * scale)) continue;
    // Closest point on s and the direction away from it.
    Vec2d c;
    if (!v.is_segment(s)) {
      c = v.point(s);
    } else {
      const auto sg = v.segment(static_cast<std::uint32_t>(s - v.num_points()));
      const Vec2d a = v.point(sg[0]), b = v.point(sg[1]);
      c = a + ((q - a).dot(b - a) / (b - a).squaredNorm()) * (b - a);
    }
    const Vec2d u = (q - c) / d0;
    // First lambda > 0 where another site is as near as s: dist(q + l u, t) = d0 + l.
    double best = kInf;
    std::uint32_t first = s;
    for (std::uint32_t t = 0; t < v.num_sites(); ++t) {
      if (t == s) continue;
      double l = kInf;
      if (!v.is_segment(t)) {
        const Vec2d w = q - v.point(t);
        const double den = 2 * (d0 - u.dot(w));
        if (den > 0) l = (w.squaredNorm() - d0 * d0) / den;
      } else {
        const auto sg = v.segment(static_cast<std::uint32_t>(t - v.num_points()));
        const Vec2d a = v.point(sg[0]), b = v.point(sg[1]);
        const Vec2d n = Vec2d(b[1] - a[1], a[0] - b[0]).normalized();
        const double h = n.dot(q - a), hu = n.dot(u);
        for (double sign : {1.0, -1.0}) {  // sign * (h + l hu) = d0 + l
          const double den = sign * hu - 1;
          if (den == 0) continue;
          const double cand = (d0 - sign * h) / den;
          if (cand > 0 && std::isfinite(elementary_distance(v, t, q + cand * u)) && cand < l) l = cand;
        }
      }
      if (l > 0 && l < best) best = l, first = t;
    }
    if (!std::isfinite(best) || first == s) continue;
    const Vec2d r = q + best * u;
    if (!box.contains(r)) continue;
    // An edge of (s, first) through r.
    bool found = false;
    for (std::uint32_t e = 0; e < v.edges().size() && !found; ++e) {
      const auto& ed = v.edges()[e];
      if (!((ed.site[0] == s && ed.site[1] == first) || (ed.site[0] == first && ed.site[1] == s))) continue;
      const auto cv = v.edge_curve(e);
      const double t = (r - cv.origin).dot(cv.direction);
      const double tol = 1e-7 * scale;
      found = t >= cv.t0 - tol && t <= cv.t1 + tol && (cv.point(t) - r).norm() <= 1e-6 * scale;
    }
    if (!found) {
      // A vertex at r (several sites tie there) also counts.
      for (const auto& vx : v.vertices()) found = found || (vx.position - r).norm() <= 1e-6 * scale;
    }
    EXPECT_TRUE(found) << "query " << q.transpose() << ": nearest site " << s << ", boundary at " << r.transpose()
                       << " with site " << first << " is on no edge";
    ++checked;
  }
  EXPECT_GE(checked, min_checked);
}

bool segments_touch(const std::array<double, 4>& a, const std::array<double, 4>& b, double gap) {
  // Conservative: distance between the closed segments below gap.
  auto dist = [](const Vec2d& x, const Vec2d& p, const Vec2d& q) {
    const Vec2d d = q - p;
    const double t = std::clamp((x - p).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (x - (p + t * d)).norm();
  };
  const Vec2d a0(a[0], a[1]), a1(a[2], a[3]), b0(b[0], b[1]), b1(b[2], b[3]);
  auto orient = [](const Vec2d& p, const Vec2d& q, const Vec2d& r) {
    return (q - p)[0] * (r - p)[1] - (q - p)[1] * (r - p)[0];
  };
  if (orient(a0, a1, b0) * orient(a0, a1, b1) < 0 && orient(b0, b1, a0) * orient(b0, b1, a1) < 0) return true;
  return std::min({dist(a0, b0, b1), dist(a1, b0, b1), dist(b0, a0, a1), dist(b1, a0, a1)}) < gap;
}

// n random disjoint segments with integer endpoints in [0, size)^2.
std::vector<double> random_segments(std::uint64_t seed, int n, int size, int max_len) {
  Rng rng(seed);
  std::vector<std::array<double, 4>> segs;
  for (int tries = 0; static_cast<int>(segs.size()) < n && tries < 100 * n; ++tries) {
    const double x = std::floor(rng.uniform(0, size)), y = std::floor(rng.uniform(0, size));
    const double dx = std::floor(rng.uniform(-max_len, max_len)), dy = std::floor(rng.uniform(-max_len, max_len));
    if (dx == 0 && dy == 0) continue;
    const std::array<double, 4> s{x, y, x + dx, y + dy};
    bool ok = true;
    for (const auto& t : segs) ok = ok && !segments_touch(s, t, 1.0);
    if (ok) segs.push_back(s);
  }
  std::vector<double> flat;
  for (const auto& s : segs) flat.insert(flat.end(), s.begin(), s.end());
  return flat;
}

std::vector<double> polygon_segments(const std::vector<Vec2d>& ring) {
  std::vector<double> out;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2d a = ring[i], b = ring[(i + 1) % ring.size()];
    out.insert(out.end(), {a[0], a[1], b[0], b[1]});
  }
  return out;
}

TEST(SegmentVoronoi, TwoPoints) {
  const std::vector<double> pts{0, 0, 4, 0};
  SegmentVoronoi v(pts, {});
  ASSERT_EQ(v.edges().size(), 1u);
  EXPECT_EQ(v.vertices().size(), 0u);
  expect_edges_sound(v);
}

TEST(SegmentVoronoi, PointsOnly) {
  Rng rng(3);
  std::vector<double> pts;
  for (int i = 0; i < 60; ++i) pts.insert(pts.end(), {std::floor(rng.uniform(0, 1000)), std::floor(rng.uniform(0, 1000))});
  SegmentVoronoi v(pts, {});
  EXPECT_EQ(v.stats().parabolic_edges, 0u);
  expect_edges_sound(v);
  expect_cells_complete(v, 4);
}

TEST(SegmentVoronoi, OneSegment) {
  const std::vector<double> segs{0, 0, 10, 3};
  SegmentVoronoi v({}, segs);
  EXPECT_EQ(v.num_points(), 2u);
  EXPECT_EQ(v.num_segments(), 1u);
  expect_edges_sound(v);
  expect_cells_complete(v, 5, 300, 0);  // no query ray leaves the cell of its nearest site
}

TEST(SegmentVoronoi, PointAndSegmentParabola) {
  const std::vector<double> segs{0, 0, 10, 0};
  const std::vector<double> pts{5, 4};
  SegmentVoronoi v(pts, segs);
  EXPECT_GE(v.stats().parabolic_edges, 1u);
  expect_edges_sound(v);
  expect_cells_complete(v, 6);
}

TEST(SegmentVoronoi, RandomSegments) {
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    const auto segs = random_segments(seed, 40, 200, 40);
    SegmentVoronoi v({}, segs);
    EXPECT_EQ(v.split_count(), 0u);
    expect_edges_sound(v);
    expect_cells_complete(v, seed + 10);
  }
}

TEST(SegmentVoronoi, RandomSegmentsAndPoints) {
  Rng rng(9);
  const auto segs = random_segments(7, 30, 300, 50);
  std::vector<double> pts;
  for (int i = 0; i < 30; ++i) pts.insert(pts.end(), {std::floor(rng.uniform(0, 300)) + 0.5, std::floor(rng.uniform(0, 300)) + 0.5});
  SegmentVoronoi v(pts, segs);
  expect_edges_sound(v);
  expect_cells_complete(v, 11);
}

TEST(SegmentVoronoi, PolygonSharedEndpoints) {
  // A star-shaped polygon with reflex and convex corners.
  std::vector<Vec2d> ring;
  Rng rng(5);
  for (int i = 0; i < 24; ++i) {
    const double a = 2 * M_PI * i / 24, r = std::floor(rng.uniform(40, 100));
    ring.emplace_back(std::round(r * std::cos(a)), std::round(r * std::sin(a)));
  }
  SegmentVoronoi v({}, polygon_segments(ring));
  EXPECT_EQ(v.num_segments(), 24u);
  EXPECT_EQ(v.num_points(), 24u);
  expect_edges_sound(v);
  expect_cells_complete(v, 12);
  // Medial axis: primary edges inside, every vertex of it equidistant (checked), none outside.
  const auto axis = v.medial_axis();
  EXPECT_GT(axis.size(), 10u);
  for (std::uint32_t e : axis) {
    const auto c = v.edge_curve(e);
    EXPECT_TRUE(v.inside(c.point(0.5 * (c.t0 + c.t1))));
    EXPECT_TRUE(v.edges()[e].primary);
  }
}

TEST(SegmentVoronoi, CollinearChain) {
  std::vector<double> segs;
  for (int i = 0; i < 8; ++i) segs.insert(segs.end(), {double(10 * i), 0, double(10 * i + 10), 0});
  for (int i = 0; i < 4; ++i) segs.insert(segs.end(), {0, double(30 + 10 * i), 0, double(40 + 10 * i)});
  const std::vector<double> pts{45, 17, 100, 0, 20, 20};
  SegmentVoronoi v(pts, segs);
  expect_edges_sound(v);
  expect_cells_complete(v, 13);
}

TEST(SegmentVoronoi, NearlyParallel) {
  std::vector<double> segs;
  for (int i = 0; i < 10; ++i) segs.insert(segs.end(), {0, double(7 * i), 100000, double(7 * i + 1 + i % 3)});
  SegmentVoronoi v({}, segs);
  expect_edges_sound(v);
  expect_cells_complete(v, 14, 300, 40);
}

TEST(SegmentVoronoi, IntegerGrid) {
  // Unit squares: segments on a lattice, four meeting at each inner node, many cocircular sites.
  std::vector<double> segs;
  const int n = 4;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j < n; ++j) {
      segs.insert(segs.end(), {double(j), double(i), double(j + 1), double(i)});
      segs.insert(segs.end(), {double(i), double(j), double(i), double(j + 1)});
    }
  SegmentVoronoi v({}, segs);
  EXPECT_EQ(v.num_segments(), 40u);
  expect_edges_sound(v);
  expect_cells_complete(v, 15);
}

// The same lattice 1e15 from the origin, where doubles are 1/8 apart: its vertices
// (at half units) round by up to 1/16, which validate() allows them.
TEST(SegmentVoronoi, IntegerGridFarFromTheOrigin) {
  std::vector<double> segs;
  for (int i = 0; i <= 3; ++i)
    for (int j = 0; j < 3; ++j) {
      segs.insert(segs.end(), {1e15 + j, 1e15 + i, 1e15 + j + 1, 1e15 + i});
      segs.insert(segs.end(), {1e15 + i, 1e15 + j, 1e15 + i, 1e15 + j + 1});
    }
  const std::vector<double> pts{1e15 + 0.5, 1e15 + 0.25, 1e15 + 2.5, 1e15 + 1.625};
  SegmentVoronoi v(pts, segs);
  v.validate();
  EXPECT_EQ(v.num_segments(), 24u);
}

TEST(SegmentVoronoi, CrossingSegmentsAreSplit) {
  const std::vector<double> segs{0, 0, 10, 10, 0, 10, 10, 0, 20, 0, 30, 0, 25, 0, 25, 8};
  SegmentVoronoi v({}, segs);
  EXPECT_EQ(v.split_count(), 3u);        // the X cuts both its segments at (5,5), the T its bar at (25,0)
  EXPECT_EQ(v.num_segments(), 4u + 3u);  // 4 arms of the X, the T's bar in two and its stem
  expect_edges_sound(v);
}

TEST(SegmentVoronoi, FloatInputIsSnapped) {
  // Non-integer input: the diagram is that of the snapped sites, which are within the grid step of the input.
  Rng rng(21);
  std::vector<double> segs = random_segments(21, 25, 100, 20);
  for (double& x : segs) x = x * 0.013 + 1e-4 * rng.uniform(0, 1);
  SegmentVoronoi v({}, segs);
  for (std::uint32_t s = 0; s < v.num_segments(); ++s) {
    const auto src = v.segment_source(s);
    const Vec2d a = v.point(v.segment(s)[0]);
    EXPECT_LT(std::min((a - Vec2d(segs[4 * src], segs[4 * src + 1])).norm(), (a - Vec2d(segs[4 * src + 2], segs[4 * src + 3])).norm()),
              1e-6);
  }
  expect_edges_sound(v);
  expect_cells_complete(v, 22);
}

TEST(SegmentVoronoi, BadInput) {
  const double nan = std::nan("");
  EXPECT_THROW(SegmentVoronoi({}, std::vector<double>{0, 0, nan, 1}), Error);
  EXPECT_THROW(SegmentVoronoi({}, {}), Error);
  EXPECT_THROW(SegmentVoronoi({}, std::vector<double>{0, 0, 1}), Error);
  // Overlapping collinear segments.
  EXPECT_THROW(SegmentVoronoi({}, std::vector<double>{0, 0, 10, 0, 5, 0, 15, 0}), Error);
  // Rules: a zero-length segment is a point site; a point on a segment splits it; duplicates are kept once.
  SegmentVoronoi z({}, std::vector<double>{3, 3, 3, 3, 0, 0, 1, 0, 0, 0, 1, 0});
  EXPECT_EQ(z.num_segments(), 1u);
  EXPECT_EQ(z.num_points(), 3u);
  SegmentVoronoi p(std::vector<double>{5, 0}, std::vector<double>{0, 0, 10, 0});
  EXPECT_EQ(p.num_segments(), 2u);
  expect_edges_sound(p);
}

}  // namespace
}  // namespace geods::voronoi

// ---------------------------------------------------------------- degenerate inputs (exact predicates)
namespace geods::voronoi {
namespace {

// Every vertex is equidistant (its clearance) to the sites of its edges, no
// site is nearer (empty circle), and Euler's relation holds for the diagram
// closed by one vertex at infinity: V + 1 - E + (number of sites) = 2.
void expect_vertices_and_euler(const SegmentVoronoi& v) {
  const double tol = 1e-9 * extent(v);
  for (std::size_t i = 0; i < v.vertices().size(); ++i) {
    const auto& vx = v.vertices()[i];
    for (std::uint32_t s = 0; s < v.num_sites(); ++s)
      ASSERT_GE(v.site_distance(s, vx.position), vx.clearance - tol) << "vertex " << i << ": site " << s << " is inside its circle";
  }
  for (const auto& e : v.edges())
    for (int k = 0; k < 2; ++k) {
      if (e.vertex[k] == SegmentVoronoi::kInfinity) continue;
      const auto& vx = v.vertices()[e.vertex[k]];
      for (int j = 0; j < 2; ++j) ASSERT_NEAR(v.site_distance(e.site[j], vx.position), vx.clearance, tol);
    }
  EXPECT_EQ(static_cast<long>(v.vertices().size()) + 1 - static_cast<long>(v.edges().size()) + static_cast<long>(v.num_sites()), 2);
}

// Distinct vertex positions (coincident vertices of cocircular sites merged).
std::size_t distinct_vertices(const SegmentVoronoi& v, double tol) {
  std::vector<Vec2d> out;
  for (const auto& vx : v.vertices()) {
    bool seen = false;
    for (const Vec2d& p : out) seen = seen || (p - vx.position).norm() <= tol;
    if (!seen) out.push_back(vx.position);
  }
  return out.size();
}

TEST(SegmentVoronoiExact, CocircularLatticePoints) {
  // The 36 integer points on x^2 + y^2 = 65^2 (65 = 5 * 13): every triple has the same circle.
  std::vector<double> pts;
  for (int x = -65; x <= 65; ++x)
    for (int y = -65; y <= 65; ++y)
      if (x * x + y * y == 65 * 65) pts.insert(pts.end(), {double(x), double(y)});
  ASSERT_EQ(pts.size(), 72u);
  SegmentVoronoi v(pts, {});
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  // All vertices at the centre; n points on a circle give n - 2 (coincident) vertices, n rays.
  for (const auto& vx : v.vertices()) EXPECT_LE(vx.position.norm(), 1e-9 * 65);
  EXPECT_EQ(v.vertices().size(), 34u);
  std::size_t unbounded = 0;
  for (const auto& e : v.edges()) unbounded += e.vertex[0] == SegmentVoronoi::kInfinity || e.vertex[1] == SegmentVoronoi::kInfinity;
  EXPECT_EQ(unbounded, 36u);
}

TEST(SegmentVoronoiExact, CocircularAtLargeCoordinates) {
  // The 68 lattice points of x^2 + y^2 = 5^16 (radius 390625) around (16000000, -16000000):
  // every circle event ties at coordinates near 2^24, decided exactly.
  const std::int64_t R = 390625;
  std::vector<double> pts;
  for (std::int64_t x = -R; x <= R; ++x) {
    const std::int64_t y2 = R * R - x * x;
    const auto y = static_cast<std::int64_t>(std::llround(std::sqrt(static_cast<double>(y2))));
    if (y * y != y2) continue;
    pts.insert(pts.end(), {16000000.0 + x, -16000000.0 + y});
    if (y != 0) pts.insert(pts.end(), {16000000.0 + x, -16000000.0 - y});
  }
  ASSERT_EQ(pts.size(), 2u * 68u);
  SegmentVoronoi v(pts, {});
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  EXPECT_EQ(v.vertices().size(), 66u);
  for (const auto& vx : v.vertices()) {
    EXPECT_NEAR(vx.position[0], 16000000.0, 1e-9 * R);
    EXPECT_NEAR(vx.position[1], -16000000.0, 1e-9 * R);
    EXPECT_NEAR(vx.clearance, double(R), 1e-9 * R);
  }
}

TEST(SegmentVoronoiExact, PointGrid) {
  // A 9 x 7 lattice: square cells, the 8 x 6 cell corners each shared by 4 cocircular points,
  // many circle events with identical x.
  std::vector<double> pts;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 7; ++j) pts.insert(pts.end(), {double(3 * i), double(3 * j)});
  SegmentVoronoi v(pts, {});
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  expect_cells_complete(v, 21);
  EXPECT_EQ(distinct_vertices(v, 1e-9), 48u);
  for (const auto& vx : v.vertices()) {
    EXPECT_DOUBLE_EQ(std::fmod(vx.position[0], 3.0), 1.5);
    EXPECT_DOUBLE_EQ(std::fmod(vx.position[1], 3.0), 1.5);
  }
}

TEST(SegmentVoronoiExact, SegmentsTangentToOneCircle) {
  // 12 segments tangent to the circle of radius 100 at its Pythagorean points
  // (20 (3, 4) and the like): the centre is equidistant to all of them.
  std::vector<double> segs;
  const int pyth[12][2] = {{5, 0}, {4, 3}, {3, 4}, {0, 5}, {-3, 4}, {-4, 3}, {-5, 0}, {-4, -3}, {-3, -4}, {0, -5}, {3, -4}, {4, -3}};
  for (const auto& p : pyth) {
    const double a = p[0], b = p[1];
    segs.insert(segs.end(), {20 * a - b, 20 * b + a, 20 * a + b, 20 * b - a});
  }
  SegmentVoronoi v({}, segs);
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  expect_cells_complete(v, 22);
  std::size_t at_centre = 0;
  for (const auto& vx : v.vertices())
    if (vx.position.norm() <= 1e-9 * 100) {
      ++at_centre;
      EXPECT_NEAR(vx.clearance, 100, 1e-9 * 100);
    }
  EXPECT_GE(at_centre, 1u);
}

TEST(SegmentVoronoiExact, SquareWithSplitDiagonals) {
  // A square, its two diagonals split at the centre (8 segments meeting at
  // endpoints): the medial axis is the diagonals themselves, every vertex is
  // an endpoint or lies on a symmetry axis.
  const std::vector<double> segs{0, 0, 40, 0, 40, 0, 40, 40, 40, 40, 0, 40, 0, 40, 0, 0,
                                 0, 0, 20, 20, 40, 0, 20, 20, 40, 40, 20, 20, 0, 40, 20, 20};
  SegmentVoronoi v({}, segs);
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  expect_cells_complete(v, 23);
  // Inside each of the four triangles, the incentre is a vertex equidistant to
  // its three sides: r = 20 / (1 + sqrt(2)).
  const double r = 20 / (1 + std::sqrt(2.0));
  for (const Vec2d& c : {Vec2d(20, r), Vec2d(20, 40 - r), Vec2d(r, 20), Vec2d(40 - r, 20)}) {
    bool found = false;
    for (const auto& vx : v.vertices()) found = found || ((vx.position - c).norm() <= 1e-9 * 40 && std::abs(vx.clearance - r) <= 1e-9 * 40);
    EXPECT_TRUE(found) << "incentre " << c.transpose();
  }
}

TEST(SegmentVoronoiExact, ParallelSegmentsAtEqualDistances) {
  // Horizontal segments of equal length 10 apart, and a second column shifted:
  // the bisectors are the lines y = 5 + 10 k, with ties between every pair of neighbours.
  std::vector<double> segs;
  for (int k = 0; k < 6; ++k) {
    segs.insert(segs.end(), {0, double(10 * k), 30, double(10 * k)});
    segs.insert(segs.end(), {40, double(10 * k), 70, double(10 * k)});
  }
  SegmentVoronoi v({}, segs);
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  expect_cells_complete(v, 24);
  for (const auto& vx : v.vertices()) {
    // Between the columns, the vertices are where the bisectors meet: x = 35 by symmetry, or on y = 5 + 10 k.
    const bool on_axis = std::abs(vx.position[0] - 35) <= 1e-9 * 70;
    const bool on_bisector = std::abs(std::fmod(vx.position[1] + 1000, 10.0) - 5) <= 1e-9 * 70;
    EXPECT_TRUE(on_axis || on_bisector) << vx.position.transpose();
  }
}

TEST(SegmentVoronoiExact, SegmentLatticeAndDiagonalGrid) {
  // A 6 x 6 lattice of unit squares and a lattice of disjoint diagonal
  // segments (all the same length, many cocircular and cotangent triples).
  std::vector<double> segs;
  const int n = 6;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j < n; ++j) {
      segs.insert(segs.end(), {double(2 * j), double(2 * i), double(2 * j + 2), double(2 * i)});
      segs.insert(segs.end(), {double(2 * i), double(2 * j), double(2 * i), double(2 * j + 2)});
    }
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) segs.insert(segs.end(), {double(20 + 4 * i), double(4 * j), double(21 + 4 * i), double(4 * j + 1)});
  SegmentVoronoi v({}, segs);
  expect_edges_sound(v);
  expect_vertices_and_euler(v);
  expect_cells_complete(v, 25);
}

}  // namespace
}  // namespace geods::voronoi
