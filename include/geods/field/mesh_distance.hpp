#pragma once
// The exact signed distance of a triangle mesh (seed §6, Definition 5):
// D(p) = sgn(p) min_{q in S} |p - q|, negative inside, with the closest
// point q, the closest face and which feature of it (vertex, edge or face)
// holds q: the vector distance field of the seed, sampled at any points.
//
// The unsigned part is a closest-point query on a bounding volume hierarchy
// (bvh::TriangleBvh). The sign is chosen by SignMethod:
// - winding: the generalized winding number w(p) (Jacobson et al. 2013),
//   inside where w > 1/2. It is the sum over the triangles of their solid
//   angles seen from p over 4 pi: 1 inside and 0 outside a closed outward
//   oriented mesh, and a sensible in-between for open meshes, holes and
//   overlaps. Computed hierarchically (Barill et al. 2018): a node of the
//   hierarchy seen from farther than 2 x its radius contributes the solid
//   angle of its dipole (its area-weighted normal at its centroid), nearer
//   nodes are opened down to the triangles' exact solid angles (Van
//   Oosterom and Strackee, in double). The dipole's error at that distance
//   is a few hundredths, far below the 1/2 that would change a sign.
// - pseudonormal: the side of the closest feature's angle-weighted
//   pseudonormal (Baerentzen and Aanaes 2005): the face normal, the sum of
//   the two face normals at an edge, the angle-weighted sum at a vertex.
//   Correct on closed, consistently oriented manifold meshes, and cheap (no
//   second traversal); on open meshes its inside is wherever the nearest
//   face looks away.
// - none: unsigned distances.
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "geods/bvh/traversal.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/core/triangle.hpp"

namespace geods::field {

/// No face or vertex (the type's maximum, as everywhere in geods).
inline constexpr std::uint32_t kNoIndex = std::numeric_limits<std::uint32_t>::max();

enum class SignMethod : std::uint8_t { winding, pseudonormal, none };

/// The feature of the closest face that holds the closest point.
enum class Feature : std::uint8_t { vertex, edge, face };

/// "winding", "pseudonormal", "none"; geods::Error naming the choices otherwise.
SignMethod parse_sign_method(std::string_view name);
std::string_view to_string(SignMethod sign);
std::string_view to_string(Feature feature);

/// Distance of one point to the mesh.
struct MeshPointDistance {
  float distance = std::numeric_limits<float>::infinity();  // signed (negative inside) unless SignMethod::none
  Vec3f closest = Vec3f::Zero();                           // closest point of the mesh
  std::uint32_t face = kNoIndex;                // closest face (kNoIndex: empty mesh)
  Feature feature = Feature::face;
  /// With feature vertex: the mesh vertex; edge: the face's edge 0, 1 or 2
  /// (from corner i to corner i + 1 mod 3); face: the face.
  std::uint32_t feature_index = kNoIndex;
};

/// The coordinates at which the module's float distances answer as at unit
/// scale (the fields of an input scaled by a power of two are those of the
/// unit-scale input, scaled; measured on the bunny from 2^-28 to 2^32): the
/// closest point's barycentric terms are of degree 4 in coordinate
/// differences, which overflow from 2^32 (coordinates within +-2^30 differ by
/// at most 2^31), and the mesh must span at least 2^-24 for its triangles'
/// terms to stay normal floats. Meshes, query points and grids outside are
/// refused (geods::Error).
inline constexpr float kDistanceCoordinateLimit = power_of_two<float>(30);
inline constexpr float kDistanceExtentFloor = power_of_two<float>(-24);

/// Everything the signed distance of one mesh needs, built once: the
/// hierarchy, the pseudonormals and the winding-number moments of its nodes.
/// Queries are const and thread-safe.
class MeshDistance {
 public:
  MeshDistance() = default;

  /// Builds over `mesh` (its own TriangleBvh with `options`). Throws
  /// geods::Error for an invalid mesh (indices out of range, NaN or infinite
  /// coordinates, coordinates beyond kDistanceCoordinateLimit or a span below
  /// kDistanceExtentFloor) or a mesh without faces. Degenerate faces are kept: they are
  /// points or segments of the surface, with no area and no normal.
  /// Time O(n log n).
  static MeshDistance build(const TriMesh& mesh, const bvh::BuildOptions& options = {});

  /// Distance, closest point, face and feature of p (finite and within
  /// kDistanceCoordinateLimit, else geods::Error).
  /// max_distance bounds the search: a point farther than that from the mesh
  /// gets distance +-infinity and no face. The sign costs a winding-number
  /// traversal with SignMethod::winding.
  MeshPointDistance query(const Vec3f& p, SignMethod sign = SignMethod::winding,
                          float max_distance = std::numeric_limits<float>::infinity()) const;
  /// The generalized winding number at p: the solid angle the mesh covers
  /// seen from p over 4 pi (1 inside a closed outward mesh, 0 outside).
  double winding_number(const Vec3f& p) const;
  /// winding_number(p) > 0.5, the same answer at less cost: the triangles' solid
  /// angles by a polynomial arctangent, the exact sum only where its error bound
  /// does not settle the answer.
  bool inside_by_winding(const Vec3f& p) const;
  /// Whether p is inside by the pseudonormal of the closest feature `q`
  /// (a result of query()); false on the surface.
  bool inside_by_pseudonormal(const Vec3f& p, const MeshPointDistance& q) const;
  /// Whether every edge is used as often in one direction as in the other
  /// (after welding vertices at equal positions): the winding number is then
  /// an integer off the surface and changes only across it.
  bool closed() const { return closed_; }

  const bvh::TriangleBvh& bvh() const { return bvh_; }
  /// Entries a TraversalStack needs for a traversal of bvh().
  std::size_t stack_size() const { return bvh::traversal_stack_size(depth_, bvh_.options().arity); }
  std::size_t num_faces() const { return faces_.size(); }
  /// The hierarchy's triangles in leaf order; leaf triangle i is face face_of(i) of the mesh.
  const FlatArray<bvh::BvhTriangle>& triangles() const { return bvh_.triangles(); }
  std::uint32_t face_of(std::uint32_t leaf) const { return bvh_.triangle_ids()[leaf]; }

  /// The feature of face `face` (a mesh face) for a region of the face's
  /// corners in mesh order, and its index (see MeshPointDistance).
  void feature_of(std::uint32_t face, TriangleRegion region, Feature& feature, std::uint32_t& index) const;
  /// The pseudonormal (not unit) of a feature of a face.
  Vec3f pseudonormal(std::uint32_t face, TriangleRegion region) const;

 private:
  // Per topology node: its dipole (area-weighted normal sum, centroid) and the
  // radius of the ball about the centroid that holds its triangles.
  struct Moment {
    Vec3d normal_area = Vec3d::Zero();
    Vec3d centroid = Vec3d::Zero();
    double radius = 0;
  };
  void fit_normals(const TriMesh& mesh);
  void fit_moments();
  // The solid angle the mesh covers seen from p, each triangle's by `angle`
  // (winding_number's traversal); `triangles` counts those.
  template <class Angle>
  double solid_angle_sum(const Vec3f& p, const Angle& angle, std::size_t& triangles) const;

  bvh::TriangleBvh bvh_;
  std::vector<TriMesh::Triangle> faces_;       // the mesh's faces (vertex indices)
  std::vector<Vec3f> face_normals_;            // unit (zero for degenerate faces)
  std::vector<Vec3f> edge_normals_;            // 3 per face: edge i from corner i to i + 1
  std::vector<Vec3f> vertex_normals_;          // per mesh vertex: angle-weighted (welded copies share)
  std::vector<Moment> moments_;                // per topology node
  int depth_ = 0;                              // of the hierarchy
  bool closed_ = false;
};

/// Signed distances of `points` to the mesh: per point its distance,
/// closest point, face and feature (in the order of `points`). Parallel and
/// deterministic. Throws geods::Error for a non-finite point.
std::vector<MeshPointDistance> signed_distance(const MeshDistance& mesh, std::span<const Vec3f> points,
                                               SignMethod sign = SignMethod::winding);
/// The same, building the MeshDistance of `mesh` first.
std::vector<MeshPointDistance> signed_distance(const TriMesh& mesh, std::span<const Vec3f> points,
                                               SignMethod sign = SignMethod::winding);

}  // namespace geods::field
