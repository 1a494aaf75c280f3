// The exact predicates against an independent oracle: GMP integer arithmetic
// on the coordinates scaled by a common power of two, with the determinants
// expanded by cofactors. Thousands of nearly and exactly degenerate inputs
// per predicate, at every scale a double can take.
#include "geods/core/predicates.hpp"

#include <gmp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "geods/core/rng.hpp"

namespace geods {
namespace {

// ---------------------------------------------------------------------------
// Oracle.

class Integer {
 public:
  Integer() { mpz_init(v_); }
  Integer(const Integer& o) { mpz_init_set(v_, o.v_); }
  Integer& operator=(const Integer& o) {
    mpz_set(v_, o.v_);
    return *this;
  }
  ~Integer() { mpz_clear(v_); }

  /// m * 2^shift, shift >= 0.
  static Integer shifted(std::int64_t m, long shift) {
    Integer r;
    mpz_set_si(r.v_, long(m));
    mpz_mul_2exp(r.v_, r.v_, (unsigned long)shift);
    return r;
  }

  friend Integer operator+(const Integer& a, const Integer& b) {
    Integer r;
    mpz_add(r.v_, a.v_, b.v_);
    return r;
  }
  friend Integer operator-(const Integer& a, const Integer& b) {
    Integer r;
    mpz_sub(r.v_, a.v_, b.v_);
    return r;
  }
  friend Integer operator*(const Integer& a, const Integer& b) {
    Integer r;
    mpz_mul(r.v_, a.v_, b.v_);
    return r;
  }
  int sign() const { return mpz_sgn(v_); }

 private:
  mpz_t v_;
};

using Point = std::array<double, 3>;
using Matrix = std::vector<std::vector<Integer>>;

// Every coordinate as an integer: x = m * 2^k with m odd; all are scaled by
// 2^-q for the smallest k (a positive factor, so signs are unchanged).
std::vector<std::vector<Integer>> to_integers(const Point* points, int count, int dim) {
  std::vector<std::vector<std::int64_t>> mantissa(count, std::vector<std::int64_t>(dim, 0));
  std::vector<std::vector<long>> exponent(count, std::vector<long>(dim, 0));
  long q = LONG_MAX;
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < dim; ++k) {
      const double x = points[i][k];
      if (x == 0.0) continue;
      int e = 0;
      const double m = std::frexp(x, &e);  // x = m 2^e, 0.5 <= |m| < 1
      std::int64_t mi = std::int64_t(std::ldexp(m, 53));
      long ei = long(e) - 53;
      while (mi % 2 == 0) {
        mi /= 2;
        ++ei;
      }
      mantissa[i][k] = mi;
      exponent[i][k] = ei;
      q = std::min(q, ei);
    }
  std::vector<std::vector<Integer>> result(count, std::vector<Integer>(dim));
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < dim; ++k)
      if (mantissa[i][k] != 0) result[i][k] = Integer::shifted(mantissa[i][k], exponent[i][k] - q);
  return result;
}

int determinant_sign(const Matrix& m) {
  std::function<Integer(const std::vector<int>&, int)> det = [&](const std::vector<int>& columns, int row) {
    if (columns.size() == 1) return m[row][columns[0]];
    Integer sum;
    for (std::size_t j = 0; j < columns.size(); ++j) {
      std::vector<int> rest = columns;
      rest.erase(rest.begin() + long(j));
      const Integer term = m[row][columns[j]] * det(rest, row + 1);
      sum = j % 2 == 0 ? sum + term : sum - term;
    }
    return sum;
  };
  std::vector<int> columns(m.size());
  for (std::size_t j = 0; j < m.size(); ++j) columns[j] = int(j);
  return det(columns, 0).sign();
}

// The rows p_i - p_last (i < last), lifted by |p_i - p_last|^2 if asked.
int oracle(const Point* points, int count, int dim, bool lifted) {
  const auto v = to_integers(points, count, dim);
  Matrix m;
  for (int i = 0; i + 1 < count; ++i) {
    std::vector<Integer> row;
    Integer lift;
    for (int k = 0; k < dim; ++k) {
      const Integer d = v[i][k] - v[count - 1][k];
      row.push_back(d);
      lift = lift + d * d;
    }
    if (lifted) row.push_back(lift);
    m.push_back(row);
  }
  return determinant_sign(m);
}

// ---------------------------------------------------------------------------
// The predicates under test, seen uniformly.

struct Predicate {
  const char* name;
  int count;  // points per call
  int dim;
  bool lifted;
  double (*exact)(const Point* p);
  double (*fast)(const Point* p);
};

const Predicate kOrient2d{"orient2d", 3, 2, false,
                          [](const Point* p) { return orient2d(p[0].data(), p[1].data(), p[2].data()); },
                          [](const Point* p) { return orient2d_fast(p[0].data(), p[1].data(), p[2].data()); }};
const Predicate kOrient3d{
    "orient3d", 4, 3, false,
    [](const Point* p) { return orient3d(p[0].data(), p[1].data(), p[2].data(), p[3].data()); },
    [](const Point* p) { return orient3d_fast(p[0].data(), p[1].data(), p[2].data(), p[3].data()); }};
const Predicate kIncircle{
    "incircle", 4, 2, true,
    [](const Point* p) { return incircle(p[0].data(), p[1].data(), p[2].data(), p[3].data()); },
    [](const Point* p) { return incircle_fast(p[0].data(), p[1].data(), p[2].data(), p[3].data()); }};
const Predicate kInsphere{
    "insphere", 5, 3, true,
    [](const Point* p) { return insphere(p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data()); },
    [](const Point* p) { return insphere_fast(p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data()); }};

// The points of one predicate call (up to 5).
using PredicateArgs = std::array<Point, 5>;

int sign(double x) { return (x > 0) - (x < 0); }

std::string describe(const PredicateArgs& p, int count) {
  std::ostringstream s;
  s << std::hexfloat;
  for (int i = 0; i < count; ++i) s << " (" << p[i][0] << ", " << p[i][1] << ", " << p[i][2] << ")";
  return s.str();
}

// Runs `cases` inputs from `generate` through the predicate and the oracle:
// the signs must agree, an exactly degenerate input must give exactly 0, and
// swapping two points must flip the sign.
void expect_exact_signs(const Predicate& pred, std::uint64_t seed, int cases,
                        const std::function<PredicateArgs(Rng&)>& generate, const char* what) {
  Rng rng(seed);
  int failures = 0, zeros = 0;
  for (int n = 0; n < cases; ++n) {
    PredicateArgs p = generate(rng);
    const int want = oracle(p.data(), pred.count, pred.dim, pred.lifted);
    const double got = pred.exact(p.data());
    zeros += want == 0;
    bool ok = std::isfinite(got) && sign(got) == want && (want != 0 || got == 0.0);
    const int i = int(rng.below(std::uint64_t(pred.count)));
    const int j = (i + 1 + int(rng.below(std::uint64_t(pred.count - 1)))) % pred.count;
    PredicateArgs swapped = p;
    std::swap(swapped[i], swapped[j]);
    const double got_swapped = pred.exact(swapped.data());
    ok = ok && sign(got_swapped) == -want;
    if (!ok && ++failures <= 5)
      ADD_FAILURE() << pred.name << " " << what << " case " << n << ": got " << got << ", swapped "
                    << got_swapped << ", exact sign " << want << " for" << describe(p, pred.count);
  }
  EXPECT_EQ(failures, 0) << pred.name << " " << what << ": " << failures << " of " << cases << " wrong";
  ::testing::Test::RecordProperty(std::string(pred.name) + "_" + what + "_zeros", zeros);
}

// ---------------------------------------------------------------------------
// Input generators.

/// Moves x by up to `ulps` representable doubles either way.
double nudge(double x, Rng& rng, int ulps) {
  const int steps = int(rng.below(std::uint64_t(2 * ulps + 1))) - ulps;
  for (int s = 0; s < std::abs(steps); ++s)
    x = std::nextafter(x, steps > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity());
  return x;
}

double log_uniform(Rng& rng, double lo_exp10, double hi_exp10) { return std::pow(10.0, rng.uniform(lo_exp10, hi_exp10)); }
double random_sign(Rng& rng) { return rng.below(2) ? 1.0 : -1.0; }

// How the unit-scale construction is placed: x_k = offset_k + scale_k * u_k,
// rounded; the rounding (and a nudge) moves the points a few ulps off the
// degenerate position.
struct Frame {
  Point offset{0, 0, 0};
  Point scale{1, 1, 1};
  Point apply(const Point& u) const {
    return {offset[0] + scale[0] * u[0], offset[1] + scale[1] * u[1], offset[2] + scale[2] * u[2]};
  }
};

enum class Scale { Unit, Offset, Huge, Tiny, Subnormal, Mixed };
constexpr std::array<Scale, 6> kScales{Scale::Unit, Scale::Offset, Scale::Huge, Scale::Tiny, Scale::Subnormal, Scale::Mixed};
const char* scale_name(Scale s) {
  switch (s) {
    case Scale::Unit: return "unit";
    case Scale::Offset: return "offset";
    case Scale::Huge: return "huge";
    case Scale::Tiny: return "tiny";
    case Scale::Subnormal: return "subnormal";
    case Scale::Mixed: return "mixed";
  }
  return "";
}

// Frames for affinely invariant degeneracies (collinear, coplanar): Mixed
// scales each axis differently; `isotropic` keeps one scale for circles and
// spheres, whose Mixed case is built separately.
Frame random_frame(Scale scale, Rng& rng, bool isotropic) {
  Frame f;
  double s = 1.0;
  switch (scale) {
    case Scale::Unit: break;
    case Scale::Offset: break;  // see offset_grid
    case Scale::Huge:
      s = log_uniform(rng, 150, 300);
      if (rng.below(2))
        for (double& o : f.offset) o = s * rng.uniform(-2, 2);
      break;
    case Scale::Tiny:
      s = log_uniform(rng, -300, -250);
      if (rng.below(2))
        for (double& o : f.offset) o = s * rng.uniform(-2, 2);
      break;
    case Scale::Subnormal: s = std::ldexp(1.0, -1074 + int(rng.below(40))); break;
    case Scale::Mixed: s = log_uniform(rng, -300, 300); break;
  }
  for (double& k : f.scale) k = s;
  if (scale == Scale::Mixed && !isotropic)
    for (double& k : f.scale) k = random_sign(rng) * log_uniform(rng, -300, 300);
  return f;
}

Point random_unit_point(Rng& rng) { return {rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)}; }

void nudge_point(Point& p, Rng& rng, int ulps) {
  for (double& x : p) x = nudge(x, rng, ulps);
}

// Integer points on a grid of one-ulp spacing far from the origin (the
// coordinates o + k ulp(o) are exact): exactly degenerate when the integer
// configuration is, then half of the time nudged by one ulp.
PredicateArgs offset_grid(Rng& rng, const PredicateArgs& integer_points, int count, int dim) {
  PredicateArgs p{};
  for (int k = 0; k < dim; ++k) {
    const int e = int(rng.below(80)) - 20;
    const double origin = random_sign(rng) * 1.5 * std::ldexp(1.0, e), ulp = std::ldexp(1.0, e - 52);
    for (int i = 0; i < count; ++i) p[i][k] = origin + integer_points[i][k] * ulp;
  }
  if (rng.below(2)) nudge_point(p[count - 1], rng, 1);
  if (dim == 2)
    for (auto& x : p) x[2] = 0.0;
  return p;
}

PredicateArgs random_integer_flat(Rng& rng, int dim) {
  PredicateArgs u{};
  auto coordinate = [&] { return double(int(rng.below(2049)) - 1024); };
  for (int i = 0; i < dim; ++i) u[i] = {coordinate(), coordinate(), coordinate()};
  const double s = double(int(rng.below(5)) - 2), t = double(int(rng.below(5)) - 2);
  for (int k = 0; k < 3; ++k)
    u[dim][k] = dim == 2 ? u[0][k] + s * (u[1][k] - u[0][k]) : u[0][k] + s * (u[1][k] - u[0][k]) + t * (u[2][k] - u[0][k]);
  return u;
}

PredicateArgs random_lattice_round(Rng& rng, int dim);

// c on the line ab (orient2d) / d on the plane abc (orient3d), then placed.
PredicateArgs near_flat(Scale scale, Rng& rng, int dim) {
  if (scale == Scale::Offset) return offset_grid(rng, random_integer_flat(rng, dim), dim + 1, dim);
  const Frame f = random_frame(scale, rng, false);
  PredicateArgs u;
  for (auto& p : u) p = random_unit_point(rng);
  const int last = dim;  // index of the dependent point
  Point& q = u[last];
  const double s = rng.uniform(-1, 2), t = rng.uniform(-1, 2);
  for (int k = 0; k < 3; ++k)
    q[k] = dim == 2 ? u[0][k] + s * (u[1][k] - u[0][k]) : u[0][k] + s * (u[1][k] - u[0][k]) + t * (u[2][k] - u[0][k]);
  PredicateArgs p;
  for (int i = 0; i < 5; ++i) p[i] = f.apply(u[i]);
  if (dim == 2)
    for (auto& x : p) x[2] = 0.0;
  nudge_point(p[last], rng, 3);
  if (rng.below(4) == 0) nudge_point(p[int(rng.below(std::uint64_t(last)))], rng, 2);
  return p;
}

// PredicateArgs on a circle (dim 2) or sphere (dim 3), the last one nudged.
PredicateArgs near_round(Scale scale, Rng& rng, int dim) {
  const int count = dim + 2;
  if (scale == Scale::Offset) return offset_grid(rng, random_lattice_round(rng, dim), count, dim);
  PredicateArgs p{};
  if (scale == Scale::Mixed) {
    // Radius 2^k around the origin, points a tiny angle away from the axes:
    // coordinates of wildly different magnitudes in one call.
    const double r = std::ldexp(1.0, int(rng.below(1600)) - 800);
    for (int i = 0; i < count; ++i) {
      Point& q = p[i];
      const int axis = int(rng.below(std::uint64_t(dim)));
      q = {0, 0, 0};
      for (int k = 0; k < dim; ++k) q[k] = r * random_sign(rng) * log_uniform(rng, -250, -1);
      q[axis] = random_sign(rng) * r * std::sqrt(1.0 - (q[(axis + 1) % dim] / r) * (q[(axis + 1) % dim] / r));
    }
    nudge_point(p[count - 1], rng, 2);
    if (dim == 2)
      for (auto& x : p) x[2] = 0.0;
    return p;
  }
  const Frame f = random_frame(scale, rng, true);
  const double two_pi = 2 * std::numbers::pi;
  for (int i = 0; i < count; ++i) {
    Point u{0, 0, 0};
    if (dim == 2) {
      const double a = rng.uniform(0, two_pi);
      u = {std::cos(a), std::sin(a), 0};
    } else {
      const double z = rng.uniform(-1, 1), a = rng.uniform(0, two_pi), r = std::sqrt(1 - z * z);
      u = {r * std::cos(a), r * std::sin(a), z};
    }
    p[i] = f.apply(u);
    if (dim == 2) p[i][2] = 0.0;
  }
  nudge_point(p[count - 1], rng, 3);
  if (dim == 2) p[count - 1][2] = 0.0;
  return p;
}

PredicateArgs random_uniform(Rng& rng, int dim) {
  PredicateArgs p{};
  for (auto& q : p) {
    q = random_unit_point(rng);
    if (dim == 2) q[2] = 0.0;
  }
  return p;
}

// Small integer grids: many exactly degenerate sets. Translated by an integer
// and scaled by a power of two, both exact while in range.
PredicateArgs integer_grid(Rng& rng, int dim, int half_width) {
  PredicateArgs p{};
  const double scale = std::ldexp(1.0, int(rng.below(1960)) - 1000);
  const double shift = double(int(rng.below(2001)) - 1000) * (rng.below(2) ? 1.0 : std::ldexp(1.0, 20));
  for (auto& q : p)
    for (int k = 0; k < dim; ++k) q[k] = (double(int(rng.below(std::uint64_t(2 * half_width + 1))) - half_width) + shift) * scale;
  return p;
}

// Integer points with x^2 + y^2 (+ z^2) = r^2.
std::vector<Point> lattice_sphere(int r, int dim) {
  std::vector<Point> points;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y) {
      if (dim == 2) {
        if (x * x + y * y == r * r) points.push_back({double(x), double(y), 0});
        continue;
      }
      for (int z = -r; z <= r; ++z)
        if (x * x + y * y + z * z == r * r) points.push_back({double(x), double(y), double(z)});
    }
  return points;
}

// Distinct exactly co-circular / co-spherical lattice points, translated by an
// integer and scaled by a power of two.
PredicateArgs on_lattice_sphere(Rng& rng, const std::vector<Point>& sphere, int dim) {
  PredicateArgs p{};
  const double scale = std::ldexp(1.0, int(rng.below(1400)) - 700);
  Point shift{};
  for (int k = 0; k < dim; ++k) shift[k] = double(int(rng.below(201)) - 100);
  for (int i = 0; i < dim + 2; ++i) {
    bool repeated = true;
    while (repeated) {
      p[i] = sphere[rng.below(sphere.size())];
      repeated = false;
      for (int j = 0; j < i; ++j) repeated |= p[j] == p[i];
    }
  }
  for (int i = 0; i < dim + 2; ++i)
    for (int k = 0; k < dim; ++k) p[i][k] = (p[i][k] + shift[k]) * scale;
  return p;
}

PredicateArgs random_lattice_round(Rng& rng, int dim) {
  static const std::vector<Point> circle = lattice_sphere(65, 2), sphere = lattice_sphere(9, 3);
  PredicateArgs p{};
  const std::vector<Point>& round = dim == 2 ? circle : sphere;
  for (int i = 0; i < dim + 2; ++i) p[i] = round[rng.below(round.size())];
  return p;
}

// PredicateArgs on a line / plane through the origin with power-of-two multiples:
// exactly degenerate with arbitrary significands and mixed magnitudes.
PredicateArgs flat_through_origin(Rng& rng, int dim) {
  PredicateArgs p{};
  auto any_double = [&] { return random_sign(rng) * log_uniform(rng, -300, 300); };
  Point a{any_double(), any_double(), dim == 3 ? any_double() : 0.0};
  Point b{any_double(), any_double(), dim == 3 ? any_double() : 0.0};
  auto multiple = [&](const Point& v) {
    const double s = random_sign(rng) * std::ldexp(1.0, int(rng.below(40)) - 20);
    return Point{v[0] * s, v[1] * s, v[2] * s};
  };
  p[0] = {0, 0, 0};
  p[1] = a;
  p[2] = multiple(a);
  if (dim == 3) p[3] = multiple(b), p[2] = b;
  if (rng.below(2)) nudge_point(p[dim], rng, 1);
  for (int i = dim + 1; i < 5; ++i) p[i] = {0, 0, 0};
  if (dim == 2)
    for (auto& x : p) x[2] = 0.0;
  // Shuffle so the origin is not always first.
  for (int i = dim; i > 0; --i) std::swap(p[i], p[rng.below(std::uint64_t(i + 1))]);
  return p;
}

// ---------------------------------------------------------------------------
// Conventions.

TEST(Predicates, Orient2dCounterClockwiseIsPositive) {
  const double a[2] = {0, 0}, b[2] = {1, 0}, c[2] = {0, 1};
  EXPECT_GT(orient2d(a, b, c), 0);
  EXPECT_LT(orient2d(a, c, b), 0);
  EXPECT_EQ(orient2d(a, b, b), 0);
  EXPECT_DOUBLE_EQ(orient2d(a, b, c), 1.0);  // twice the signed area
  EXPECT_GT(orient2d(Vec2d(0, 0), Vec2d(1, 0), Vec2d(0, 1)), 0);
  EXPECT_EQ(orient2d_fast(a, b, c), 1.0);
}

TEST(Predicates, Orient3dPositiveWhenBelowCounterClockwisePlane) {
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
  const double below[3] = {0, 0, -1}, above[3] = {0.2, 0.3, 1}, on[3] = {5, -7, 0};
  EXPECT_GT(orient3d(a, b, c, below), 0);
  EXPECT_LT(orient3d(a, b, c, above), 0);
  EXPECT_EQ(orient3d(a, b, c, on), 0);
  EXPECT_DOUBLE_EQ(orient3d(a, b, c, below), 1.0);  // six times the signed volume
  EXPECT_GT(orient3d(Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, -1)), 0);
  EXPECT_EQ(orient3d_fast(a, b, c, below), 1.0);
}

TEST(Predicates, IncirclePositiveInsideCounterClockwiseCircle) {
  const double a[2] = {0, 0}, b[2] = {1, 0}, c[2] = {0, 1};
  const double inside[2] = {0.25, 0.25}, outside[2] = {2, 2}, on[2] = {1, 1};
  EXPECT_GT(incircle(a, b, c, inside), 0);
  EXPECT_LT(incircle(a, b, c, outside), 0);
  EXPECT_EQ(incircle(a, b, c, on), 0);
  EXPECT_LT(incircle(a, c, b, inside), 0);  // clockwise flips the sign
  EXPECT_GT(incircle(Vec2d(0, 0), Vec2d(1, 0), Vec2d(0, 1), Vec2d(0.25, 0.25)), 0);
  EXPECT_GT(incircle_fast(a, b, c, inside), 0);
}

TEST(Predicates, InspherePositiveInsidePositivelyOrientedSphere) {
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {0, 0, -1};
  ASSERT_GT(orient3d(a, b, c, d), 0);
  const double inside[3] = {0.2, 0.2, -0.2}, outside[3] = {3, 3, 3}, on[3] = {1, 1, 0};
  EXPECT_GT(insphere(a, b, c, d, inside), 0);
  EXPECT_LT(insphere(a, b, c, d, outside), 0);
  EXPECT_EQ(insphere(a, b, c, d, on), 0);
  EXPECT_LT(insphere(b, a, c, d, inside), 0);  // negative orientation flips the sign
  EXPECT_GT(insphere(Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, -1), Vec3d(0.2, 0.2, -0.2)), 0);
  EXPECT_GT(insphere_fast(a, b, c, d, inside), 0);
}

TEST(Predicates, NonFiniteInputGivesNaN) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {0, 0, 1};
  for (const double bad : {inf, -inf, nan}) {
    const double e[3] = {bad, 0.5, 0.5};
    EXPECT_TRUE(std::isnan(orient2d(a, b, e)));
    EXPECT_TRUE(std::isnan(orient3d(a, b, c, e)));
    EXPECT_TRUE(std::isnan(incircle(a, b, c, e)));
    EXPECT_TRUE(std::isnan(insphere(a, b, c, d, e)));
    EXPECT_TRUE(std::isnan(insphere(e, b, c, d, a)));
  }
}

TEST(Predicates, ResultsAreFiniteAtTheEndsOfTheRange) {
  // The determinant of these overflows / underflows a double; the sign must not.
  const double big = std::numeric_limits<double>::max() / 4, small = std::numeric_limits<double>::denorm_min();
  const double a[3] = {-big, -big, -big}, b[3] = {big, -big, -big}, c[3] = {-big, big, -big}, d[3] = {-big, -big, big};
  const double e[3] = {0, 0, 0};
  EXPECT_EQ(orient2d(a, b, c), std::numeric_limits<double>::max());
  EXPECT_EQ(orient3d(a, b, c, d), -std::numeric_limits<double>::max());
  EXPECT_EQ(incircle(a, b, c, e), std::numeric_limits<double>::max());
  EXPECT_EQ(insphere(a, b, c, d, e), -std::numeric_limits<double>::max());  // e inside, orient3d < 0
  const double s0[2] = {0, 0}, s1[2] = {small, 0}, s2[2] = {0, small};
  EXPECT_EQ(orient2d(s0, s1, s2), small);
}

// ---------------------------------------------------------------------------
// Exact signs against the oracle.

constexpr int kCases = 1500;

void expect_exact_signs_everywhere(const Predicate& pred, bool round) {
  const int dim = pred.dim;
  std::uint64_t seed = 1000 * std::uint64_t(pred.count) + std::uint64_t(dim);
  expect_exact_signs(pred, ++seed, kCases, [&](Rng& rng) { return random_uniform(rng, dim); }, "random");
  for (const Scale s : kScales)
    expect_exact_signs(pred, ++seed, kCases,
                       [&](Rng& rng) { return round ? near_round(s, rng, dim) : near_flat(s, rng, dim); },
                       scale_name(s));
  expect_exact_signs(pred, ++seed, kCases, [&](Rng& rng) { return integer_grid(rng, dim, dim == 2 ? 3 : 2); },
                     "integer_grid");
  if (!round)
    expect_exact_signs(pred, ++seed, kCases, [&](Rng& rng) { return flat_through_origin(rng, dim); },
                       "through_origin");
}

TEST(Predicates, Orient2dExactSigns) { expect_exact_signs_everywhere(kOrient2d, false); }
TEST(Predicates, Orient3dExactSigns) { expect_exact_signs_everywhere(kOrient3d, false); }
TEST(Predicates, IncircleExactSigns) { expect_exact_signs_everywhere(kIncircle, true); }
TEST(Predicates, InsphereExactSigns) { expect_exact_signs_everywhere(kInsphere, true); }

TEST(Predicates, IncircleExactOnLatticeCircles) {
  for (const int r : {5, 65, 1105}) {
    const auto circle = lattice_sphere(r, 2);
    expect_exact_signs(kIncircle, std::uint64_t(r), kCases, [&](Rng& rng) { return on_lattice_sphere(rng, circle, 2); },
                       "lattice_circle");
  }
}

// Unscaled integer coordinates far from the origin whose differences reach the
// limits of the plain-double path for integers (2^26 for orient2d, 2^12 for
// incircle) and up to 8 times beyond (where the adaptive stages take over):
// random, collinear or co-circular (lattice circles of radius 1105 and 5525,
// scaled by up to 2), or those moved by one unit.
PredicateArgs integer_differences_near_limit(Rng& rng, int bits, const std::vector<std::vector<Point>>& circles) {
  PredicateArgs p{};
  const double origin = double(std::int64_t(rng.below(std::uint64_t(1) << 50)) - (std::int64_t(1) << 49));
  const double limit = std::ldexp(1.0, bits + int(rng.below(4)));
  const auto coordinate = [&] { return std::floor(rng.uniform(-limit, limit)); };
  const std::uint64_t kind = rng.below(3);
  if (kind == 0) {
    for (auto& q : p) q = {origin + coordinate(), origin + coordinate(), 0};
    return p;
  }
  if (bits == 26) {  // collinear: a + t v with t in -2..2
    const Point a{origin + coordinate(), origin + coordinate(), 0};
    const double vx = std::floor(coordinate() / 2), vy = std::floor(coordinate() / 2);
    for (int i = 0; i < 5; ++i) p[i] = {a[0] + double(i - 2) * vx, a[1] + double(i - 2) * vy, 0};
  } else {
    const auto& circle = circles[rng.below(circles.size())];
    const double scale = double(1 + rng.below(2));
    for (int i = 0; i < 5; ++i) {
      const Point& q = circle[rng.below(circle.size())];
      p[i] = {origin + scale * q[0], origin + scale * q[1], 0};
    }
  }
  if (kind == 2) p[rng.below(3)][rng.below(2)] += rng.below(2) ? 1.0 : -1.0;  // nearly degenerate
  return p;
}

TEST(Predicates, ExactOnIntegerDifferencesNearTheLimit) {
  const std::vector<std::vector<Point>> circles = {lattice_sphere(1105, 2), lattice_sphere(5525, 2)};
  expect_exact_signs(kOrient2d, 71, 4 * kCases,
                     [&](Rng& rng) { return integer_differences_near_limit(rng, 26, circles); }, "orient2d_integers");
  expect_exact_signs(kIncircle, 72, 4 * kCases,
                     [&](Rng& rng) { return integer_differences_near_limit(rng, 12, circles); }, "incircle_integers");
}

TEST(Predicates, InsphereExactOnLatticeSpheres) {
  for (const int r : {3, 9, 21}) {
    const auto sphere = lattice_sphere(r, 3);
    expect_exact_signs(kInsphere, std::uint64_t(r), kCases, [&](Rng& rng) { return on_lattice_sphere(rng, sphere, 3); },
                       "lattice_sphere");
  }
}

// Exactly degenerate points whose coordinate differences are not exact:
// components x, y, z of very different magnitudes, permuted and negated, lie
// on one line / plane through the origin or on one circle / sphere around it.
// Nothing short of the last exact stage can call these 0; nudged by an ulp,
// they exercise the stage with the first-order tail terms (C) and the last.
PredicateArgs inexact_differences(Rng& rng, int dim, bool round, bool nudged) {
  const double x = 1.0 + rng.uniform(0, 1), y = std::ldexp(rng.uniform(1, 2), -int(rng.below(40)) - 1);
  const double z = std::ldexp(rng.uniform(1, 2), -int(rng.below(40)) - 1);
  PredicateArgs p{};
  const int count = dim + (round ? 2 : 1);
  for (int i = 0; i < count; ++i) {
    double v[3] = {x, y, z};
    if (round) {
      const int shift = int(rng.below(std::uint64_t(dim)));  // cyclic permutations keep |v|
      for (int k = 0; k < dim; ++k) p[i][k] = random_sign(rng) * v[(k + shift) % dim];
    } else {
      // On the line y = x (2D) or the plane z = x (3D), scaled by a power of two.
      const double s = random_sign(rng) * std::ldexp(1.0, int(rng.below(7)) - 3);
      const int pick = int(rng.below(3));
      const double u = v[pick] * s, w = v[(pick + 1) % 3] * s;
      p[i] = dim == 2 ? Point{u, u, 0} : Point{u, w, u};
    }
  }
  if (nudged) nudge_point(p[count - 1], rng, 1);
  if (dim == 2)
    for (auto& q : p) q[2] = 0.0;
  return p;
}

TEST(Predicates, ExactlyDegenerateWithInexactDifferences) {
  for (const Predicate* pred : {&kOrient2d, &kOrient3d, &kIncircle, &kInsphere}) {
    const bool round = pred->lifted;
    expect_exact_signs(*pred, 7, kCases, [&](Rng& rng) { return inexact_differences(rng, pred->dim, round, false); },
                       "inexact_differences");
    expect_exact_signs(*pred, 8, kCases, [&](Rng& rng) { return inexact_differences(rng, pred->dim, round, true); },
                       "inexact_differences_nudged");
  }
}

TEST(Predicates, FastDeterminantsAgreeAwayFromDegeneracy) {
  Rng rng(99);
  for (const Predicate* pred : {&kOrient2d, &kOrient3d, &kIncircle, &kInsphere}) {
    for (int n = 0; n < 2000; ++n) {
      const PredicateArgs p = random_uniform(rng, pred->dim);
      const double fast = pred->fast(p.data()), exact = pred->exact(p.data());
      if (std::abs(fast) > 1e-9) {
        EXPECT_EQ(sign(fast), sign(exact)) << pred->name;
      }
    }
  }
}

}  // namespace
}  // namespace geods
