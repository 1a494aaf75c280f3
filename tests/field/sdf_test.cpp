// field::signed_distance and field::sdf_grid against brute force: every
// sample of small grids and random samples of larger ones get the distance of
// a search over all faces in double, and their sign agrees with the parity of
// ray crossings (counted over all faces) on closed meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>

#include "common/data_files.hpp"
#include "common/simd_level_guard.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/field/sdf_grid.hpp"
#include "mesh_oracle.hpp"

namespace geods::field {
namespace {

double mesh_size(const TriMesh& m) { return m.bounds().extent().maxCoeff(); }

// Checks one sample of a field against brute force: the distance, and on a
// closed mesh the sign against ray parity (away from the surface).
void expect_sample(const TriMesh& m, const Vec3f& p, float d, bool closed, const std::string& where) {
  const Brute b = brute_distance(m, p);
  const double tol = 2e-6 * (mesh_size(m) + p.cwiseAbs().maxCoeff());
  ASSERT_NEAR(std::abs(double(d)), b.distance, tol) << where;
  if (!closed || b.distance < 1e-4 * mesh_size(m)) return;
  const int in = ray_inside(m, p);
  if (in >= 0) {
    ASSERT_EQ(d < 0, in == 1) << where << " d = " << d;
  }
}

// The whole field on every sample of `grid`, for each sign method: the
// distance against brute force, the sign against ray parity, and the face
// reported at that distance.
void expect_grid(const TriMesh& m, const Grid3Geometry& grid, std::initializer_list<SignMethod> signs, bool closed) {
  std::vector<SdfGrid> fields;
  for (const SignMethod sign : signs) {
    SdfGridOptions options;
    options.sign = sign;
    options.faces = true;
    fields.push_back(sdf_grid(m, grid, options));
    ASSERT_EQ(fields.back().distance.size(), grid.dims[0] * grid.dims[1] * grid.dims[2]);
  }
  const double tol = 2e-6 * (mesh_size(m) + grid.bounds().lo.cwiseAbs().maxCoeff() + grid.bounds().hi.cwiseAbs().maxCoeff());
  for (std::size_t k = 0; k < grid.dims[2]; ++k)
    for (std::size_t j = 0; j < grid.dims[1]; ++j)
      for (std::size_t i = 0; i < grid.dims[0]; ++i) {
        const Vec3f p = grid.position(i, j, k);
        const std::string where = "sample " + std::to_string(i) + "," + std::to_string(j) + "," + std::to_string(k);
        const Brute b = brute_distance(m, p);
        const int in = closed && b.distance >= 1e-4 * mesh_size(m) ? ray_inside(m, p) : -1;
        for (const SdfGrid& r : fields) {
          const float d = r.distance(i, j, k);
          ASSERT_NEAR(std::abs(double(d)), b.distance, tol) << where;
          if (in >= 0) {
            ASSERT_EQ(d < 0, in == 1) << where << " d = " << d;
          }
          const std::uint32_t f = r.faces[grid.index(i, j, k)];
          ASSERT_LT(f, m.num_triangles());
          const Vec3d q = p.cast<double>();
          const double df = (closest_point_on_triangle(q, corner(m, f, 0), corner(m, f, 1), corner(m, f, 2)) - q).norm();
          ASSERT_NEAR(df, std::abs(d), tol) << where;
        }
      }
}

TriMesh cube(float s = 1) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back(Vec3f(i & 1 ? s : -s, i & 2 ? s : -s, i & 4 ? s : -s));
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TEST(MeshDistance, CubeIsClosedWithUnitWinding) {
  const MeshDistance md = MeshDistance::build(cube());
  EXPECT_TRUE(md.closed());
  EXPECT_NEAR(md.winding_number(Vec3f(0.1f, 0.2f, -0.3f)), 1.0, 1e-9);
  EXPECT_NEAR(md.winding_number(Vec3f(3, 0.2f, -0.3f)), 0.0, 1e-2);
  const MeshPointDistance q = md.query(Vec3f(0.2f, 0.3f, 0.5f));
  EXPECT_NEAR(q.distance, -0.5f, 1e-6f);
  EXPECT_EQ(q.feature, Feature::face);
  const MeshPointDistance v = md.query(Vec3f(2, 2, 2), SignMethod::pseudonormal);
  EXPECT_NEAR(v.distance, std::sqrt(3.0f), 1e-6f);
  EXPECT_EQ(v.feature, Feature::vertex);
  EXPECT_EQ(v.feature_index, 7u);
  const MeshPointDistance e = md.query(Vec3f(2, 2, 0.5f), SignMethod::pseudonormal);
  EXPECT_NEAR(e.distance, std::sqrt(2.0f), 1e-6f);
  EXPECT_EQ(e.feature, Feature::edge);
}

TEST(SdfGrid, BunnyEverySampleOfASmallGrid) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  // Not a multiple of the tiles, anisotropic, shifted off the mesh's centre.
  Grid3Geometry grid = sdf_grid_geometry(bunny.bounds(), 11, 0, 2);
  grid.spacing = grid.spacing.cwiseProduct(Vec3f(1.0f, 1.15f, 0.9f));
  grid.dims[2] = 9;
  expect_grid(bunny, grid, {SignMethod::winding, SignMethod::pseudonormal}, true);
}

TEST(SdfGrid, BunnyEverySampleOfThinGrids) {
  // Grids one or a few samples thick along some axes: tiles and blocks of
  // 1 to 3 samples, boxes without extent along an axis (the block lists'
  // interpolated bounds then rest on coincident corners).
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const Grid3Geometry base = sdf_grid_geometry(bunny.bounds(), 14, 0, 1);
  for (const std::array<std::size_t, 3> dims : {std::array<std::size_t, 3>{1, 14, 11}, {13, 1, 2}, {3, 6, 1}}) {
    Grid3Geometry grid = base;
    grid.dims = dims;
    for (int a = 0; a < 3; ++a)
      if (dims[a] < 4) grid.origin[a] += 0.4f * float(base.dims[a]) * grid.spacing[a];  // through the middle
    expect_grid(bunny, grid, {SignMethod::winding}, true);
  }
}

TEST(SdfGrid, BunnyRandomSamplesOfALargerGrid) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const Grid3Geometry grid = sdf_grid_geometry(bunny.bounds(), 56, 0, 4);
  const SdfGrid r = sdf_grid(bunny, grid);
  EXPECT_EQ(r.stats.in_band, r.distance.size());
  Rng rng(16);
  std::size_t inside = 0;
  for (int t = 0; t < 250; ++t) {
    const std::size_t i = rng.below(grid.dims[0]), j = rng.below(grid.dims[1]), k = rng.below(grid.dims[2]);
    expect_sample(bunny, grid.position(i, j, k), r.distance(i, j, k), true, "sample " + std::to_string(t));
    inside += r.distance(i, j, k) < 0;
  }
  EXPECT_GT(inside, 20u);  // the test saw both sides
  // Pseudonormals sign the closed bunny as the winding number does.
  SdfGridOptions pn;
  pn.sign = SignMethod::pseudonormal;
  const SdfGrid p = sdf_grid(bunny, grid, pn);
  for (std::size_t s = 0; s < r.distance.size(); ++s)
    if (std::abs(r.distance.data[s]) > 1e-4f) {
      ASSERT_EQ(r.distance.data[s], p.distance.data[s]) << s;
    }
}

TEST(SdfGrid, SameBitsForAnyThreadCount) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const Grid3Geometry grid = sdf_grid_geometry(bunny.bounds(), 40, 0, 3);
  SdfGridOptions options;
  options.faces = true;
  set_num_threads(1);
  const SdfGrid one = sdf_grid(bunny, grid, options);
  set_num_threads(0);
  const SdfGrid all = sdf_grid(bunny, grid, options);
  EXPECT_EQ(one.distance.data, all.distance.data);
  EXPECT_EQ(one.faces, all.faces);
}

// The AVX-512 kernels (chosen at run time) against the portable ones: the
// same bits and faces, whole grid and band (portable alone where the CPU has
// no AVX-512; ctest field_portable_simd runs the brute-force tests there too).
TEST(SdfGrid, SameBitsAtEverySimdLevel) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const MeshDistance md = MeshDistance::build(bunny);
  const Grid3Geometry grid = sdf_grid_geometry(bunny.bounds(), 40, 0, 3);
  const test::LevelGuard guard;
  for (const double band : {std::numeric_limits<double>::infinity(), 2.0}) {
    SdfGridOptions options;
    options.faces = true;
    options.band = band;
    set_simd_level(SimdLevel::portable);
    const SdfGrid portable = sdf_grid(md, grid, options);
    for (const SimdLevel level : {SimdLevel::avx2, SimdLevel::avx512}) {
      if (level > best_simd_level()) continue;
      set_simd_level(level);
      const SdfGrid r = sdf_grid(md, grid, options);
      EXPECT_EQ(r.distance.data, portable.distance.data) << simd_level_name(level);
      EXPECT_EQ(r.faces, portable.faces) << simd_level_name(level);
      EXPECT_EQ(r.stats.in_band, portable.stats.in_band);
    }
  }
}

TEST(SdfGrid, NarrowBandEqualsTheWholeGridInside) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const Grid3Geometry grid = sdf_grid_geometry(bunny.bounds(), 48, 0, 3);
  const SdfGrid whole = sdf_grid(bunny, grid);
  SdfGridOptions options;
  options.band = 2.5;
  const SdfGrid band = sdf_grid(bunny, grid, options);
  const float w = 2.5f * grid.spacing.x();
  std::size_t in = 0;
  for (std::size_t s = 0; s < whole.distance.size(); ++s) {
    const float d = whole.distance.data[s], b = band.distance.data[s];
    if (std::abs(d) <= w) {
      ASSERT_EQ(d, b) << s;
      ++in;
    } else {
      ASSERT_TRUE(std::isinf(b)) << s;
      ASSERT_EQ(d < 0, b < 0) << s;
    }
  }
  EXPECT_EQ(in, band.stats.in_band);
  EXPECT_GT(band.stats.tiles_outside, 0u);
}

TEST(SdfGrid, PropagationIsAnUpperBoundExactOnTheShell) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const MeshDistance md = MeshDistance::build(bunny);
  const Grid3Geometry grid = sdf_grid_geometry(bunny.bounds(), 48, 0, 4);
  SdfGridOptions options;
  options.sign = SignMethod::pseudonormal;
  options.faces = true;
  const SdfGrid exact = sdf_grid(md, grid, options);
  options.method = SdfMethod::propagation;
  const SdfGrid approx = sdf_grid(md, grid, options);
  const float h = grid.spacing.x(), tol = 1e-5f;
  double worst = 0;
  std::size_t off = 0;
  for (std::size_t s = 0; s < exact.distance.size(); ++s) {
    const float e = exact.distance.data[s], a = approx.distance.data[s];
    ASSERT_GE(std::abs(a), std::abs(e) - tol) << s;  // never below
    if (std::abs(e) <= 1.7f * h) {
      ASSERT_NEAR(a, e, tol) << s;  // the shell is exact
    }
    if (std::abs(e) > tol) {
      ASSERT_EQ(a < 0, e < 0) << s;  // the same side
    }
    worst = std::max(worst, double(std::abs(a) - std::abs(e)) / h);
    off += std::abs(a) > std::abs(e) + tol;
  }
  EXPECT_GT(off, 0u);      // an approximation
  EXPECT_LT(worst, 1.5);   // docs/field.md: at most 1.1 samples measured on the sdf workload
  options.band = 2;
  EXPECT_THROW(sdf_grid(md, grid, options), Error);
}

TEST(SignedDistance, PointsMatchBruteForceWithFeatures) {
  const TriMesh bunny = test::data_mesh("bunny.ply");
  Rng rng(7);
  const AABB3f box = bunny.bounds();
  std::vector<Vec3f> points;
  for (int i = 0; i < 200; ++i) {
    Vec3f p;
    for (int a = 0; a < 3; ++a) p[a] = float(rng.uniform(box.lo[a] - 1, box.hi[a] + 1));
    points.push_back(p);
  }
  // Points on vertices and edges too.
  points.push_back(bunny.vertices[bunny.triangles[5][1]]);
  points.push_back(0.5f * (bunny.vertices[bunny.triangles[9][0]] + bunny.vertices[bunny.triangles[9][1]]));
  std::vector<Brute> brute;
  std::vector<int> inside;
  for (const Vec3f& p : points) {
    brute.push_back(brute_distance(bunny, p));
    inside.push_back(brute.back().distance > 1e-3 ? ray_inside(bunny, p) : -1);
  }
  for (const SignMethod sign : {SignMethod::winding, SignMethod::pseudonormal, SignMethod::none}) {
    const std::vector<MeshPointDistance> r = signed_distance(bunny, points, sign);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Brute& b = brute[i];
      const double tol = 2e-6 * (mesh_size(bunny) + 10);
      ASSERT_NEAR(std::abs(r[i].distance), b.distance, tol) << i;
      ASSERT_NEAR((r[i].closest - points[i]).norm(), b.distance, tol) << i;
      if (sign == SignMethod::none) {
        ASSERT_GE(r[i].distance, 0) << i;
      } else if (inside[i] >= 0) {
        ASSERT_EQ(r[i].distance < 0, inside[i] == 1) << i;
      }
      // The feature holds the closest point: the vertex itself, a point of the edge, inside the face.
      const std::uint32_t f = r[i].face;
      const Vec3d q = r[i].closest.cast<double>();
      if (r[i].feature == Feature::vertex) {
        ASSERT_EQ(r[i].closest, bunny.vertices[r[i].feature_index]) << i;
        ASSERT_TRUE(bunny.triangles[f][0] == r[i].feature_index || bunny.triangles[f][1] == r[i].feature_index ||
                    bunny.triangles[f][2] == r[i].feature_index) << i;
      } else if (r[i].feature == Feature::edge) {
        const int e = int(r[i].feature_index);
        const Vec3d a = corner(bunny, f, e), c = corner(bunny, f, (e + 1) % 3);
        ASSERT_NEAR(((q - a).cross(c - a)).norm() / (c - a).norm(), 0.0, 1e-5) << i;
      } else {
        ASSERT_EQ(r[i].feature_index, f);
        const Vec3d w = barycentric(q, corner(bunny, f, 0), corner(bunny, f, 1), corner(bunny, f, 2));
        ASSERT_GT(w.minCoeff(), -1e-5) << i;
      }
    }
  }
}

TEST(SignedDistance, OpenMeshHasASensibleInside) {
  // The bunny with a hole: winding numbers still call its deep inside inside,
  // and far outside outside.
  TriMesh open = test::data_mesh("bunny.ply");
  const TriMesh closed = open;
  open.triangles.erase(open.triangles.begin() + 100, open.triangles.begin() + 130);
  const MeshDistance md = MeshDistance::build(open);
  EXPECT_FALSE(md.closed());
  const MeshDistance mc = MeshDistance::build(closed);
  const Grid3Geometry grid = sdf_grid_geometry(open.bounds(), 24, 0, 2);
  const SdfGrid g = sdf_grid(md, grid);
  const SdfGrid c = sdf_grid(mc, grid);
  std::size_t deep = 0;
  for (std::size_t s = 0; s < g.distance.size(); ++s) {
    if (std::abs(c.distance.data[s]) < 0.1f * float(mesh_size(open))) continue;  // away from the hole
    ASSERT_EQ(g.distance.data[s] < 0, c.distance.data[s] < 0) << s;
    deep += c.distance.data[s] < 0;
  }
  EXPECT_GT(deep, 0u);
  // Every sample's sign is its winding number's (no propagation across an open mesh).
  for (std::size_t s = 0; s < g.distance.size(); s += 7) {
    const Vec3f p = grid.position(s % grid.dims[0], s / grid.dims[0] % grid.dims[1], s / (grid.dims[0] * grid.dims[1]));
    if (g.distance.data[s] != 0) {
      ASSERT_EQ(g.distance.data[s] < 0, md.winding_number(p) > 0.5) << s;
    }
  }
}

TEST(MeshDistance, InsideByWindingIsTheWindingNumbersSide) {
  // Its polynomial arctangent must never change the side: on grids over the closed bunny
  // and the bunny with a hole, and at the centroids of the hole's missing faces (winding
  // numbers near 1/2, where the exact sum decides).
  TriMesh open = test::data_mesh("bunny.ply");
  const TriMesh closed = open;
  std::vector<Vec3f> points;
  for (std::size_t t = 100; t < 130; ++t) {
    const auto& f = open.triangles[t];
    points.push_back((open.vertices[f[0]] + open.vertices[f[1]] + open.vertices[f[2]]) / 3);
  }
  open.triangles.erase(open.triangles.begin() + 100, open.triangles.begin() + 130);
  const Grid3Geometry grid = sdf_grid_geometry(open.bounds(), 20, 0, 2);
  for (std::size_t s = 0; s < grid.dims[0] * grid.dims[1] * grid.dims[2]; ++s)
    points.push_back(grid.position(s % grid.dims[0], s / grid.dims[0] % grid.dims[1], s / (grid.dims[0] * grid.dims[1])));
  std::size_t near_half = 0;
  for (const TriMesh* m : {static_cast<const TriMesh*>(&open), &closed}) {
    const MeshDistance md = MeshDistance::build(*m);
    for (const Vec3f& p : points) {
      const double w = md.winding_number(p);
      ASSERT_EQ(md.inside_by_winding(p), w > 0.5) << p.transpose() << " w = " << w;
      near_half += std::abs(w - 0.5) < 0.25;
    }
  }
  EXPECT_GT(near_half, 0u);
  // On a lone triangle, inside it (w = +-1/2 exactly: the exact sum decides) and beside it.
  TriMesh one;
  one.vertices = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  one.triangles = {{0, 1, 2}};
  const MeshDistance md = MeshDistance::build(one);
  for (const Vec3f& p : {Vec3f(0.25f, 0.25f, 0), Vec3f(2, 2, 0), Vec3f(0.25f, 0.25f, 1e-30f), Vec3f(0.25f, 0.25f, -1e-30f)})
    EXPECT_EQ(md.inside_by_winding(p), md.winding_number(p) > 0.5) << p.transpose();
}

TEST(SdfGrid, DegenerateAndDuplicatedFaces) {
  // A cube with unwelded corners (each face its own vertices), a degenerate
  // face (a segment) and a point face, and a duplicated face.
  const TriMesh c = cube();
  TriMesh m;
  for (const auto& t : c.triangles) {
    const auto base = std::uint32_t(m.vertices.size());
    for (int i = 0; i < 3; ++i) m.vertices.push_back(c.vertices[t[i]]);
    m.triangles.push_back({base, base + 1, base + 2});
  }
  m.vertices.push_back(Vec3f(0.5f, 0.5f, 2));
  m.vertices.push_back(Vec3f(0.5f, 0.5f, 3));
  const auto n = std::uint32_t(m.vertices.size());
  m.triangles.push_back({n - 2, n - 1, n - 1});  // a segment above the cube
  m.triangles.push_back({n - 2, n - 2, n - 2});  // a point
  const MeshDistance md = MeshDistance::build(m);
  EXPECT_TRUE(md.closed());  // welded, the cube is closed; the degenerate faces add no boundary
  Grid3Geometry grid;
  grid.dims = {9, 10, 17};
  grid.origin = Vec3f(-1.7f, -1.6f, -1.9f);
  grid.spacing = Vec3f(0.41f, 0.37f, 0.33f);
  expect_grid(m, grid, {SignMethod::winding, SignMethod::pseudonormal}, true);
  const SdfGrid g = sdf_grid(md, grid);
  EXPECT_LT(g.distance(4, 4, 5), 0);  // (-0.06, -0.12, -0.25): inside the cube
}

TEST(SdfGrid, GeometryFromResolutionOrSpacing) {
  const AABB3f box(Vec3f(-1, -0.5f, 0), Vec3f(1, 0.5f, 0.25f));
  const Grid3Geometry g = sdf_grid_geometry(box, 64, 0, 4);
  EXPECT_EQ(g.dims[0], 64u);
  EXPECT_NEAR(g.spacing.x(), 2.0 / 56, 1e-7);
  EXPECT_EQ(g.dims[1], 36u);  // 1 / h = 28, plus 8
  // Centred: the first and last samples are as far from the box.
  EXPECT_NEAR(g.origin.x() + g.position(63, 0, 0).x(), 0.0, 1e-6);
  const Grid3Geometry s = sdf_grid_geometry(box, 0, 0.1, 1);
  EXPECT_EQ(s.dims[0], 22u);
  EXPECT_EQ(s.dims[2], 5u);  // ceil(2.5 + 2)
}

// Within the module's float range (mesh_distance.hpp: coordinates within
// +-2^30, a mesh spanning at least 2^-24) the field of a mesh and grid scaled
// by a power of two is the unit-scale field, scaled, bit for bit; outside,
// meshes, query points and grids are refused. (The plane distance of the grid
// kernels squared a term of degree 3 and gave wrong distances and 2 % wrong
// signs from 2^24 and below 2^-20, silently.)
TEST(SdfGrid, PowerOfTwoScalesGiveTheUnitScaleFieldOrAreRefused) {
  const TriMesh bunny = test::data_mesh("bunny.ply");  // coordinates up to 10
  const Grid3Geometry unit_grid = sdf_grid_geometry(bunny.bounds(), 20, 0, 2);
  for (const SignMethod sign : {SignMethod::winding, SignMethod::pseudonormal}) {
    SdfGridOptions options;
    options.sign = sign;
    const SdfGrid unit = sdf_grid(MeshDistance::build(bunny), unit_grid, options);
    for (int e : {-20, -8, 8, 24}) {
      TriMesh m = bunny;
      for (Vec3f& v : m.vertices) v = Vec3f(std::ldexp(v[0], e), std::ldexp(v[1], e), std::ldexp(v[2], e));
      Grid3Geometry grid = unit_grid;
      for (int a = 0; a < 3; ++a) {
        grid.origin[a] = std::ldexp(grid.origin[a], e);
        grid.spacing[a] = std::ldexp(grid.spacing[a], e);
      }
      const SdfGrid scaled = sdf_grid(MeshDistance::build(m), grid, options);
      for (std::size_t i = 0; i < unit.distance.size(); ++i)
        ASSERT_EQ(scaled.distance.data[i], std::ldexp(unit.distance.data[i], e)) << "2^" << e << " sample " << i;
    }
  }
  for (int e : {28, -28}) {  // 10 x 2^28 is beyond 2^30; 10 x 2^-28 spans less than 2^-24
    TriMesh m = bunny;
    for (Vec3f& v : m.vertices) v = Vec3f(std::ldexp(v[0], e), std::ldexp(v[1], e), std::ldexp(v[2], e));
    EXPECT_THROW(MeshDistance::build(m), Error) << e;
  }
  const MeshDistance md = MeshDistance::build(bunny);
  EXPECT_THROW(md.query(Vec3f(0, std::ldexp(1.0f, 31), 0)), Error);
  Grid3Geometry far = unit_grid;
  far.origin[0] = std::ldexp(1.0f, 31);
  EXPECT_THROW(sdf_grid(md, far), Error);
}

TEST(SdfGrid, BadInputIsRefused) {
  const TriMesh c = cube();
  EXPECT_THROW(MeshDistance::build(TriMesh{}), Error);
  TriMesh nan = c;
  nan.vertices[3].x() = std::nanf("");
  EXPECT_THROW(MeshDistance::build(nan), Error);
  TriMesh bad_index = c;
  bad_index.triangles[0][1] = 99;
  EXPECT_THROW(MeshDistance::build(bad_index), Error);
  const MeshDistance md = MeshDistance::build(c);
  EXPECT_THROW(md.query(Vec3f(0, std::nanf(""), 0)), Error);
  const std::vector<Vec3f> points{Vec3f(0, 0, 0), Vec3f(INFINITY, 0, 0)};
  EXPECT_THROW(signed_distance(md, points), Error);
  Grid3Geometry grid;
  grid.dims = {4, 4, 4};
  grid.spacing = Vec3f(1, 0, 1);
  EXPECT_THROW(sdf_grid(md, grid), Error);
  grid.spacing = Vec3f(1, std::nanf(""), 1);
  EXPECT_THROW(sdf_grid(md, grid), Error);
  grid.spacing = Vec3f(1, 1, 1);
  SdfGridOptions options;
  options.band = -1;
  EXPECT_THROW(sdf_grid(md, grid, options), Error);
  // Far more samples than any machine's memory: refused before allocating.
  grid.dims = {100000, 100000, 100000};
  try {
    sdf_grid(md, grid);
    FAIL() << "no error for 10^15 samples";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("GB"), std::string::npos) << e.what();
  }
  EXPECT_THROW(sdf_grid_geometry(AABB3f(), 32), Error);
  EXPECT_THROW(sdf_grid_geometry(c.bounds(), 6, 0, 3), Error);
  EXPECT_THROW(sdf_grid_geometry(c.bounds(), 0, -1, 3), Error);
  EXPECT_THROW(sdf_grid_geometry(c.bounds(), 0, 1e-9, 3), Error);  // 2e9 samples along each axis
}

}  // namespace
}  // namespace geods::field
