#include "geods/core/tri_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "geods/core/error.hpp"

namespace geods {
namespace {

// A closed, outward-oriented tetrahedron.
TriMesh tetrahedron() {
  TriMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

TEST(TriMesh, ClosedTetrahedronIsCleanWithPositiveVolume) {
  const TriMesh m = tetrahedron();
  const MeshReport r = m.validate();
  EXPECT_TRUE(r.valid());
  EXPECT_TRUE(r.closed_manifold()) << ::testing::PrintToString(r.problems());
  EXPECT_TRUE(r.problems().empty());
  EXPECT_NEAR(m.signed_volume(), 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(m.surface_area(), 1.5 + std::sqrt(3.0) / 2, 1e-6);
  EXPECT_EQ(m.bounds(), AABB3f(Vec3f::Zero(), Vec3f::Ones()));
}

TEST(TriMesh, OpenBoundaryEdgesAreCounted) {
  TriMesh m = tetrahedron();
  m.triangles.pop_back();
  const MeshReport r = m.validate();
  EXPECT_TRUE(r.valid());
  EXPECT_FALSE(r.closed_manifold());
  EXPECT_EQ(r.boundary_edges, 3u);
}

TEST(TriMesh, OutOfRangeIndicesMakeItInvalid) {
  TriMesh m = tetrahedron();
  m.triangles.push_back({0, 1, 9});
  const MeshReport r = m.validate();
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.out_of_range_indices, 1u);
  ASSERT_FALSE(r.examples.empty());
  EXPECT_NE(r.examples.front().find("face 4"), std::string::npos);
  EXPECT_THROW(m.require_valid("test.ply"), Error);
  try {
    m.require_valid("test.ply");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("test.ply"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("out-of-range"), std::string::npos);
  }
}

TEST(TriMesh, NonFiniteVerticesAreReported) {
  TriMesh m = tetrahedron();
  m.vertices[2].y() = std::numeric_limits<float>::quiet_NaN();
  m.vertices[3].z() = std::numeric_limits<float>::infinity();
  EXPECT_EQ(m.validate().non_finite_vertices, 2u);
  EXPECT_FALSE(m.validate().valid());
}

TEST(TriMesh, DegenerateFacesRepeatedCornersAndZeroArea) {
  TriMesh m = tetrahedron();
  m.vertices.push_back({2, 0, 0});     // 4: collinear with 0 and 1
  m.triangles.push_back({0, 0, 1});    // repeated corner
  m.triangles.push_back({0, 1, 4});    // zero area
  const MeshReport r = m.validate();
  EXPECT_EQ(r.degenerate_faces, 2u);
  EXPECT_TRUE(r.valid());
  EXPECT_FALSE(r.closed_manifold());
}

TEST(TriMesh, DuplicateFacesInAnyOrderAndNonManifoldEdges) {
  TriMesh m = tetrahedron();
  m.triangles.push_back({2, 1, 0});  // same as face 0, rotated
  const MeshReport r = m.validate();
  EXPECT_EQ(r.duplicate_faces, 1u);
  // Edges of face 0 are now used three times.
  EXPECT_EQ(r.non_manifold_edges, 3u);
}

TEST(TriMesh, InconsistentOrientationIsDetected) {
  TriMesh m = tetrahedron();
  std::swap(m.triangles[3][0], m.triangles[3][1]);  // flip one face
  const MeshReport r = m.validate();
  EXPECT_EQ(r.inconsistent_edges, 3u);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_FALSE(r.closed_manifold());
}

TEST(TriMesh, EmptyMeshIsValidAndHasEmptyBounds) {
  const TriMesh m;
  EXPECT_TRUE(m.validate().valid());
  EXPECT_TRUE(m.bounds().empty());
  EXPECT_EQ(m.signed_volume(), 0.0);
}

TEST(TriMesh, TinyButValidTrianglesAreNotDegenerate) {
  TriMesh m;
  m.vertices = {{0, 0, 0}, {1e-20f, 0, 0}, {0, 1e-20f, 0}};
  m.triangles = {{0, 1, 2}};
  EXPECT_EQ(m.validate().degenerate_faces, 0u);
}

}  // namespace
}  // namespace geods
