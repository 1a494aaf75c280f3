// The exact sign evaluation of the segment Voronoi predicates
// (src/voronoi/segment_voronoi_exact.hpp: a double interval filter, then MPFR
// balls past the BFMSS separation bound) against an independent oracle:
// rational arithmetic (GMP mpq_class) on squared forms,
// sign(a + sqrt(b) - sqrt(c)) decided by isolating and squaring with sign
// tracking. Inputs are small integers, so that exact ties (cocircular points,
// equal circle events, a site on a circle's rightmost point) are frequent.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <cmath>

#include "../../src/voronoi/segment_voronoi_exact.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/segment_voronoi.hpp"

namespace geods::voronoi::detail::exact {
namespace {

using Q = mpq_class;

int sign(const Q& q) { return sgn(q); }
// sign(p + q sqrt(b)), b >= 0.
int sign_pq(const Q& p, const Q& q, const Q& b) {
  if (q == 0 || b == 0) return sign(p);
  const int sq = sign(q);
  if (sign(p) == sq || p == 0) return sq;
  return sign(p) * sign(p * p - q * q * b);
}
// sign(a + sqrt(b) - sqrt(c)), b, c >= 0.
int sign_abc(const Q& a, const Q& b, const Q& c) {
  const int su = sign_pq(a, 1, b);  // u = a + sqrt(b)
  if (c == 0) return su;
  if (su <= 0) return -1;
  return sign_pq(a * a + b - c, 2 * a, b);  // sign(u^2 - c) for u > 0
}

struct Pt3 {
  double x[3], y[3];
};
// Centre x and squared radius of the circle through three points, in rationals.
void circle_q(const Pt3& p, Q& cx, Q& cy, Q& r2) {
  const Q ax(p.x[0]), ay(p.y[0]);
  const Q bx = Q(p.x[1]) - ax, by = Q(p.y[1]) - ay, qx = Q(p.x[2]) - ax, qy = Q(p.y[2]) - ay;
  const Q d = 2 * (bx * qy - by * qx);
  const Q b2 = bx * bx + by * by, c2 = qx * qx + qy * qy;
  const Q ux = (qy * b2 - by * c2) / d, uy = (bx * c2 - qx * b2) / d;
  cx = ax + ux;
  cy = ay + uy;
  r2 = ux * ux + uy * uy;
}
// The same circle in a number type T (the sweep's circle_ppp form): centre x, y and x + r.
template <class T>
void circle_t(const Pt3& p, T& cx, T& cy, T& lx) {
  const double ax = p.x[0], ay = p.y[0];
  const double bx = p.x[1] - ax, by = p.y[1] - ay, qx = p.x[2] - ax, qy = p.y[2] - ay;
  const T d(2 * (bx * qy - by * qx));
  const double b2 = bx * bx + by * by, c2 = qx * qx + qy * qy;
  const T ux = (T(qy) * T(b2) - T(by) * T(c2)) / d, uy = (T(bx) * T(c2) - T(qx) * T(b2)) / d;
  cx = T(ax) + ux;
  cy = T(ay) + uy;
  lx = cx + sqrt(ux * ux + uy * uy);
}

bool collinear(const Pt3& p) { return (p.x[1] - p.x[0]) * (p.y[2] - p.y[0]) == (p.y[1] - p.y[0]) * (p.x[2] - p.x[0]); }

// Three distinct lattice points of the circle of radius 25 around (cx, cy) (12 + 8 + 8 + 4 of them).
Pt3 cocircular_triple(Rng& rng, double cx, double cy) {
  static const int off[][2] = {{25, 0}, {24, 7}, {20, 15}, {15, 20}, {7, 24}, {0, 25}, {-7, 24}, {-15, 20}, {-20, 15}, {-24, 7},
                               {-25, 0}, {-24, -7}, {-20, -15}, {-15, -20}, {-7, -24}, {0, -25}, {7, -24}, {15, -20}, {20, -15}, {24, -7}};
  Pt3 p;
  int used[3] = {-1, -1, -1};
  for (int i = 0; i < 3; ++i) {
    int j;
    do j = static_cast<int>(rng.uniform(0, 20)) % 20;
    while (j == used[0] || j == used[1]);
    used[i] = j;
    p.x[i] = cx + off[j][0];
    p.y[i] = cy + off[j][1];
  }
  return p;
}

Pt3 random_triple(Rng& rng, int size) {
  Pt3 p;
  do {
    for (int i = 0; i < 3; ++i) {
      p.x[i] = std::floor(rng.uniform(0, size));
      p.y[i] = std::floor(rng.uniform(0, size));
    }
  } while (collinear(p));
  return p;
}

TEST(SegmentVoronoiExactSign, AlgebraicIdentities) {
  auto eval = [](auto f) { return exact_sign(f); };
  // sqrt(5) + sqrt(3) - sqrt(8 + 2 sqrt(15)) = 0 (nested radicals).
  EXPECT_EQ(eval([](auto type) {
              using T = typename decltype(type)::type;
              return sqrt(T(5)) + sqrt(T(3)) - sqrt(T(8) + T(2) * sqrt(T(15)));
            }),
            0);
  // sqrt(2) sqrt(3) - sqrt(6) = 0 with three distinct radicals; sqrt(2) sqrt(8) - 4 = 0.
  EXPECT_EQ(eval([](auto type) {
              using T = typename decltype(type)::type;
              return sqrt(T(2)) * sqrt(T(3)) - sqrt(T(6));
            }),
            0);
  EXPECT_EQ(eval([](auto type) {
              using T = typename decltype(type)::type;
              return sqrt(T(2)) * sqrt(T(8)) - T(4);
            }),
            0);
  // sqrt(a^2 + 1) - a - 1 / (2a) < 0 by about 1 / (8 a^3) = 2^-152 for a = 2^50:
  // far below double precision, decided by the balls.
  EXPECT_EQ(eval([](auto type) {
              using T = typename decltype(type)::type;
              const T a(0x1p50);
              return sqrt(a * a + T(1)) - a - T(1) / (T(2) * a);
            }),
            -1);
  // (sqrt(x + 1) - sqrt(x)) (sqrt(x + 1) + sqrt(x)) - 1 = 0 for x = 2^52 - 1.
  EXPECT_EQ(eval([](auto type) {
              using T = typename decltype(type)::type;
              const T x(0x1p52 - 1);
              return (sqrt(x + T(1)) - sqrt(x)) * (sqrt(x + T(1)) + sqrt(x)) - T(1);
            }),
            0);
  // The filter alone cannot tell these; filtered_sign falls back and agrees.
  EXPECT_EQ(filtered_sign([](auto type) {
              using T = typename decltype(type)::type;
              return sqrt(T(2)) * sqrt(T(2)) - T(2);
            }),
            0);
}

TEST(SegmentVoronoiExactSign, RandomSquareRootSumsAgainstRationals) {
  // sign(p + q sqrt(b) - sqrt(c)) with p chosen to nearly cancel.
  Rng rng(41);
  int zeros = 0;
  for (int k = 0; k < 400; ++k) {
    double b = std::floor(rng.uniform(0, 1 << 20)), q = std::floor(rng.uniform(-1000, 1000));
    double c = std::floor(rng.uniform(0, 1 << 20));
    double p = std::round(std::sqrt(c) - q * std::sqrt(b)) + std::floor(rng.uniform(-1, 2));
    if (k % 4 == 0) q = std::fabs(q), c = q * q * b, p = 0;  // q sqrt(b) = sqrt(c): a tie
    if (k % 4 == 1) {  // perfect squares: p + q t - s = 0
      const double t = std::floor(rng.uniform(0, 1000)), u = std::floor(rng.uniform(0, 1000));
      b = t * t;
      c = u * u;
      p = u - q * t;
    }
    // p + q sqrt(b) - sqrt(c) with B = q^2 b: p + sqrt(B) - sqrt(c) for q >= 0;
    // p - (sqrt(B) + sqrt(c)) for q < 0, whose sign is that of p^2 - B - c - 2 sqrt(B c) when p > 0.
    const Q B = Q(q) * Q(q) * Q(b), C(c), P(p);
    int want;
    if (q >= 0)
      want = sign_abc(P, B, C);
    else if (p <= 0)
      want = (p == 0 && B == 0 && C == 0) ? 0 : -1;
    else
      want = sign_pq(P * P - B - C, -2, B * C);
    const int got = filtered_sign([&](auto type) {
      using T = typename decltype(type)::type;
      return T(p) + T(q) * sqrt(T(b)) - sqrt(T(c));
    });
    EXPECT_EQ(got, want) << p << " + " << q << " sqrt(" << b << ") - sqrt(" << c << ")";
    zeros += want == 0;
  }
  EXPECT_GE(zeros, 50);
}

TEST(SegmentVoronoiExactSign, CircleEventOrderAgainstRationals) {
  // Circle events of random point triples on a small grid (many cocircular
  // quadruples and equal x + r): the order of two events (x + r, then the
  // centre's y) and of a site x against an event, exactly.
  Rng rng(42);
  int ties = 0, site_ties = 0;
  for (int k = 0; k < 600; ++k) {
    const bool same_circle = k % 3 == 0;
    const double cx = std::floor(rng.uniform(0, 4)), cy = std::floor(rng.uniform(0, 4));
    const Pt3 a = same_circle ? cocircular_triple(rng, cx, cy) : random_triple(rng, 7);
    const Pt3 b = same_circle ? cocircular_triple(rng, cx, std::floor(rng.uniform(0, 2)) == 0 ? cy : cy + 1) : random_triple(rng, 7);
    Q ax, ay, ar2, bx, by, br2;
    circle_q(a, ax, ay, ar2);
    circle_q(b, bx, by, br2);
    const int want_x = sign_abc(ax - bx, ar2, br2);
    const int got_x = filtered_sign([&](auto type) {
      using T = typename decltype(type)::type;
      T cx, cy, la, lb;
      circle_t(a, cx, cy, la);
      circle_t(b, cx, cy, lb);
      return la - lb;
    });
    ASSERT_EQ(got_x, want_x) << "event " << k;
    ties += want_x == 0;
    const int want_y = sign(ay - by);
    const int got_y = filtered_sign([&](auto type) {
      using T = typename decltype(type)::type;
      T ca, cb, lx;
      circle_t(a, lx, ca, lx);
      circle_t(b, lx, cb, lx);
      return ca - cb;
    });
    ASSERT_EQ(got_y, want_y) << "event " << k;
    // A site x against the event's x + r: sign(x - cx - r) = -sign((cx - x) + sqrt(r2)).
    const double x = same_circle && k % 2 == 0 ? cx + 25 : std::floor(rng.uniform(0, 12));
    const int want_s = -sign_abc(ax - Q(x), ar2, 0);
    const int got_s = filtered_sign([&](auto type) {
      using T = typename decltype(type)::type;
      T cx, cy, lx;
      circle_t(a, cx, cy, lx);
      return T(x) - lx;
    });
    ASSERT_EQ(got_s, want_s) << "site " << x << " against event " << k;
    site_ties += want_s == 0;
  }
  EXPECT_GE(ties, 50);
  EXPECT_GE(site_ties, 50);
}

TEST(SegmentVoronoiExactSign, FilterDecidesRandomInputExactStageDecidesTies) {
  // Random disjoint segments with large coordinates: the filter decides (almost) everything.
  Rng rng(43);
  std::vector<double> segs;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) {
      const double x = i * 65536.0 + std::floor(rng.uniform(1, 30000)), y = j * 65536.0 + std::floor(rng.uniform(1, 30000));
      segs.insert(segs.end(), {x, y, x + std::floor(rng.uniform(1, 30000)), y + std::floor(rng.uniform(1, 30000))});
    }
  const ExactStats before = exact_stats;
  const SegmentVoronoi random_diagram({}, segs);
  const std::uint64_t random_exact = exact_stats.evaluations - before.evaluations;
  EXPECT_LE(random_exact, random_diagram.vertices().size() / 1000) << random_exact << " exact evaluations";
  // A lattice of points: every circle event ties with others, the exact stage decides them.
  std::vector<double> pts;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) pts.insert(pts.end(), {double(i), double(j)});
  const ExactStats mid = exact_stats;
  const SegmentVoronoi grid(pts, {});
  EXPECT_GT(exact_stats.evaluations - mid.evaluations, 10u);
  EXPECT_EQ(grid.vertices().size(), 2u * 25u);  // two (coincident) vertices per lattice cell
}

}  // namespace
}  // namespace geods::voronoi::detail::exact
