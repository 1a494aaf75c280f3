// Delaunay3 against independent oracles: a brute-force exact empty-sphere test
// over all vertices, the convex hull's volume (core's Quickhull), Euler's
// formula for a triangulated ball, and the uniqueness that the symbolic
// perturbation promises (the same tetrahedra whatever the insertion order).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <vector>

#include "geods/core/convex_hull3.hpp"
#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/delaunay3.hpp"
#include "../../src/voronoi/delaunay3_mesh.hpp"

namespace geods::voronoi {
namespace {

enum class Shape3 { uniform, clustered, sphere, lattice, coplanar, duplicates, tiny, huge, mixed };

std::vector<Vec3d> make_points(Shape3 shape, std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3d> p;
  switch (shape) {
    case Shape3::uniform:
      for (std::size_t i = 0; i < n; ++i) p.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
      break;
    case Shape3::clustered:
      for (std::size_t i = 0; i < n; ++i) {
        const double s = i % 10 == 0 ? 1.0 : 1e-4;
        const double c = double(rng.below(5));
        p.emplace_back(c + s * rng.normal(), c * 0.5 + s * rng.normal(), s * rng.normal());
      }
      break;
    case Shape3::sphere:  // every integer point on the sphere of radius 15: cospherical, coplanar and cocircular sets
      for (int x = -15; x <= 15; ++x)
        for (int y = -15; y <= 15; ++y)
          for (int z = -15; z <= 15; ++z)
            if (x * x + y * y + z * z == 225) p.emplace_back(x, y, z);
      p.emplace_back(0, 0, 0);
      break;
    case Shape3::lattice:  // 6 x 7 x 8 integer grid, shuffled: degenerate everywhere
      for (int x = 0; x < 6; ++x)
        for (int y = 0; y < 7; ++y)
          for (int z = 0; z < 8; ++z) p.emplace_back(x, y, z);
      for (std::size_t i = p.size(); i > 1; --i) std::swap(p[i - 1], p[rng.below(i)]);
      break;
    case Shape3::coplanar:  // most points on three planes (two axis-aligned, one skew), a few off them
      for (std::size_t i = 0; i < n; ++i) {
        const double a = double(rng.below(20)), b = double(rng.below(20));
        switch (i % 4) {
          case 0: p.emplace_back(a, b, 0.0); break;
          case 1: p.emplace_back(a, 0.0, b); break;
          case 2: p.emplace_back(a, b, a + b); break;
          default: p.emplace_back(rng.uniform(0, 20), rng.uniform(0, 20), rng.uniform(0, 20)); break;
        }
      }
      break;
    case Shape3::duplicates: {
      std::vector<Vec3d> base;
      for (int i = 0; i < 60; ++i) base.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
      for (std::size_t i = 0; i < n; ++i) p.push_back(base[rng.below(base.size())]);
      break;
    }
    case Shape3::tiny:
      for (std::size_t i = 0; i < n; ++i) p.emplace_back(1e-300 * rng.uniform(), 1e-300 * rng.uniform(), 1e-300 * rng.uniform());
      break;
    case Shape3::huge:
      for (std::size_t i = 0; i < n; ++i)
        p.emplace_back(1e300 * rng.uniform(-1, 1), 1e300 * rng.uniform(-1, 1), 1e300 * rng.uniform(-1, 1));
      break;
    case Shape3::mixed:
      for (std::size_t i = 0; i < n; ++i) {
        const double s = std::ldexp(1.0, int(rng.below(200)) - 100);
        p.emplace_back(s * rng.uniform(-1, 1), s * rng.uniform(-1, 1), s * rng.uniform(-1, 1));
      }
      break;
  }
  return p;
}

const Shape3 kShapes3[] = {Shape3::uniform, Shape3::clustered, Shape3::sphere, Shape3::lattice, Shape3::coplanar,
                           Shape3::duplicates, Shape3::tiny, Shape3::huge, Shape3::mixed};

double signed_volume(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

// The facts every tetrahedralization of a solid set must show.
void check_solid(const std::vector<Vec3d>& p, const Delaunay3& dt) {
  ASSERT_NO_THROW(dt.validate());
  ASSERT_EQ(dt.dimension(), 3);
  const auto& tets = dt.tetrahedra();
  const std::size_t m = dt.tetrahedron_count();
  // Every distinct point is a vertex; representatives are first occurrences of equal points.
  std::set<std::array<double, 3>> distinct;
  std::set<std::uint32_t> used(tets.begin(), tets.end());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool fresh = distinct.insert({p[i][0], p[i][1], p[i][2]}).second;
    const std::uint32_t r = dt.representative(std::uint32_t(i));
    EXPECT_EQ(fresh, r == i) << "point " << i;
    EXPECT_TRUE(p[r] == p[i]);
    if (fresh) {
      EXPECT_TRUE(used.count(std::uint32_t(i))) << "point " << i << " is not a vertex";
    }
  }
  EXPECT_EQ(used.size(), distinct.size());
  EXPECT_EQ(dt.duplicate_count(), p.size() - distinct.size());
  // Positive orientation (exact) and the volumes add up to the hull's,
  // computed on the points scaled by a power of two to about unit size.
  double largest = 0;
  for (const Vec3d& q : p) largest = std::max(largest, q.cwiseAbs().maxCoeff());
  const double unit = largest > 0 ? std::ldexp(1.0, -std::ilogb(largest)) : 1.0;
  std::vector<Vec3d> scaled;
  for (const Vec3d& q : p) scaled.push_back(q * unit);
  double volume = 0, scale = 0;
  for (std::size_t t = 0; t < m; ++t) {
    ASSERT_LT(orient3d(p[tets[4 * t]], p[tets[4 * t + 1]], p[tets[4 * t + 2]], p[tets[4 * t + 3]]), 0)
        << "tetrahedron " << t;
  }
  for (std::size_t t = 0; t < m; ++t) {
    const Vec3d &a = scaled[tets[4 * t]], &b = scaled[tets[4 * t + 1]], &c = scaled[tets[4 * t + 2]], &d = scaled[tets[4 * t + 3]];
    volume += signed_volume(a, b, c, d);
    scale += std::abs(signed_volume(a, b, c, d));
  }
  const ConvexHull3 hull = convex_hull3(p);
  const Vec3d origin = scaled[hull.vertices[0]];
  double hull_volume = 0;
  for (const auto& f : hull.faces) hull_volume += signed_volume(origin, scaled[f[0]], scaled[f[1]], scaled[f[2]]);
  EXPECT_NEAR(volume, hull_volume, 1e-10 * scale);
  // The hull triangles, outward, enclose the same volume; every hull corner is on them.
  const auto triangles = dt.hull();
  double hull_of_dt = 0;
  std::set<std::uint32_t> on_hull;
  for (const auto& f : triangles) {
    hull_of_dt += signed_volume(origin, scaled[f[0]], scaled[f[1]], scaled[f[2]]);
    on_hull.insert(f.begin(), f.end());
  }
  EXPECT_NEAR(hull_of_dt, hull_volume, 1e-10 * scale);
  for (std::uint32_t v : hull.vertices) EXPECT_TRUE(on_hull.count(dt.representative(v))) << "hull corner " << v;
  // Neighbours share faces; no_index exactly on the hull triangles.
  std::size_t open = 0;
  const std::vector<std::uint32_t> neighbors = dt.neighbors();
  ASSERT_EQ(neighbors.size(), tets.size());
  for (std::size_t t = 0; t < m; ++t)
    for (int f = 0; f < 4; ++f) {
      const std::uint32_t u = neighbors[4 * t + f];
      if (u == Delaunay3::no_index) {
        ++open;
        continue;
      }
      std::vector<std::uint32_t> mine, theirs(&tets[4 * std::size_t(u)], &tets[4 * std::size_t(u)] + 4);
      for (int k = 0; k < 4; ++k)
        if (k != f) mine.push_back(tets[4 * t + k]);
      for (std::uint32_t v : mine) EXPECT_TRUE(std::count(theirs.begin(), theirs.end(), v)) << "tetrahedron " << t;
    }
  EXPECT_EQ(open, triangles.size());
  // Euler's formula for a triangulated ball: V - E + F - T = 1.
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t t = 0; t < m; ++t)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        edges.insert(std::minmax(tets[4 * t + i], tets[4 * t + j]));
      }
  const std::size_t faces = (4 * m + triangles.size()) / 2;
  EXPECT_EQ(std::int64_t(used.size()) - std::int64_t(edges.size()) + std::int64_t(faces) - std::int64_t(m), 1);
}

// Brute force: no vertex strictly inside any tetrahedron's circumsphere (exact insphere).
void check_empty_spheres(const Delaunay3& dt) {
  const auto p = dt.points();
  std::vector<std::uint32_t> vertices;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (dt.representative(std::uint32_t(i)) == i) vertices.push_back(std::uint32_t(i));
  const auto& tets = dt.tetrahedra();
  for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t) {
    const Vec3d &a = p[tets[4 * t]], &b = p[tets[4 * t + 1]], &c = p[tets[4 * t + 2]], &d = p[tets[4 * t + 3]];
    for (std::uint32_t v : vertices)
      // orient3d(a, b, c, d) < 0, so insphere > 0 means outside
      ASSERT_GE(insphere(a, b, c, d, p[v]), 0) << "vertex " << v << " inside the sphere of tetrahedron " << t;
  }
}

std::vector<std::array<std::uint32_t, 4>> sorted_tets(const Delaunay3& dt) {
  std::vector<std::array<std::uint32_t, 4>> out;
  for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t) {
    std::array<std::uint32_t, 4> q;
    std::copy_n(&dt.tetrahedra()[4 * t], 4, q.begin());
    std::sort(q.begin(), q.end());
    out.push_back(q);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Delaunay3, EmptySphereOnEveryShape) {
  for (Shape3 shape : kShapes3)
    for (std::uint64_t seed : {1, 2}) {
      SCOPED_TRACE("shape " + std::to_string(int(shape)) + " seed " + std::to_string(seed));
      // Far from unit size every predicate takes core's big-integer path: fewer points there.
      const bool extreme = shape == Shape3::tiny || shape == Shape3::huge || shape == Shape3::mixed;
      const auto p = make_points(shape, extreme ? 50 : 400, seed);
      const Delaunay3 dt(p);
      check_solid(p, dt);
      check_empty_spheres(dt);
    }
}

TEST(Delaunay3, UniqueWhateverTheInsertionOrder) {
  // The perturbation makes the tetrahedralization of degenerate sets unique:
  // other seeds (other BRIO orders) give the same tetrahedra.
  for (Shape3 shape : {Shape3::sphere, Shape3::lattice, Shape3::coplanar, Shape3::duplicates}) {
    SCOPED_TRACE("shape " + std::to_string(int(shape)));
    const auto p = make_points(shape, 300, 7);
    const auto reference = sorted_tets(Delaunay3(p));
    for (std::uint64_t seed : {11, 12, 13}) EXPECT_EQ(sorted_tets(Delaunay3(p, {.seed = seed})), reference);
  }
}

TEST(Delaunay3, LargerUniformAndClusteredValidate) {
  for (Shape3 shape : {Shape3::uniform, Shape3::clustered}) {
    const auto p = make_points(shape, 6000, 3);
    const Delaunay3 dt(p);
    check_solid(p, dt);
    // about 6.5 tetrahedra per point for uniform points
    if (shape == Shape3::uniform) {
      EXPECT_GT(dt.tetrahedron_count(), 6 * p.size());
      EXPECT_LT(dt.tetrahedron_count(), 7 * p.size());
    }
  }
}

TEST(Delaunay3, LowerDimensionalSets) {
  EXPECT_EQ(Delaunay3().dimension(), -1);
  EXPECT_EQ(Delaunay3(std::vector<Vec3d>{}).dimension(), -1);
  const std::vector<Vec3d> one = {{1, 2, 3}, {1, 2, 3}};
  const std::vector<Vec3d> line = {{0, 0, 0}, {1, 1, 1}, {3, 3, 3}, {1, 1, 1}, {-2, -2, -2}};
  const std::vector<Vec3d> plane = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {5, 7, 1}, {0, 0, 1}, {3, 3, 1}};
  const std::vector<Vec3d> three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (const auto* set : {&one, &line, &plane, &three}) {
    const Delaunay3 dt(*set);
    EXPECT_TRUE(dt.tetrahedra().empty());
    EXPECT_TRUE(dt.hull().empty());
    EXPECT_NO_THROW(dt.validate());
  }
  EXPECT_EQ(Delaunay3(one).dimension(), 0);
  EXPECT_EQ(Delaunay3(one).duplicate_count(), 1u);
  EXPECT_EQ(Delaunay3(line).dimension(), 1);
  EXPECT_EQ(Delaunay3(line).representative(3), 1u);
  EXPECT_EQ(Delaunay3(plane).dimension(), 2);
  EXPECT_EQ(Delaunay3(plane).duplicate_count(), 1u);
  EXPECT_EQ(Delaunay3(three).dimension(), 2);
  // Four points not coplanar: one tetrahedron, positive.
  const std::vector<Vec3d> four = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}};
  const Delaunay3 dt(four);
  EXPECT_EQ(dt.dimension(), 3);
  check_solid(four, dt);
  EXPECT_EQ(dt.tetrahedron_count(), 1u);
  EXPECT_EQ(dt.hull().size(), 4u);
}

TEST(Delaunay3, RejectsNonFinitePoints) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (double bad : {nan, inf, -inf}) {
    const std::vector<Vec3d> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, bad}};
    EXPECT_THROW(Delaunay3{p}, Error);
  }
}

TEST(Delaunay3, StatsCountWhatIsThere) {
  const auto p = make_points(Shape3::duplicates, 500, 5);
  const Delaunay3 dt(p);
  const Delaunay3Stats s = dt.stats();
  EXPECT_EQ(s.points, p.size());
  EXPECT_EQ(s.vertices + s.duplicates, p.size());
  EXPECT_EQ(s.duplicates, dt.duplicate_count());
  EXPECT_EQ(s.tetrahedra, dt.tetrahedron_count());
  EXPECT_EQ(s.hull_triangles, dt.hull().size());
  EXPECT_EQ(s.dimension, 3u);
  EXPECT_GT(s.bytes, s.tetrahedra * 32);
}

TEST(Delaunay3, LocateAndNearestVertexAgreeWithBruteForce) {
  for (Shape3 shape : {Shape3::uniform, Shape3::lattice, Shape3::duplicates}) {
    const auto p = make_points(shape, 500, 9);
    const Delaunay3 dt(p);
    Rng rng(4);
    const auto& tets = dt.tetrahedra();
    for (int k = 0; k < 200; ++k) {
      const Vec3d q(rng.uniform(-0.2, 1.2) * 7, rng.uniform(-0.2, 1.2) * 7, rng.uniform(-0.2, 1.2) * 7);
      const Vec3d scaled = shape == Shape3::lattice ? q : q / 7.0;
      // locate: the tetrahedron holds q (exact orientations), or q is outside the hull
      const std::uint32_t t = dt.locate(scaled);
      bool inside_hull = true;
      for (const auto& f : dt.hull())
        if (orient3d(p[f[0]], p[f[1]], p[f[2]], scaled) < 0) inside_hull = false;  // beyond an outward face
      ASSERT_EQ(t != Delaunay3::no_index, inside_hull) << "query " << k;
      if (t != Delaunay3::no_index) {
        const Vec3d* v[4] = {&p[tets[4 * t]], &p[tets[4 * t + 1]], &p[tets[4 * t + 2]], &p[tets[4 * t + 3]]};
        for (int f = 0; f < 4; ++f) {
          const Vec3d* w[4] = {v[0], v[1], v[2], v[3]};
          w[f] = &scaled;
          EXPECT_LE(orient3d(*w[0], *w[1], *w[2], *w[3]), 0) << "query " << k << " face " << f;
        }
      }
      // nearest_vertex: as close as the closest point
      double best = INFINITY;
      for (const Vec3d& x : p) best = std::min(best, (x - scaled).squaredNorm());
      const std::uint32_t n = dt.nearest_vertex(scaled);
      ASSERT_NE(n, Delaunay3::no_index);
      EXPECT_EQ(dt.representative(n), n);
      EXPECT_EQ((p[n] - scaled).squaredNorm(), best) << "query " << k;
    }
  }
}

TEST(Delaunay3, InsertAndRemoveGiveTheTetrahedralizationOfTheSet) {
  auto p = make_points(Shape3::lattice, 0, 21);
  std::vector<Vec3d> first(p.begin(), p.begin() + 150), rest(p.begin() + 150, p.end());
  Delaunay3 dt(first);
  for (const Vec3d& x : rest) dt.insert(x);
  dt.insert(p[3]);  // a duplicate
  std::vector<Vec3d> all = first;
  all.insert(all.end(), rest.begin(), rest.end());
  all.push_back(p[3]);
  ASSERT_NO_THROW(dt.validate());
  EXPECT_EQ(sorted_tets(dt), sorted_tets(Delaunay3(all)));
  EXPECT_EQ(dt.representative(std::uint32_t(all.size() - 1)), 3u);
  // Remove the first copy of p[3]: its duplicate stands for it; remove some others.
  dt.remove(3);
  EXPECT_EQ(dt.representative(3), Delaunay3::no_index);
  EXPECT_EQ(dt.representative(std::uint32_t(all.size() - 1)), std::uint32_t(all.size() - 1));
  for (std::uint32_t i : {0u, 10u, 200u}) dt.remove(i);
  ASSERT_NO_THROW(dt.validate());
  EXPECT_EQ(dt.stats().removed, 4u);
  EXPECT_THROW(dt.remove(10), Error);
  EXPECT_THROW(dt.remove(100000), Error);
  // The same tetrahedra as a fresh build of what is left (compared by coordinates).
  std::vector<Vec3d> left;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (i != 3 && i != 0 && i != 10 && i != 200) left.push_back(all[i]);
  const Delaunay3 fresh(left);
  EXPECT_EQ(fresh.tetrahedron_count(), dt.tetrahedron_count());
  // Inserting into a lower-dimensional set lifts it.
  Delaunay3 flat(std::vector<Vec3d>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  EXPECT_EQ(flat.dimension(), 2);
  flat.insert(Vec3d(0, 0, 1));
  EXPECT_EQ(flat.dimension(), 3);
  EXPECT_EQ(flat.tetrahedron_count(), 1u);
  EXPECT_THROW(flat.insert(Vec3d(0, NAN, 1)), Error);
}

// Removal is local (the star refilled from its link's tetrahedralization):
// after every step the result is the fresh tetrahedralization of the points
// left, compared by original point indices, on every shape.
TEST(Delaunay3, LocalRemovalEqualsAFreshBuildOnEveryShape) {
  for (Shape3 shape : kShapes3) {
    SCOPED_TRACE("shape " + std::to_string(int(shape)));
    const auto p = make_points(shape, 240, 7);
    Delaunay3 dt(p);
    if (dt.dimension() < 3) continue;
    Rng rng(99);
    std::vector<std::uint8_t> gone(p.size(), 0);
    for (int step = 0; step < 60; ++step) {
      std::uint32_t i;
      do {
        i = std::uint32_t(rng.below(p.size()));
      } while (gone[i]);
      gone[i] = 1;
      dt.remove(i);
      if (step % 15 != 14) continue;
      ASSERT_NO_THROW(dt.validate());
      std::vector<Vec3d> left;
      std::vector<std::uint32_t> original;
      for (std::uint32_t k = 0; k < p.size(); ++k)
        if (!gone[k]) left.push_back(p[k]), original.push_back(k);
      const Delaunay3 fresh(left);
      auto expected = sorted_tets(fresh);
      for (auto& t : expected) {
        for (auto& v : t) v = original[v];
        std::sort(t.begin(), t.end());
      }
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(sorted_tets(dt), expected);
      for (std::uint32_t k = 0; k < left.size(); ++k)
        EXPECT_EQ(dt.representative(original[k]), original[fresh.representative(k)]);
    }
    // Only a hull vertex with coplanar neighbours (the integer sphere has some) needs a rebuild.
    if (shape != Shape3::sphere) {
      EXPECT_EQ(dt.stats().rebuilds, 0u);
    }
  }
}

// The parallel build (two halves and a seam) gives the sequential build's
// arrays exactly, on every shape, with the split forced on small inputs.
// Coordinates whose squares leave double range (1e300, 1e-300) build sequentially.
TEST(Delaunay3, ParallelBuildEqualsTheSequentialOne) {
  const int threads = num_threads();
  for (Shape3 shape : kShapes3) {
    SCOPED_TRACE("shape " + std::to_string(int(shape)));
    const bool extreme = shape == Shape3::tiny || shape == Shape3::huge;
    const auto p = make_points(shape, extreme ? 300 : 2000, 9);
    set_num_threads(1);
    const Delaunay3 sequential(p);
    set_num_threads(2);
    const Delaunay3 parallel(p, {.parallel_from = 16});
    set_num_threads(threads);
    if (extreme) {
      EXPECT_EQ(parallel.stats().seam_points, 0u);
    } else {
      EXPECT_GT(parallel.stats().seam_points, 0u);
    }
    EXPECT_EQ(sequential.stats().seam_points, 0u);
    ASSERT_NO_THROW(parallel.validate());
    EXPECT_EQ(parallel.tetrahedra(), sequential.tetrahedra());
    EXPECT_EQ(parallel.neighbors(), sequential.neighbors());
    for (std::uint32_t i = 0; i < p.size(); ++i) EXPECT_EQ(parallel.representative(i), sequential.representative(i));
    // The documented canonical order: each tetrahedron starts at its smallest
    // vertex, then the smallest of the other three; strictly ascending.
    const std::vector<std::uint32_t>& t = sequential.tetrahedra();
    for (std::size_t k = 0; k < t.size(); k += 4) {
      ASSERT_LT(t[k], std::min({t[k + 1], t[k + 2], t[k + 3]})) << "tetrahedron " << k / 4;
      ASSERT_LT(t[k + 1], std::min(t[k + 2], t[k + 3])) << "tetrahedron " << k / 4;
      if (k > 0) {
        ASSERT_TRUE(std::lexicographical_compare(&t[k - 4], &t[k], &t[k], &t[k + 4])) << "tetrahedron " << k / 4;
      }
    }
  }
}

TEST(Delaunay3, SaveLoadRoundTripAndBadFiles) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "geods_delaunay3_test";
  std::filesystem::create_directories(dir);
  auto p = make_points(Shape3::duplicates, 300, 4);
  Delaunay3 dt(p);
  dt.remove(5);
  dt.save(dir / "dt.geods");
  Delaunay3 loaded = Delaunay3::load(dir / "dt.geods");
  EXPECT_EQ(loaded.tetrahedra(), dt.tetrahedra());
  EXPECT_EQ(loaded.neighbors(), dt.neighbors());
  EXPECT_EQ(loaded.representative(5), Delaunay3::no_index);
  EXPECT_EQ(loaded.nearest_vertex(Vec3d(0.5, 0.5, 0.5)), dt.nearest_vertex(Vec3d(0.5, 0.5, 0.5)));
  // Updates go on as on the saved structure.
  loaded.insert(Vec3d(0.25, 0.5, 0.75));
  dt.insert(Vec3d(0.25, 0.5, 0.75));
  EXPECT_EQ(sorted_tets(loaded), sorted_tets(dt));
  // A lower-dimensional set round-trips too.
  Delaunay3(std::vector<Vec3d>{{0, 0, 0}, {1, 1, 1}}).save(dir / "line.geods");
  EXPECT_EQ(Delaunay3::load(dir / "line.geods").dimension(), 1);
  // Truncated and missing files, another kind.
  const auto size = std::filesystem::file_size(dir / "dt.geods");
  std::filesystem::copy_file(dir / "dt.geods", dir / "cut.geods", std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(dir / "cut.geods", size / 2);
  EXPECT_THROW(Delaunay3::load(dir / "cut.geods"), Error);
  EXPECT_THROW(Delaunay3::load(dir / "missing.geods"), Error);
  std::filesystem::remove_all(dir);
}

TEST(Delaunay3, VertexNeighborsAreTheEdges) {
  const auto p = make_points(Shape3::uniform, 300, 2);
  const Delaunay3 dt(p);
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  const auto& tets = dt.tetrahedra();
  for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (i != j) edges.insert({tets[4 * t + i], tets[4 * t + j]});
  for (std::uint32_t v = 0; v < p.size(); ++v)
    for (std::uint32_t w : dt.vertex_neighbors(v)) EXPECT_TRUE(edges.count({v, w}));
  std::size_t total = 0;
  for (std::uint32_t v = 0; v < p.size(); ++v) total += dt.vertex_neighbors(v).size();
  EXPECT_EQ(total, edges.size());
}

// Flip-based insertion (1-4, 2-3, 3-2, 4-4) reaches the cavity insertion's
// tetrahedralization: the same canonical arrays on every shape (cospherical,
// lattice, coplanar-heavy and duplicate-heavy sets included), and the exact
// empty-sphere check; every point the first four do not span is inserted by
// exactly one 1-4, split or hull step.
TEST(Delaunay3, FlipInsertionEqualsTheCavityInsertionOnEveryShape) {
  const int threads = num_threads();
  set_num_threads(1);
  for (Shape3 shape : kShapes3)
    for (std::uint64_t seed : {1, 2}) {
      SCOPED_TRACE("shape " + std::to_string(int(shape)) + " seed " + std::to_string(seed));
      const bool extreme = shape == Shape3::tiny || shape == Shape3::huge || shape == Shape3::mixed;
      const auto p = make_points(shape, extreme ? 50 : 400, seed);
      const Delaunay3 cavity(p, {.seed = seed});
      const Delaunay3 flips(p, {.insertion = Delaunay3Insertion::flips, .seed = seed});
      check_solid(p, flips);
      if (!extreme) check_empty_spheres(flips);
      EXPECT_EQ(flips.tetrahedra(), cavity.tetrahedra());
      EXPECT_EQ(flips.neighbors(), cavity.neighbors());
      for (std::uint32_t i = 0; i < p.size(); ++i) EXPECT_EQ(flips.representative(i), cavity.representative(i));
      const Delaunay3Stats s = flips.stats(), c = cavity.stats();
      EXPECT_EQ(s.flips_14 + s.splits + s.hull_inserts, s.vertices - 4);
      EXPECT_EQ(s.duplicates, c.duplicates);
      EXPECT_EQ(c.flips_14 + c.flips_23 + c.flips_32 + c.splits + c.hull_inserts, 0u);
      EXPECT_EQ(s.flip_repairs, 0u);
      if (shape == Shape3::uniform) {
        EXPECT_GT(s.flips_23, s.vertices);
        EXPECT_GT(s.flips_32, 0u);
      }
      if (shape == Shape3::lattice || shape == Shape3::coplanar) {
        EXPECT_GT(s.splits + s.flips_44, 0u);
      }
    }
  set_num_threads(threads);
}

// The flip insertion's repair step (a cavity step from the new point's star
// when a link face is still not Delaunay after the flips): never needed on the
// shapes above, so reached here by stopping the flips early, after `budget`
// flips per insertion (0: the 1-4 split or hull join only). From any such
// state the tetrahedra without the point are tetrahedra of the old
// triangulation, the star of the point covers only tetrahedra in conflict
// with it, and the repair must end at the same tetrahedralization as the
// cavity insertion (compared as sets of oriented tetrahedra).
TEST(Delaunay3, FlipRepairFinishesFromAnyStateOfTheFlips) {
  for (Shape3 shape : {Shape3::uniform, Shape3::sphere, Shape3::lattice, Shape3::coplanar})
    for (std::size_t budget : {0, 1, 3}) {
      SCOPED_TRACE("shape " + std::to_string(int(shape)) + " budget " + std::to_string(budget));
      const auto p = make_points(shape, 200, 5);
      const Delaunay3 cavity(p);
      // The points in an order whose first four span a solid, inserted one by one.
      std::vector<Vec3d> coords(p.begin(), p.end());
      for (std::size_t k = 3; k < coords.size() && orient3d(coords[0], coords[1], coords[2], coords[3]) == 0; ++k)
        std::swap(coords[3], coords[k]);
      for (std::size_t k = 2; k < coords.size() && orient3d(coords[0], coords[1], coords[2], coords[3]) == 0; ++k)
        std::swap(coords[2], coords[k]);
      ASSERT_NE(orient3d(coords[0], coords[1], coords[2], coords[3]), 0);
      std::vector<std::uint32_t> tets, free_slots;
      Tet3Mesh mesh(coords, tets, free_slots);
      mesh.flips = true;
      mesh.flip_budget = budget;
      mesh.make_first(0, 1, 2, 3);
      std::size_t merged = 0;
      for (std::uint32_t k = 4; k < coords.size(); ++k) merged += mesh.insert(k) != Tet3Mesh::kNone;
      EXPECT_EQ(merged, cavity.duplicate_count());
      EXPECT_GT(mesh.flip_counts[Tet3Mesh::flip_repair], 0u);
      // Both as sets of tetrahedra over coordinates, each rotated to an even
      // permutation starting at its lexicographically smallest corner.
      using Tet = std::array<std::array<double, 3>, 4>;
      const auto canonical = [](std::array<Vec3d, 4> v) {
        const auto key = [](const Vec3d& a) { return std::array<double, 3>{a[0], a[1], a[2]}; };
        const int m = int(std::min_element(v.begin(), v.end(), [&](const Vec3d& a, const Vec3d& b) { return key(a) < key(b); }) - v.begin());
        static constexpr int kEven[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
        Tet t;
        for (int i = 0; i < 4; ++i) t[i] = key(v[kEven[m][i]]);
        // the three after the first: rotate so that the smallest is second (a rotation is even)
        const int r = int(std::min_element(t.begin() + 1, t.end()) - t.begin()) - 1;
        std::rotate(t.begin() + 1, t.begin() + 1 + r, t.end());
        return t;
      };
      std::set<Tet> by_flips, by_cavity;
      for (std::size_t s = 0; s < tets.size() / 8; ++s) {
        const std::uint32_t* v = &tets[8 * s];
        if (((v[0] | v[1] | v[2] | v[3]) & Tet3Mesh::kGhostBit) != 0) continue;
        ASSERT_GT(Tet3Mesh::orient(coords[v[0]], coords[v[1]], coords[v[2]], coords[v[3]]), 0);
        by_flips.insert(canonical({coords[v[0]], coords[v[1]], coords[v[2]], coords[v[3]]}));
      }
      const auto& t = cavity.tetrahedra();
      for (std::size_t k = 0; k < t.size(); k += 4)
        by_cavity.insert(canonical({p[t[k]], p[t[k + 1]], p[t[k + 2]], p[t[k + 3]]}));
      EXPECT_EQ(by_flips.size(), cavity.tetrahedron_count());
      EXPECT_TRUE(by_flips == by_cavity);
    }
}

// Single-point insert() by flips, and the parallel build's halves and seam by flips.
TEST(Delaunay3, FlipInsertOneByOneAndInParallel) {
  for (Shape3 shape : {Shape3::uniform, Shape3::lattice, Shape3::sphere, Shape3::duplicates}) {
    SCOPED_TRACE("shape " + std::to_string(int(shape)));
    const auto p = make_points(shape, 300, 5);
    const std::size_t half = p.size() / 2;
    Delaunay3 dt(std::vector<Vec3d>(p.begin(), p.begin() + std::ptrdiff_t(half)),
                 {.insertion = Delaunay3Insertion::flips});
    for (std::size_t i = half; i < p.size(); ++i) dt.insert(p[i]);
    ASSERT_NO_THROW(dt.validate());
    EXPECT_GT(dt.stats().flips_14 + dt.stats().splits + dt.stats().hull_inserts, 0u);
    const Delaunay3 whole(p);
    EXPECT_EQ(sorted_tets(dt), sorted_tets(whole));
    // A saved flip build goes on inserting by flips after load.
    const std::filesystem::path file = std::filesystem::temp_directory_path() / "geods_delaunay3_flips_test.geods";
    Delaunay3(std::vector<Vec3d>(p.begin(), p.end() - 1), {.insertion = Delaunay3Insertion::flips}).save(file);
    Delaunay3 loaded = Delaunay3::load(file);
    std::filesystem::remove(file);
    const Delaunay3Stats before = loaded.stats();
    loaded.insert(p.back());
    const Delaunay3Stats after = loaded.stats();
    if (whole.representative(std::uint32_t(p.size() - 1)) == p.size() - 1) {
      EXPECT_EQ(after.flips_14 + after.splits + after.hull_inserts, before.flips_14 + before.splits + before.hull_inserts + 1);
    }
    EXPECT_EQ(loaded.tetrahedra().size(), whole.tetrahedra().size());
    for (std::uint32_t i = 0; i < p.size(); ++i) EXPECT_EQ(dt.representative(i), whole.representative(i));
    const int threads = num_threads();
    set_num_threads(2);
    const Delaunay3 parallel(p, {.insertion = Delaunay3Insertion::flips, .parallel_from = 16});
    set_num_threads(threads);
    EXPECT_EQ(parallel.tetrahedra(), whole.tetrahedra());
  }
}

}  // namespace
}  // namespace geods::voronoi
