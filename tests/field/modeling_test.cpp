// Modeling with distance fields (seed §6.2.2): the CSG operators of the
// seed's table against the point membership of their inputs, offsets of a
// sphere field against the sphere of the offset radius, blends against their
// defining properties, and the surfaces by marching cubes.
#include <gtest/gtest.h>

#include <cmath>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/modeling.hpp"
#include "geods/field/sdf_grid.hpp"

namespace geods::field {
namespace {

Grid3<float> sphere_field(const Grid3Geometry& g, const Vec3d& c, double r) {
  Grid3<float> f;
  static_cast<Grid3Geometry&>(f) = g;
  f.data.resize(g.dims[0] * g.dims[1] * g.dims[2]);
  for (std::size_t k = 0; k < g.dims[2]; ++k)
    for (std::size_t j = 0; j < g.dims[1]; ++j)
      for (std::size_t i = 0; i < g.dims[0]; ++i)
        f(i, j, k) = float((g.position(i, j, k).cast<double>() - c).norm() - r);
  return f;
}

Grid3Geometry cube_grid(std::size_t n, double lo, double hi) {
  Grid3Geometry g;
  g.dims = {n, n, n};
  g.origin = Vec3f::Constant(float(lo));
  g.spacing = Vec3f::Constant(float((hi - lo) / double(n - 1)));
  return g;
}

bool member(bool a, bool b, CsgOp op) {
  return op == CsgOp::union_ ? a || b : op == CsgOp::intersection ? a && b : a && !b;
}

TEST(Modeling, CsgAgreesWithMembershipOfTheMeshes) {
  // The bunny and a sphere through it, their exact fields on one grid; at random points
  // farther than a cell's diagonal from both surfaces, the sign of the interpolated
  // result is the Boolean of the meshes' own insides (exact signed distances, not the grids).
  const TriMesh bunny = test::data_mesh("bunny.ply");
  const MeshDistance md = MeshDistance::build(bunny);
  const Grid3Geometry g = sdf_grid_geometry(bunny.bounds(), 28);
  const Grid3<float> object = sdf_grid(md, g).distance;
  const AABB3f box = bunny.bounds();
  const Vec3d centre = ((box.lo + box.hi) / 2).cast<double>() + Vec3d(0.3, 0.2, 0.1).cwiseProduct((box.hi - box.lo).cast<double>());
  const double radius = 0.3 * (box.hi - box.lo).norm();
  const Grid3<float> tool = sphere_field(g, centre, radius);
  const double diagonal = g.spacing.cast<double>().norm();
  Rng rng(5);
  std::vector<Vec3f> points;
  for (int i = 0; i < 4000; ++i) {
    Vec3f p;
    for (int a = 0; a < 3; ++a) p[a] = float(rng.uniform(g.bounds().lo[a], g.bounds().hi[a]));
    points.push_back(p);
  }
  const std::vector<MeshPointDistance> exact = signed_distance(md, points);
  for (const CsgOp op : {CsgOp::union_, CsgOp::intersection, CsgOp::difference}) {
    const Grid3<float> result = csg(object, tool, op);
    std::size_t checked = 0, in = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double ds = (points[i].cast<double>() - centre).norm() - radius;
      if (std::abs(exact[i].distance) <= diagonal || std::abs(ds) <= diagonal) continue;
      const bool expected = member(exact[i].distance < 0, ds < 0, op);
      EXPECT_EQ(sample_trilinear(result.view(), points[i].cast<double>()) < 0, expected) << to_string(op) << " " << i;
      ++checked, in += expected;
    }
    EXPECT_GT(checked, 2000u);
    EXPECT_GT(in, 20u) << to_string(op);
    // The seed's operators sample by sample.
    for (std::size_t s = 0; s < result.size(); s += 97) {
      const float a = object.data[s], b = tool.data[s];
      const float expected = op == CsgOp::union_ ? std::min(a, b) : op == CsgOp::intersection ? std::max(a, b) : std::max(a, -b);
      EXPECT_EQ(result.data[s], expected);
    }
  }
  // Difference is intersection with the complement; union and intersection commute.
  EXPECT_EQ(csg(object, tool, CsgOp::union_).data, csg(tool, object, CsgOp::union_).data);
  Grid3<float> complement = tool;
  for (float& v : complement.data) v = -v;
  EXPECT_EQ(csg(object, tool, CsgOp::difference).data, csg(object, complement, CsgOp::intersection).data);
}

TEST(Modeling, OffsetOfASphereIsASphereOfTheOffsetRadius) {
  const Grid3Geometry g = cube_grid(41, -2, 2);
  const Vec3d c(0.05, -0.1, 0.02);
  const Grid3<float> sphere = sphere_field(g, c, 1.0);
  const double h = g.spacing.x();
  for (const double r : {0.5, -0.4, 0.0}) {
    const TriMesh m = field_surface(offset(sphere, r));
    ASSERT_GT(m.num_triangles(), 100u);
    EXPECT_TRUE(m.validate().closed_manifold());
    for (const Vec3f& v : m.vertices) EXPECT_NEAR((v.cast<double>() - c).norm(), 1.0 + r, h * h / (2 * (1 + r)));  // linear interpolation's sagitta
    // Outward: the enclosed volume is positive and near the ball's.
    EXPECT_NEAR(m.signed_volume(), 4.0 / 3.0 * M_PI * std::pow(1 + r, 3), 0.03 * std::pow(1 + r, 3) * 4);
  }
  // field_surface at a level is the offset's zero set.
  EXPECT_EQ(field_surface(sphere, 0.5).vertices.size(), field_surface(offset(sphere, 0.5)).vertices.size());
}

TEST(Modeling, BlendsRoundTheCreaseAndKeepTheRest) {
  const Grid3Geometry g = cube_grid(33, -2, 2);
  const Grid3<float> a = sphere_field(g, Vec3d(-0.5, 0, 0), 0.8), b = sphere_field(g, Vec3d(0.5, 0, 0), 0.8);
  const double r = 0.4;
  const Grid3<float> smooth = blend(a, b, r);
  const Grid3<float> sharp = csg(a, b, CsgOp::union_);
  for (std::size_t i = 0; i < smooth.size(); ++i) {
    const double diff = std::abs(double(a.data[i]) - double(b.data[i]));
    EXPECT_LE(smooth.data[i], sharp.data[i]);  // a smooth union only adds material
    EXPECT_GE(smooth.data[i], sharp.data[i] - float(r / 4) - 1e-6f);  // by at most r / 4
    if (diff >= r) {
      EXPECT_EQ(smooth.data[i], sharp.data[i]);  // far from the crease: min itself
    }
  }
  // On the plane between the spheres, where a = b, the fillet is r / 4.
  const std::size_t mid = g.index(16, 16, 16);
  EXPECT_NEAR(smooth.data[mid], sharp.data[mid] - r / 4, 1e-6);
  // The smooth union's surface is closed and holds the sharp one's volume and more.
  const TriMesh s = field_surface(smooth), h = field_surface(sharp);
  EXPECT_TRUE(s.validate().closed_manifold());
  EXPECT_GT(s.signed_volume(), h.signed_volume());
  // Smooth intersection and difference remove material instead.
  const Grid3<float> si = blend(a, b, r, CsgOp::intersection), sd = blend(a, b, r, CsgOp::difference);
  for (std::size_t i = 0; i < si.size(); i += 7) {
    EXPECT_GE(si.data[i], std::max(a.data[i], b.data[i]));
    EXPECT_GE(sd.data[i], std::max(a.data[i], -b.data[i]));
  }
}

TEST(Modeling, TrilinearSampling) {
  const Grid3Geometry g = cube_grid(5, 0, 4);
  Grid3<float> f;
  static_cast<Grid3Geometry&>(f) = g;
  f.data.resize(125);
  for (std::size_t k = 0; k < 5; ++k)
    for (std::size_t j = 0; j < 5; ++j)
      for (std::size_t i = 0; i < 5; ++i) f(i, j, k) = float(double(i) + 2.0 * double(j) - 3.0 * double(k));  // affine: reproduced exactly
  Rng rng(1);
  for (int n = 0; n < 100; ++n) {
    const Vec3d p(rng.uniform(0, 4), rng.uniform(0, 4), rng.uniform(0, 4));
    EXPECT_NEAR(sample_trilinear(f.view(), p), p.x() + 2 * p.y() - 3 * p.z(), 1e-9);
  }
  EXPECT_EQ(sample_trilinear(f.view(), Vec3d(-5, 0, 0)), 0.0);  // clamped to the box
  EXPECT_EQ(sample_trilinear(f.view(), Vec3d(4, 4, 4)), 4.0 + 8 - 12);
}

TEST(Modeling, BadInput) {
  const Grid3Geometry g = cube_grid(5, 0, 1), h = cube_grid(6, 0, 1);
  const Grid3<float> a = sphere_field(g, Vec3d::Zero(), 0.5), b = sphere_field(h, Vec3d::Zero(), 0.5);
  EXPECT_THROW(csg(a, b, CsgOp::union_), Error);  // different grids
  Grid3<float> moved = a;
  moved.origin.x() += 0.1f;
  EXPECT_THROW(csg(a, moved, CsgOp::union_), Error);
  Grid3<float> nan = a;
  nan.data[3] = std::nanf("");
  EXPECT_THROW(csg(a, nan, CsgOp::union_), Error);
  EXPECT_THROW(offset(nan, 1), Error);
  EXPECT_THROW(csg(a, a, CsgOp::union_, -1), Error);
  EXPECT_THROW(blend(a, a, 0), Error);
  EXPECT_THROW(offset(a, INFINITY), Error);
  EXPECT_THROW(parse_csg_op("xor"), Error);
  EXPECT_EQ(parse_csg_op("difference"), CsgOp::difference);
  EXPECT_THROW(field_surface(a, NAN), Error);
  // A narrow band's infinities are clamped for marching cubes.
  Grid3<float> band = sphere_field(cube_grid(21, -2, 2), Vec3d::Zero(), 1);
  for (float& v : band.data)
    if (std::abs(v) > 0.5f) v = std::copysign(INFINITY, v);
  EXPECT_TRUE(field_surface(band).validate().closed_manifold());
}

}  // namespace
}  // namespace geods::field
