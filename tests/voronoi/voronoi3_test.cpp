// Voronoi3 against brute force: the cells' volumes add up to the box, every
// sampled point of the box lies in the cell of its nearest site (found by a
// scan of all sites), centroids lie in their cells.
#include <gtest/gtest.h>

#include <gmpxx.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "../../src/voronoi/exact_compare.hpp"
#include "common/archive_files.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/voronoi/voronoi3.hpp"

namespace geods::voronoi {
namespace {

// q inside the closed cell: on the inner side of every face's plane (its outward
// normal from the loop), within `slack`.
bool in_cell(const Voronoi3Cell& cell, const Vec3d& q, double slack) {
  for (std::size_t f = 0; f < cell.face_count(); ++f) {
    const std::uint32_t* loop = &cell.face_vertices[cell.face_offsets[f]];
    const std::size_t m = cell.face_offsets[f + 1] - cell.face_offsets[f];
    Vec3d normal = Vec3d::Zero();
    for (std::size_t k = 0; k < m; ++k) normal += cell.vertices[loop[k]].cross(cell.vertices[loop[(k + 1) % m]]);
    if (normal.normalized().dot(q - cell.vertices[loop[0]]) > slack) return false;
  }
  return cell.face_count() > 0;
}

void check_partition(const std::vector<Vec3d>& sites, const AABB3d& box, std::uint64_t seed) {
  const Voronoi3 vd(sites, box);
  vd.validate();
  const double box_volume = (box.hi - box.lo).prod();
  EXPECT_NEAR(vd.volume_total(), box_volume, 1e-9 * box_volume);
  Rng rng(seed);
  const double slack = 1e-9 * (box.hi - box.lo).norm();
  for (int k = 0; k < 300; ++k) {
    const Vec3d q(rng.uniform(box.lo[0], box.hi[0]), rng.uniform(box.lo[1], box.hi[1]),
                  rng.uniform(box.lo[2], box.hi[2]));
    std::size_t best = 0;
    for (std::size_t c = 1; c < vd.cells().size(); ++c)
      if ((sites[vd.cells()[c].site] - q).squaredNorm() < (sites[vd.cells()[best].site] - q).squaredNorm()) best = c;
    EXPECT_TRUE(in_cell(vd.cells()[best], q, slack)) << "sample " << k << " nearest site " << vd.cells()[best].site;
  }
  for (const Voronoi3Cell& cell : vd.cells()) {
    if (cell.face_count() == 0) {
      EXPECT_EQ(cell.volume, 0);
      continue;
    }
    EXPECT_GT(cell.volume, 0);
    EXPECT_TRUE(in_cell(cell, cell.centroid, slack));
    // Closed: every edge is used by exactly two faces, once in each direction.
    std::size_t directed = 0, matched = 0;
    for (std::size_t f = 0; f < cell.face_count(); ++f) {
      const std::size_t m = cell.face_offsets[f + 1] - cell.face_offsets[f];
      for (std::size_t e = 0; e < m; ++e) {
        const std::uint32_t a = cell.face_vertices[cell.face_offsets[f] + e];
        const std::uint32_t b = cell.face_vertices[cell.face_offsets[f] + (e + 1) % m];
        ++directed;
        for (std::size_t g = 0; g < cell.face_count(); ++g) {
          const std::size_t n = cell.face_offsets[g + 1] - cell.face_offsets[g];
          for (std::size_t h = 0; h < n; ++h)
            matched += cell.face_vertices[cell.face_offsets[g] + h] == b &&
                       cell.face_vertices[cell.face_offsets[g] + (h + 1) % n] == a;
        }
      }
    }
    EXPECT_EQ(directed, matched) << "cell of site " << cell.site;
  }
}

// The circumcentre of slivers (a corner 1e-9 or 1e-12 off the plane of the
// other three) against rational arithmetic: within 2^-40 of its offset from a
// and of a. (The rounded formula alone was off by up to a tenth of the distance.)
TEST(Voronoi3, CircumcentresOfSliversAreAccurate) {
  Rng rng(51);
  const auto det3 = [](const mpq_class (&m)[3][3]) -> mpq_class {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  for (int i = 0; i < 2000; ++i) {
    const auto random = [&] { return Vec3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)); };
    const Vec3d a = random(), b = random(), c = random();
    const Vec3d d = a + rng.uniform(-1, 1) * (b - a) + rng.uniform(-1, 1) * (c - a) + (i % 2 ? 1e-9 : 1e-12) * random();
    if (orient3d(a.data(), b.data(), c.data(), d.data()) == 0) continue;
    // 2 (p - a) . x = |p - a|^2 for p = b, c, d: x = centre - a, by Cramer's rule.
    mpq_class m[3][3], r[3];
    const Vec3d* corners[3] = {&b, &c, &d};
    for (int k = 0; k < 3; ++k) {
      r[k] = 0;
      for (int j = 0; j < 3; ++j) {
        const mpq_class e = mpq_class((*corners[k])[j]) - mpq_class(a[j]);
        m[k][j] = 2 * e;
        r[k] += e * e;
      }
    }
    const mpq_class det = det3(m);
    const Vec3d got = detail::circumcentre(a, b, c, d);
    double error = 0, size = a.cwiseAbs().maxCoeff(), offset = 0;
    for (int j = 0; j < 3; ++j) {
      mpq_class mj[3][3];
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) mj[k][l] = l == j ? r[k] : m[k][l];
      const mpq_class x = det3(mj) / det;
      error = std::max(error, std::abs(mpq_class(mpq_class(got[j]) - mpq_class(a[j]) - x).get_d()));
      offset = std::max(offset, std::abs(x.get_d()));
    }
    EXPECT_LE(error, std::ldexp(size + offset, -40)) << i;
  }
}

TEST(Voronoi3, CellsPartitionTheBoxAndHoldTheirNearestPoints) {
  Rng rng(3);
  std::vector<Vec3d> uniform;
  for (int i = 0; i < 300; ++i) uniform.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  check_partition(uniform, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)), 1);
  // Sites outside the box still own parts of it.
  check_partition(uniform, AABB3d(Vec3d(0.2, -0.5, 0.3), Vec3d(0.7, 0.5, 1.5)), 2);
  // A lattice with duplicates: cubes of equal volume.
  std::vector<Vec3d> lattice;
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 4; ++y)
      for (int z = 0; z < 4; ++z) lattice.emplace_back(x + 0.5, y + 0.5, z + 0.5);
  lattice.push_back(lattice[5]);
  const AABB3d cube(Vec3d(0, 0, 0), Vec3d(4, 4, 4));
  check_partition(lattice, cube, 3);
  const Voronoi3 vd(lattice, cube);
  EXPECT_EQ(vd.cells().size(), 64u);
  for (const Voronoi3Cell& cell : vd.cells()) {
    EXPECT_NEAR(cell.volume, 1.0, 1e-12);
    EXPECT_NEAR((cell.centroid - lattice[cell.site]).norm(), 0.0, 1e-12);
    EXPECT_EQ(cell.face_count(), 6u);
  }
}

TEST(Voronoi3, LowerDimensionalSitesAndBadBoxes) {
  // Coplanar sites (no tetrahedra): slabs and prisms still partition the box.
  const std::vector<Vec3d> plane = {{0.1, 0.2, 0.5}, {0.8, 0.3, 0.5}, {0.4, 0.9, 0.5}, {0.5, 0.5, 0.5}};
  check_partition(plane, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)), 4);
  const std::vector<Vec3d> one = {{0.3, 0.3, 0.3}};
  const Voronoi3 single(one, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 2, 3)));
  EXPECT_NEAR(single.volume_total(), 6.0, 1e-12);
  EXPECT_THROW(Voronoi3(one, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 0, 1))), Error);
  EXPECT_THROW(Voronoi3(one, AABB3d(Vec3d(0, 0, 0), Vec3d(1, NAN, 1))), Error);
}

// A cell inside the box is the dual of its site's star: its faces are the
// site's Delaunay neighbours, each with a corner per tetrahedron around the
// edge, and every corner is the circumcentre of a tetrahedron around the site,
// the same bits in every cell that has it. Cells at the box keep its faces.
TEST(Voronoi3, CellsAreTheDualOfTheTetrahedra) {
  Rng rng(21);
  std::vector<Vec3d> sites;
  for (int i = 0; i < 600; ++i) sites.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  const Delaunay3 dt(sites);
  const Voronoi3 vd(dt, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)));
  vd.validate();
  const auto& tets = dt.tetrahedra();
  std::size_t interior = 0, at_box = 0;
  for (const Voronoi3Cell& cell : vd.cells()) {
    const std::uint32_t s = cell.site;
    std::vector<Vec3d> centres;  // of the tetrahedra around s
    for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t)
      if (std::find(&tets[4 * t], &tets[4 * t + 4], s) != &tets[4 * t + 4])
        centres.push_back(detail::circumcentre(sites[tets[4 * t]], sites[tets[4 * t + 1]], sites[tets[4 * t + 2]],
                                               sites[tets[4 * t + 3]]));
    const bool inside = std::all_of(centres.begin(), centres.end(), [](const Vec3d& c) {
      return (c.array() > 0.01).all() && (c.array() < 0.99).all();
    });
    if (!inside) {
      at_box += std::any_of(cell.face_neighbors.begin(), cell.face_neighbors.end(), Voronoi3::is_box_side);
      continue;
    }
    ++interior;
    std::vector<std::uint32_t> labels(cell.face_neighbors.begin(), cell.face_neighbors.end());
    std::sort(labels.begin(), labels.end());
    EXPECT_EQ(labels, dt.vertex_neighbors(s)) << "site " << s;
    EXPECT_EQ(cell.vertices.size(), centres.size()) << "site " << s;
    for (const Vec3d& x : cell.vertices)
      EXPECT_NE(std::find(centres.begin(), centres.end(), x), centres.end()) << "site " << s;
    for (std::size_t f = 0; f < cell.face_count(); ++f) {
      std::size_t around = 0;
      for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t)
        around += std::find(&tets[4 * t], &tets[4 * t + 4], s) != &tets[4 * t + 4] &&
                  std::find(&tets[4 * t], &tets[4 * t + 4], cell.face_neighbors[f]) != &tets[4 * t + 4];
      EXPECT_EQ(cell.face_offsets[f + 1] - cell.face_offsets[f], around) << "site " << s;
    }
  }
  EXPECT_GT(interior, 200u);
  EXPECT_GT(at_box, 100u);
}

// Clipped to the convex hull: the cells' volumes add up to the tetrahedra's,
// every corner lies in the hull, samples of the hull lie in their nearest
// site's cell, and cut faces carry hull labels.
TEST(Voronoi3, CellsClippedToTheHullPartitionIt) {
  Rng rng(8);
  std::vector<Vec3d> sets[2];
  for (int i = 0; i < 250; ++i) sets[0].emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  for (int x = 0; x < 4; ++x)  // a lattice: hull faces through many sites, cospherical everywhere
    for (int y = 0; y < 3; ++y)
      for (int z = 0; z < 5; ++z) sets[1].emplace_back(x, y, z);
  for (const auto& sites : sets) {
    const Delaunay3 dt(sites);
    const Voronoi3 vd(dt);
    vd.validate();
    double hull_volume = 0;
    for (std::size_t t = 0; t < dt.tetrahedron_count(); ++t) {
      const std::uint32_t* v = &dt.tetrahedra()[4 * t];
      hull_volume += (sites[v[1]] - sites[v[0]]).dot((sites[v[2]] - sites[v[0]]).cross(sites[v[3]] - sites[v[0]])) / 6;
    }
    EXPECT_NEAR(vd.volume_total(), hull_volume, 1e-9 * hull_volume);
    const auto hull = dt.hull();
    const double slack = 1e-9 * (vd.box().hi - vd.box().lo).norm();
    const auto in_hull = [&](const Vec3d& q) {
      for (const auto& h : hull) {
        const Vec3d n = (sites[h[1]] - sites[h[0]]).cross(sites[h[2]] - sites[h[0]]).normalized();
        if (n.dot(q - sites[h[0]]) > slack) return false;
      }
      return true;
    };
    std::size_t hull_labels = 0;
    for (const Voronoi3Cell& cell : vd.cells()) {
      for (const Vec3d& x : cell.vertices) EXPECT_TRUE(in_hull(x));
      for (const std::uint32_t l : cell.face_neighbors) {
        EXPECT_FALSE(Voronoi3::is_box_side(l));
        if (Voronoi3::is_hull_face(l)) {
          ++hull_labels;
          EXPECT_LT(l & 0x7fffffffu, hull.size());
        }
      }
    }
    EXPECT_GT(hull_labels, 0u);
    for (int k = 0; k < 300; ++k) {
      // a random point of a random tetrahedron
      const std::uint32_t* v = &dt.tetrahedra()[4 * rng.below(dt.tetrahedron_count())];
      double w[4], sum = 0;
      for (double& x : w) sum += (x = rng.uniform());
      Vec3d q = Vec3d::Zero();
      for (int j = 0; j < 4; ++j) q += sites[v[j]] * (w[j] / sum);
      std::size_t best = 0;
      for (std::size_t c = 1; c < vd.cells().size(); ++c)
        if ((sites[vd.cells()[c].site] - q).squaredNorm() < (sites[vd.cells()[best].site] - q).squaredNorm()) best = c;
      EXPECT_TRUE(in_cell(vd.cells()[best], q, slack));
    }
  }
  EXPECT_THROW(Voronoi3(Delaunay3(std::vector<Vec3d>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})), Error);
}


// Lattice points whose hull has coplanar triangles: the second triangle's
// plane, cut in rounding, left a second face on the first (the cell was not closed).
TEST(Voronoi3, CoplanarHullTrianglesCutOnce) {
  const std::vector<Vec3d> p = {{0, 1, 2}, {0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 2, 0},
                                {2, 0, 0}, {1, 0, 2}, {0, 0, 1}, {0, 1, 1}, {0, 2, 2}};
  const Voronoi3 vd{Delaunay3(p)};
  vd.validate();
}

// Corners closer than any tolerance could tell apart: sites 1e-10 of the box
// apart, nearly cospherical (lattice subsets, rows raised by 1 % of the
// spacing), and points on a sphere, whose cells all meet near its centre.
// Merged by coordinates (within 1e-12 of the box), such corners left cells
// open; joined by identity, every cell is closed and validate() passes.
TEST(Voronoi3, CornersCloserThanRoundingKeepCellsClosed) {
  const AABB3d unit(Vec3d(0, 0, 0), Vec3d(1, 1, 1));
  for (int trial = 0; trial < 20; ++trial) {
    Rng rng(std::uint64_t(trial) * 7 + 1);
    std::vector<Vec3d> p;
    const int n = 5 + int(rng.below(25));
    for (int i = 0; i < n; ++i)
      p.emplace_back(0.5 + 1e-10 * double(rng.below(4)), 0.5 + 1e-10 * (double(rng.below(4)) + 0.01 * double(rng.below(3))),
                     0.5 + 1e-10 * double(rng.below(4)));
    const Voronoi3 vd(p, unit);
    vd.validate();
    EXPECT_NEAR(vd.volume_total(), 1.0, 1e-12);
  }
  Rng rng(5);
  std::vector<Vec3d> sphere;
  for (int i = 0; i < 300; ++i) sphere.push_back(Vec3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized());
  Voronoi3(sphere, AABB3d(Vec3d(-2, -2, -2), Vec3d(2, 2, 2))).validate();
  Voronoi3(Delaunay3(sphere)).validate();
}

// Cell volumes are cubic in the coordinates: a power-of-two copy inside that
// range has the volumes scaled exactly (to rounding), 1e300 sites or boxes are refused.
TEST(Voronoi3, ExtremeScalesAreScaledOrRefused) {
  Rng rng(43);
  std::vector<Vec3d> unit;
  for (int i = 0; i < 40; ++i) unit.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  const Voronoi3 reference(unit, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)));
  for (int e : {-280, 330}) {
    std::vector<Vec3d> p = unit;
    for (Vec3d& x : p) x = Vec3d(std::ldexp(x[0], e), std::ldexp(x[1], e), std::ldexp(x[2], e));
    const double s = std::ldexp(1.0, e);
    const Voronoi3 v(p, AABB3d(Vec3d(0, 0, 0), Vec3d(s, s, s)));
    v.validate();
    for (std::size_t i = 0; i < unit.size(); ++i) {
      EXPECT_NEAR(v.cells()[i].volume / (s * s * s), reference.cells()[i].volume, 1e-12) << e;
      // (the centroids' moments, quartic in the coordinates, overflowed at 2^330)
      EXPECT_NEAR((v.cells()[i].centroid / s - reference.cells()[i].centroid).norm(), 0, 1e-12) << e;
    }
  }
  std::vector<Vec3d> far = unit;
  for (Vec3d& x : far) x *= 1e300;
  EXPECT_THROW(Voronoi3(far, AABB3d(Vec3d(0, 0, 0), Vec3d(1e300, 1e300, 1e300))), Error);
  EXPECT_THROW(Voronoi3(unit, AABB3d(Vec3d(-1e200, 0, 0), Vec3d(1, 1, 1))), Error);
}

// Sites 1e-300 apart beside one at (1, 1, 1): the bisector planes were
// the sites' differences, whose products with coordinates near 1e-300
// underflowed to 0; a cell vanished and the others covered 0.77 of the box.
TEST(Voronoi3, SitesCloserThanTheSquareRootOfTheSmallestNormal) {
  for (double gap : {1e-300, 1e-307}) {
    const std::vector<Vec3d> p = {{0, 0, 0}, {gap, 0, 0}, {0, gap, 0}, {0, 0, gap}, {1, 1, 1}};
    const Voronoi3 v(p, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)));
    v.validate();
    EXPECT_NEAR(v.volume_total(), 1.0, 1e-12) << gap;
    // By symmetry the three cells beside the origin are equal: each holds the
    // points nearer to it than to (1, 1, 1) where its axis's coordinate is largest.
    for (int k = 1; k <= 3; ++k) EXPECT_NEAR(v.cells()[k].volume, v.cells()[1].volume, 1e-12) << gap;
    // The origin's own cell is gap-sized (its volume underflows to 0); every cell has faces.
    EXPECT_EQ(v.stats().empty, 0u) << gap;
  }
}

// A box far thinner along one axis than along the others (a slab for
// coplanar sites, as the CLI makes for them): the cells are the prisms of the
// sites' 2D cells, whatever the slab's thickness. Rounding along the long
// axes once merged the slab's two sides (a tolerance scaled by the box's
// diagonal), and atan2 tied the angles of a cap's corners.
TEST(Voronoi3, BoxesThinAlongOneAxisGiveTheCellsOfAnyOtherThickness) {
  Rng rng(47);
  std::vector<Vec3d> unit;
  for (int i = 0; i < 30; ++i) unit.emplace_back(rng.uniform(), rng.uniform(), 0.0);
  const Voronoi3 reference(unit, AABB3d(Vec3d(0, 0, -0.5), Vec3d(1, 1, 0.5)));
  for (const double s : {1e3, 1e17, 1e20, 1e38}) {
    for (const double thickness : {1.0, 1e-3}) {
      std::vector<Vec3d> p = unit;
      for (Vec3d& x : p) x *= s;
      const AABB3d box(Vec3d(0, 0, -thickness / 2), Vec3d(s, s, thickness / 2));
      const Voronoi3 v(p, box);
      v.validate();
      EXPECT_NEAR(v.volume_total() / (s * s * thickness), 1.0, 1e-12) << s << " " << thickness;
      ASSERT_EQ(v.cells().size(), reference.cells().size());
      for (std::size_t i = 0; i < unit.size(); ++i) {
        EXPECT_NEAR(v.cells()[i].volume / (s * s * thickness), reference.cells()[i].volume, 1e-12) << s;
        EXPECT_EQ(v.cells()[i].face_count(), reference.cells()[i].face_count()) << s;
        EXPECT_EQ(v.cells()[i].vertices.size(), reference.cells()[i].vertices.size()) << s;
      }
    }
  }
  // The same sites turned to lie in a plane of each axis: the thin axis may be any.
  for (int axis = 0; axis < 2; ++axis) {
    std::vector<Vec3d> p = unit;
    for (Vec3d& x : p) x = axis == 0 ? Vec3d(0, x[0], x[1]) * 1e20 : Vec3d(x[0], 0, x[1]) * 1e20;
    Vec3d lo(0, 0, 0), hi(1e20, 1e20, 1e20);
    lo[axis] = -0.5, hi[axis] = 0.5;
    const Voronoi3 v(p, AABB3d(lo, hi));
    v.validate();
    for (std::size_t i = 0; i < unit.size(); ++i)
      EXPECT_NEAR(v.cells()[i].volume / 1e40, reference.cells()[i].volume, 1e-12) << axis;
  }
}


void expect_same(const Voronoi3& a, const Voronoi3& b) {
  EXPECT_EQ(a.points(), b.points());
  EXPECT_EQ(a.box().lo, b.box().lo);
  EXPECT_EQ(a.box().hi, b.box().hi);
  EXPECT_EQ(a.hull(), b.hull());
  ASSERT_EQ(a.cells().size(), b.cells().size());
  for (std::size_t c = 0; c < a.cells().size(); ++c) {
    const Voronoi3Cell &x = a.cells()[c], &y = b.cells()[c];
    EXPECT_EQ(x.site, y.site);
    EXPECT_EQ(x.vertices, y.vertices);
    EXPECT_EQ(x.face_offsets, y.face_offsets);
    EXPECT_EQ(x.face_vertices, y.face_vertices);
    EXPECT_EQ(x.face_neighbors, y.face_neighbors);
    EXPECT_EQ(x.volume, y.volume);
    EXPECT_EQ(x.centroid, y.centroid);
  }
}

// Saved and loaded, the cells are the same (clipped to a box, with sites
// outside it, and to the hull); truncated, flipped and wrong-kind files are refused.
TEST(Voronoi3Archive, RoundTripAndBadFiles) {
  Rng rng(61);
  std::vector<Vec3d> sites;
  for (int i = 0; i < 200; ++i) sites.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  const Delaunay3 dt(sites);
  const std::filesystem::path path = test::temp_archive("voronoi3");
  for (const Voronoi3& original : {Voronoi3(dt, AABB3d(Vec3d(0.2, -0.5, 0.3), Vec3d(0.7, 0.5, 1.5))), Voronoi3(dt)}) {
    original.save(path);
    expect_same(original, Voronoi3::load(path));
    expect_same(original, Voronoi3::load(path, Archive::Verify::full));
  }
  test::expect_bad_copies_refused(path, [](const std::filesystem::path& p) { Voronoi3::load(p); });
  EXPECT_THROW(Delaunay3::load(path), Error);  // another kind
  std::filesystem::remove(path);
}

// What validate() sees that the checksums do not: a file whose sections were
// changed after saving, loaded without checksums (Verify::structure_only).
// Each change is one number: a corner moved, a label or corner index changed,
// a volume, a site moved.
TEST(Voronoi3Archive, ChangedCellsAreRefusedByValidate) {
  Rng rng(62);
  std::vector<Vec3d> sites;
  for (int i = 0; i < 100; ++i) sites.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  const Voronoi3 original(sites, AABB3d(Vec3d(0, 0, 0), Vec3d(1, 1, 1)));
  const std::filesystem::path good = test::temp_archive("voronoi3_good"), bad = test::temp_archive("voronoi3_bad");
  original.save(good);
  const std::vector<char> bytes = test::read_bytes(good);
  const Voronoi3Cell& first = original.cells()[0];
  std::uint32_t other_site = 0;  // a site that is not across any face of the first cell
  while (other_site == first.site || std::count(first.face_neighbors.begin(), first.face_neighbors.end(), other_site))
    ++other_site;
  const auto changed = [&](const char* section, std::size_t at, auto value) {
    std::vector<char> copy = bytes;
    std::memcpy(copy.data() + test::archive_section_offset(bytes, section) + at * sizeof(value), &value, sizeof(value));
    test::write_bytes(bad, copy);
    return bad;
  };
  const auto load = [](const std::filesystem::path& p) { Voronoi3::load(p, Archive::Verify::structure_only); };
  load(changed("volumes", 0, first.volume));  // unchanged: the rewrite itself loads
  EXPECT_THROW(load(changed("vertices", 0, first.vertices[0][0] + 1e-3)), Error) << "a corner moved by 1e-3";
  EXPECT_THROW(load(changed("face_neighbors", 0, other_site)), Error) << "a face's label another site";
  EXPECT_THROW(load(changed("face_neighbors", 0, first.site)), Error) << "a face's label its own site";
  EXPECT_THROW(load(changed("face_vertices", 0, first.face_vertices[1])), Error) << "a corner index changed";
  EXPECT_THROW(load(changed("volumes", 0, 2 * first.volume)), Error) << "a volume doubled";
  EXPECT_THROW(load(changed("centroids", 0, first.centroid[0] + 1e-3)), Error) << "a centroid moved";
  EXPECT_THROW(load(changed("points", 3 * first.site, sites[first.site][0] + 0.05)), Error) << "a site moved";
  EXPECT_THROW(load(changed("box", 3, 1.01)), Error) << "a box side moved";
  // With the checksums, a change is refused before any check.
  EXPECT_THROW(Voronoi3::load(changed("volumes", 0, 2 * first.volume)), Error);
  std::filesystem::remove(good);
  std::filesystem::remove(bad);
}

}  // namespace
}  // namespace geods::voronoi
