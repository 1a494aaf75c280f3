#pragma once
// An indexed triangle mesh: vertex positions and triangles as vertex-index triples.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "geods/core/aabb.hpp"

namespace geods {

/// What TriMesh::validate() found. Counts are exact; the examples name the
/// first few offending elements so a message can point at them.
struct MeshReport {
  std::size_t out_of_range_indices = 0;  // triangle corners >= number of vertices
  std::size_t non_finite_vertices = 0;   // a NaN or infinite coordinate
  std::size_t degenerate_faces = 0;      // a repeated corner index or zero area
  std::size_t duplicate_faces = 0;       // same vertex set as an earlier face (any order)
  std::size_t non_manifold_edges = 0;    // undirected edges used by more than two faces
  std::size_t boundary_edges = 0;        // undirected edges used by exactly one face
  std::size_t inconsistent_edges = 0;    // manifold edges whose two faces traverse it the same way
  std::vector<std::string> examples;     // "face 12: corner 3 out of range", ... (at most 16)

  /// Usable as a mesh at all: indices in range and coordinates finite.
  bool valid() const { return out_of_range_indices == 0 && non_finite_vertices == 0; }
  /// A closed, consistently oriented 2-manifold without degenerate or duplicate faces.
  bool closed_manifold() const {
    return valid() && degenerate_faces == 0 && duplicate_faces == 0 && non_manifold_edges == 0 &&
           boundary_edges == 0 && inconsistent_edges == 0;
  }
  /// One line per kind of problem found ("3 boundary edges"), empty if none.
  std::vector<std::string> problems() const;
};

struct TriMesh {
  using Triangle = std::array<std::uint32_t, 3>;

  std::vector<Vec3f> vertices;
  std::vector<Triangle> triangles;
  std::vector<Vec3f> normals;  // per-vertex normals; empty or one per vertex

  std::size_t num_vertices() const { return vertices.size(); }
  std::size_t num_triangles() const { return triangles.size(); }

  /// Bounds of all vertices (also unreferenced ones); empty box for no vertices.
  AABB3f bounds() const;
  /// Checks indices, coordinates, faces and edge topology; O(n log n).
  MeshReport validate() const;
  /// Throws geods::Error naming `what` unless validate().valid() holds.
  void require_valid(const std::string& what) const;
  /// Signed volume enclosed (positive for an outward-oriented closed mesh).
  double signed_volume() const;
  double surface_area() const;
};

}  // namespace geods
