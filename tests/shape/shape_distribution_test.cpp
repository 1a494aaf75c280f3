// Shape distributions against independent oracles: the closed-form D2 density
// of a sphere, Monte Carlo on the analytic surfaces (cube, cylinder, sphere)
// with a sampler and shape functions written here, invariance under rigid
// motion, scale and tessellation on data/ meshes, and distances against
// their definitions (the EMD against a transport plan built bin by bin).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <random>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/shape/shape_distribution.hpp"
#include "shape/test_meshes.hpp"

namespace geods::shape {
namespace {

using testing::cube;
using testing::cylinder;
using testing::icosphere;

double l1(const std::vector<float>& a, const std::vector<float>& b) { return histogram_distance(a, b, Metric::l1); }

// ---------------------------------------------------------------- oracle: analytic surfaces
using Sampler = std::function<Vec3d(std::mt19937_64&)>;

Vec3d sphere_point(std::mt19937_64& g) {
  std::normal_distribution<double> n;
  Vec3d v;
  do v = Vec3d(n(g), n(g), n(g));
  while (v.norm() < 1e-9);
  return v.normalized();
}
Vec3d cube_point(std::mt19937_64& g) {  // [0, 1]^3
  std::uniform_real_distribution<double> u;
  const int face = int(u(g) * 6);
  Vec3d p(u(g), u(g), u(g));
  p[face / 2] = face % 2;
  return p;
}
Vec3d cylinder_point(std::mt19937_64& g) {  // r = 1, h = 2
  std::uniform_real_distribution<double> u;
  const double side = 2 * std::numbers::pi * 2, cap = std::numbers::pi, pick = u(g) * (side + 2 * cap);
  const double a = 2 * std::numbers::pi * u(g);
  if (pick < side) return Vec3d(std::cos(a), std::sin(a), 2 * u(g));
  const double r = std::sqrt(u(g));
  return Vec3d(r * std::cos(a), r * std::sin(a), pick < side + cap ? 0.0 : 2.0);
}

double oracle_function(ShapeFunction f, const Sampler& s, const Vec3d& centroid, std::mt19937_64& g) {
  const Vec3d p = s(g);
  if (f == ShapeFunction::d1) return (p - centroid).norm();
  const Vec3d q = s(g);
  if (f == ShapeFunction::d2) return (p - q).norm();
  const Vec3d r = s(g);
  const Vec3d u = q - p, v = r - p;
  if (f == ShapeFunction::a3) return std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0));
  if (f == ShapeFunction::d3) return std::sqrt(u.cross(v).norm() / 2);
  const Vec3d w = s(g) - p;
  return std::cbrt(std::abs(u.cross(v).dot(w)) / 6);
}

// The oracle's histogram: mean-normalized (or raw over [0, max]) as the header specifies.
std::vector<float> oracle_histogram(ShapeFunction f, const Sampler& s, const Vec3d& centroid, std::size_t n,
                                    std::size_t bins, bool normalize, double max_value) {
  std::mt19937_64 g(12345);
  std::vector<double> values(n);
  double mean = 0;
  for (auto& v : values) mean += (v = oracle_function(f, s, centroid, g));
  mean /= double(n);
  const double scale = (normalize && f != ShapeFunction::a3) ? mean : 1.0;
  std::vector<float> h(bins, 0.0f);
  for (double v : values) {
    const auto b = std::size_t(std::min(double(bins - 1), std::floor(v / scale / max_value * double(bins))));
    h[b] += float(1.0 / double(n));
  }
  return h;
}

// ---------------------------------------------------------------- closed form
TEST(ShapeDistribution, SphereD2MatchesClosedFormDensity) {
  // f(d) = d / (2 R^2) on [0, 2R]: a bin [d0, d1) holds (d1^2 - d0^2) / (4 R^2).
  const float R = 2.5f;
  const TriMesh sphere = icosphere(5, R);
  DistributionOptions o;
  o.samples = 1 << 18;
  o.bins = 32;
  o.normalization = Normalization::none;
  o.max_value = 2 * R;
  const std::vector<float> h = shape_distribution(sphere, ShapeFunction::d2, o);
  double total = 0, worst = 0;
  for (std::size_t i = 0; i < o.bins; ++i) {
    const double d0 = 2 * R * double(i) / 32, d1 = 2 * R * double(i + 1) / 32;
    const double expected = (d1 * d1 - d0 * d0) / (4 * R * R);
    const double sigma = std::sqrt(expected * (1 - expected) / double(o.samples));
    worst = std::max(worst, std::abs(h[i] - expected) / (sigma + 1e-4));
    total += h[i];
  }
  EXPECT_NEAR(total, 1.0, 1e-5);
  EXPECT_LT(worst, 5.0) << "a bin is more than 5 sigma from d/(2R^2)";

  // Mean-normalized: the mean is 4R/3, so x = 3d/(4R) has density 8x/9 on [0, 1.5].
  DistributionOptions m;
  m.samples = 1 << 18;
  m.bins = 30;  // over [0, 3): bins of 0.1
  const std::vector<float> hm = shape_distribution(sphere, ShapeFunction::d2, m);
  for (std::size_t i = 0; i < 30; ++i) {
    const double x0 = 0.1 * double(i), x1 = 0.1 * double(i + 1);
    const double expected = x1 <= 1.5 ? 4.0 / 9.0 * (x1 * x1 - x0 * x0) : 0.0;
    EXPECT_NEAR(hm[i], expected, 0.004) << "bin " << i;
  }
}

TEST(ShapeDistribution, SphereD1IsOnePoint) {
  // Every surface point is at distance R from the centroid: after normalization all mass is at 1.
  DistributionOptions o;
  o.samples = 10000;
  o.bins = 30;  // bin 10 = [1.0, 1.1)
  const TriMesh sphere = icosphere(4, 3.0f);
  const std::vector<float> h = shape_distribution(sphere, ShapeFunction::d1, o);
  EXPECT_NEAR(h[9] + h[10], 1.0, 1e-6);
}

// ---------------------------------------------------------------- Monte Carlo on the analytic surfaces
struct Analytic {
  const char* name;
  TriMesh mesh;
  Sampler oracle;
  Vec3d centroid;
};

std::vector<Analytic> analytic_shapes() {
  return {{"sphere", icosphere(5), sphere_point, Vec3d::Zero()},
          {"cube", cube(), cube_point, Vec3d(0.5, 0.5, 0.5)},
          {"cylinder", cylinder(256), cylinder_point, Vec3d(0, 0, 1)}};
}

TEST(ShapeDistribution, AllFunctionsMatchMonteCarloOnAnalyticSurfaces) {
  const auto shapes = analytic_shapes();
  for (ShapeFunction f : {ShapeFunction::d1, ShapeFunction::d2, ShapeFunction::a3, ShapeFunction::d3,
                          ShapeFunction::d4}) {
    DistributionOptions o;
    o.samples = 1 << 16;
    o.bins = 32;
    std::vector<std::vector<float>> ours;
    for (const Analytic& s : shapes) {
      ours.push_back(shape_distribution(s.mesh, f, o));
      const std::vector<float> oracle =
          oracle_histogram(f, s.oracle, s.centroid, 1 << 18, o.bins, true, histogram_max(f, o));
      const double agree = l1(ours.back(), oracle);
      EXPECT_LT(agree, 0.03) << s.name << " " << shape_function_name(f);
    }
    // The test can tell shapes apart: the distributions of different shapes differ far more.
    // The test can tell Figure 55's shapes apart: their D2 distributions differ
    // by several times the agreement with the oracle (about 0.015, sampling noise).
    if (f == ShapeFunction::d2) {
      EXPECT_GT(l1(ours[0], ours[1]), 0.15) << "sphere vs cube";
      EXPECT_GT(l1(ours[1], ours[2]), 0.05) << "cube vs cylinder";
    }
  }
}

TEST(ShapeDistribution, RawD2OfFigure55ShapesMatchMonteCarlo) {
  // As Figure 55: raw distances (no normalization) of the sphere, cube and cylinder.
  for (const Analytic& s : analytic_shapes()) {
    DistributionOptions o;
    o.samples = 1 << 16;
    o.bins = 40;
    o.normalization = Normalization::none;
    o.max_value = 4;
    const auto ours = shape_distribution(s.mesh, ShapeFunction::d2, o);
    const auto oracle = oracle_histogram(ShapeFunction::d2, s.oracle, s.centroid, 1 << 18, 40, false, 4);
    EXPECT_LT(l1(ours, oracle), 0.03) << s.name;
  }
}

// ---------------------------------------------------------------- sampling
TEST(SurfaceSampler, PicksTrianglesByAreaAndNeverZeroArea) {
  TriMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {3, 0, 1}, {0, 1, 1}, {5, 5, 5}, {6, 6, 6}, {7, 7, 7}};
  m.triangles = {{0, 1, 2}, {6, 7, 8}, {3, 4, 5}};  // areas 0.5, 0 (collinear), 1.5
  const SurfaceSampler s(m);
  EXPECT_DOUBLE_EQ(s.area(), 2.0);
  EXPECT_TRUE(s.centroid().isApprox(Vec3d(0.25 * 1.0 / 3 + 0.75 * 1.0, 0.25 / 3 + 0.75 / 3, 0.75), 1e-12));
  Rng rng(7);
  int low = 0, high = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const Vec3d p = s.sample(rng);
    ASSERT_TRUE(std::abs(p.z()) < 1e-12 || std::abs(p.z() - 1) < 1e-12) << "a point off both triangles";
    (p.z() < 0.5 ? low : high)++;
    if (p.z() < 0.5) {
      ASSERT_LE(p.x() + p.y(), 1 + 1e-12);
    }
  }
  EXPECT_NEAR(double(low) / n, 0.25, 4 * std::sqrt(0.25 * 0.75 / n));
}

TEST(ShapeDistribution, DeterministicPerSeedAndThreadCount) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  DistributionOptions o;
  o.samples = 50000;
  const auto a = shape_distribution(bunny, ShapeFunction::d2, o);
  set_num_threads(1);
  const auto b = shape_distribution(bunny, ShapeFunction::d2, o);
  set_num_threads(0);
  EXPECT_EQ(a, b);
  o.seed = 1;
  EXPECT_NE(a, shape_distribution(bunny, ShapeFunction::d2, o));
  const auto values = shape_function_values(bunny, ShapeFunction::d2, 50000, 0);
  EXPECT_EQ(a, histogram(values, normalization_scale(values, ShapeFunction::d2, Normalization::mean), 3.0, 64));
}

// ---------------------------------------------------------------- invariance
TEST(ShapeDistribution, InvariantToRigidMotionScaleAndTessellation) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const TriMesh teapot = test::data_mesh("teapot.obj");
  const float size = bunny.bounds().extent().maxCoeff();
  const std::vector<std::pair<const char*, TriMesh>> copies = {
      {"rotated", testing::transformed(bunny, testing::rotation(1.1f, {1, 2, 3}), Vec3f::Zero(), 1)},
      {"translated", testing::transformed(bunny, Eigen::Matrix3f::Identity(), {40, -7, 3}, 1)},
      {"scaled", testing::transformed(bunny, Eigen::Matrix3f::Identity(), Vec3f::Zero(), 37.5f)},
      {"all three", testing::transformed(bunny, testing::rotation(-2.0f, {0, 1, 1}), {1, 2, 3}, 0.01f)},
      {"subdivided", testing::subdivide(bunny)},
      {"decimated", testing::decimate(bunny, size / 40)}};
  // Rigid motions and scale with the same seed pick the same triangles and
  // barycentric coordinates: the values transform exactly, up to rounding.
  // Tessellation changes the triangles, so another seed and sampling noise:
  // 2^18 samples over 16 bins keep it well below the bunny-teapot distance.
  for (Normalization n : {Normalization::mean, Normalization::median}) {
    for (ShapeFunction f :
         {ShapeFunction::d1, ShapeFunction::d2, ShapeFunction::a3, ShapeFunction::d3, ShapeFunction::d4}) {
      if (n == Normalization::median && f != ShapeFunction::d2) continue;
      DistributionOptions o;
      o.samples = 1 << 18;
      o.bins = 16;
      o.normalization = n;
      o.seed = 3;
      const auto original = shape_distribution(bunny, f, o);
      const double different = l1(original, shape_distribution(teapot, f, o));
      const std::string what = std::string(shape_function_name(f)) + " " + std::string(normalization_name(n));
      EXPECT_GT(different, 0.02) << what;
      for (const auto& [name, copy] : copies) {
        const bool rigid = copy.triangles.size() == bunny.triangles.size();
        o.seed = rigid ? 3 : 4;
        const double d = l1(original, shape_distribution(copy, f, o));
        EXPECT_LT(d, rigid ? different / 20 : different / 3) << name << " " << what << " (bunny-teapot " << different << ")";
        EXPECT_LT(d, rigid ? 0.003 : 0.02) << name << " " << what;
      }
    }
  }
}

// ---------------------------------------------------------------- distances
TEST(Distance, DefinitionsOnSmallHistograms) {
  const std::vector<float> a{0.5f, 0.25f, 0.25f, 0.0f}, b{0.0f, 0.25f, 0.25f, 0.5f};
  EXPECT_NEAR(histogram_distance(a, b, Metric::l1), 1.0, 1e-7);
  EXPECT_NEAR(histogram_distance(a, b, Metric::l2), std::sqrt(0.5), 1e-7);
  EXPECT_NEAR(histogram_distance(a, b, Metric::chi2), 0.25 / 0.5 + 0.25 / 0.5, 1e-7);
  // Half the mass moves 3 bins: EMD 1.5 bins.
  EXPECT_NEAR(histogram_distance(a, b, Metric::emd), 1.5, 1e-7);
  EXPECT_EQ(histogram_distance(a, a, Metric::emd), 0.0);
  // Blocks: two distributions of two bins; each moves all its mass one bin.
  EXPECT_NEAR(histogram_distance(std::vector<float>{1, 0, 1, 0}, std::vector<float>{0, 1, 0, 1}, Metric::emd, 2), 2.0, 1e-7);
  EXPECT_THROW(histogram_distance(a, std::vector<float>{1, 0}, Metric::l1), Error);
  EXPECT_THROW(histogram_distance(a, b, Metric::emd, 3), Error);
  EXPECT_THROW(parse_metric("cosine"), Error);
}

// EMD oracle: move mass bin by bin (north-west corner rule of the 1D transport problem, optimal in 1D).
double transport_cost(std::vector<double> a, std::vector<double> b) {
  double cost = 0;
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double m = std::min(a[i], b[j]);
    cost += m * std::abs(double(i) - double(j));
    a[i] -= m;
    b[j] -= m;
    if (a[i] <= 1e-15) {
      ++i;
    } else {
      ++j;
    }
  }
  return cost;
}

TEST(Distance, EmdEqualsOptimalTransportOnRandomHistograms) {
  std::mt19937 g(5);
  std::uniform_real_distribution<double> u;
  for (int trial = 0; trial < 50; ++trial) {
    const std::size_t n = 1 + g() % 20;
    std::vector<double> a(n), b(n);
    double sa = 0, sb = 0;
    for (std::size_t i = 0; i < n; ++i) sa += (a[i] = trial % 5 == 0 && i % 2 ? 0 : u(g)), sb += (b[i] = u(g));
    if (sa == 0) a[0] = sa = 1;
    std::vector<float> fa(n), fb(n);
    for (std::size_t i = 0; i < n; ++i) a[i] /= sa, b[i] /= sb, fa[i] = float(a[i]), fb[i] = float(b[i]);
    std::vector<double> da(fa.begin(), fa.end()), db(fb.begin(), fb.end());
    EXPECT_NEAR(histogram_distance(fa, fb, Metric::emd), transport_cost(da, db), 1e-5) << "trial " << trial;
  }
}

// ---------------------------------------------------------------- descriptors
TEST(Descriptor, ParseAndCombine) {
  EXPECT_EQ(descriptor_name(parse_descriptor("d2")), "d2");
  EXPECT_EQ(descriptor_name(parse_descriptor("combined")), "combined");
  const DescriptorOptions w = parse_descriptor("d2+a3:0.5");
  EXPECT_EQ(w.functions, (std::vector<ShapeFunction>{ShapeFunction::d2, ShapeFunction::a3}));
  EXPECT_EQ(w.weights, (std::vector<double>{1.0, 0.5}));
  EXPECT_EQ(descriptor_name(parse_descriptor(descriptor_name(w))), descriptor_name(w));
  for (const char* bad : {"", "d5", "d2+", "d2:-1", "d2:x", "d2:nan"}) EXPECT_THROW(parse_descriptor(bad), Error) << bad;

  DescriptorOptions o = w;
  o.distribution.samples = 20000;
  o.distribution.bins = 16;
  const TriMesh teapot = test::data_mesh("teapot.obj");
  const std::vector<float> d = describe(teapot, o);
  ASSERT_EQ(d.size(), 32u);
  DistributionOptions one = o.distribution;
  const auto d2 = shape_distribution(teapot, ShapeFunction::d2, one);
  one.seed += 1;
  const auto a3 = shape_distribution(teapot, ShapeFunction::a3, one);
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(d[i], d2[i]);
    EXPECT_FLOAT_EQ(d[16 + i], 0.5f * a3[i]);
  }
  o.weights = {1.0};
  EXPECT_THROW(describe(teapot, o), Error);
}

// ---------------------------------------------------------------- bad input
TEST(ShapeDistribution, BadInputThrows) {
  const TriMesh sphere = icosphere(1);
  auto d2 = [](const TriMesh& m, DistributionOptions o = {}) { return shape_distribution(m, ShapeFunction::d2, o); };
  EXPECT_THROW(d2(TriMesh{}), Error);
  TriMesh flat;  // triangles of zero area
  flat.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  flat.triangles = {{0, 1, 2}, {0, 0, 1}};
  EXPECT_THROW(d2(flat), Error);
  TriMesh nan = sphere;
  nan.vertices[3].y() = std::nanf("");
  EXPECT_THROW(d2(nan), Error);
  TriMesh inf = sphere;
  inf.vertices[0].x() = INFINITY;
  EXPECT_THROW(d2(inf), Error);
  TriMesh out_of_range = sphere;
  out_of_range.triangles[5][1] = 1000;
  EXPECT_THROW(d2(out_of_range), Error);
  EXPECT_THROW(d2(sphere, {.samples = 0}), Error);
  EXPECT_THROW(d2(sphere, {.bins = 0}), Error);
  EXPECT_THROW(d2(sphere, {.normalization = Normalization::none}), Error);
  EXPECT_THROW(d2(sphere, {.max_value = -1}), Error);
  EXPECT_THROW(d2(sphere, {.max_value = NAN}), Error);
  // A flat square has no volume: d4 cannot be normalized, and says so.
  TriMesh square;
  square.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_THROW(shape_distribution(square, ShapeFunction::d4), Error);
  EXPECT_NO_THROW(shape_distribution(square, ShapeFunction::d2));
  // Extreme but finite coordinates: corners 6e38 apart overflow float edges, so refused; 1e-30 and
  // 1e30 scaled copies (polynomials of degree 3 stay inside double's range) give the unit
  // histograms up to float rounding at bin edges.
  TriMesh huge = sphere;
  huge.vertices[huge.triangles[0][0]].x() = -3e38f;
  huge.vertices[huge.triangles[0][1]].x() = 3e38f;
  EXPECT_THROW(d2(huge), Error);
  for (float scale : {1e-30f, 1e30f})
    for (ShapeFunction f : {ShapeFunction::d2, ShapeFunction::d4}) {
      DistributionOptions o{.samples = 4096, .bins = 16};
      const auto scaled = testing::transformed(sphere, Eigen::Matrix3f::Identity(), Vec3f::Zero(), scale);
      EXPECT_LT(l1(shape_distribution(scaled, f, o), shape_distribution(sphere, f, o)), 0.01) << scale;
    }
  EXPECT_THROW(parse_shape_function("d6"), Error);
  EXPECT_THROW(parse_normalization("max"), Error);
}

}  // namespace
}  // namespace geods::shape

namespace geods::shape {
namespace {

TEST(AnalyticShapes, ClosedManifoldsOfTheRightArea) {
  const double pi = std::numbers::pi;
  const struct {
    const char* name;
    TriMesh mesh;
    double area, tolerance;
  } shapes[] = {{"icosphere", icosphere(4, 2), 4 * pi * 4, 0.01},
                {"box", box_mesh(1, 2, 3), 2 * (2 + 6 + 3), 1e-6},
                {"cylinder", cylinder_mesh(256, 1, 2), 2 * pi * 2 + 2 * pi, 0.001},
                {"torus", torus_mesh(3, 1, 128, 64), 4 * pi * pi * 3, 0.002}};
  for (const auto& s : shapes) {
    EXPECT_TRUE(s.mesh.validate().closed_manifold()) << s.name;
    EXPECT_GT(s.mesh.signed_volume(), 0) << s.name << " is inside out";
    EXPECT_NEAR(s.mesh.surface_area() / s.area, 1.0, s.tolerance) << s.name;
  }
  EXPECT_THROW(cylinder_mesh(2), Error);
  EXPECT_THROW(torus_mesh(1, 0.5f, 2, 8), Error);
}

}  // namespace
}  // namespace geods::shape
