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
