#pragma once
// Collision detection and proximity between two rigid triangle meshes (seed
// §4.2): each mesh has a bounding volume hierarchy (geods::bvh, any of its
// volumes) and a pose; one free function over a request and a result answers
// "do they touch" (first contact), "which triangle pairs touch" (all
// contacts), and "how far apart, and where" (distance, or whether within a
// tolerance), in the style of Coal/FCL.
//
// The query is the simultaneous traversal of the two hierarchies (traverse(A,
// B) of §4.2, on bvh::traverse): B's volume is carried into A's frame by the
// relative pose once per node pair and tested against A's (AABBs are bounded
// again after the rotation, k-DOPs bound the rotated box of the other side in
// both frames, OBBs use the 15-axis separating test, spheres their centres);
// the rule that says which node of a pair to open is a parameter. Volume
// tests are padded by a relative 1e-9 so that they never reject a pair the
// exact test would accept.
//
// Exactness: the triangle pairs reached are decided by the exact test of
// triangle_pair.hpp on the world coordinates R p + t (double) of both
// triangles, each computed from its own mesh and pose only, so the contacts
// do not depend on the order of the arguments nor on the bounding volume:
// every volume and builder gives the same pairs, equal to testing all pairs.
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/core/vec.hpp"

namespace geods::collide {

inline constexpr std::uint32_t kNoIndex = std::numeric_limits<std::uint32_t>::max();

/// A rigid motion: world point = rotation * model point + translation. The
/// quaternion need not be normalized (it is, in double, when used); a zero or
/// non-finite quaternion or translation is refused with geods::Error.
template <typename T>
struct Pose {
  Eigen::Quaternion<T> rotation = Eigen::Quaternion<T>::Identity();
  Vec<T, 3> translation = Vec<T, 3>::Zero();

  /// From (qw, qx, qy, qz, tx, ty, tz), the row layout of the collide workload.
  static Pose from_row(const T* row) {
    Pose p;
    p.rotation = Eigen::Quaternion<T>(row[0], row[1], row[2], row[3]);
    p.translation = Vec<T, 3>(row[4], row[5], row[6]);
    return p;
  }
};
using Posef = Pose<float>;
using Posed = Pose<double>;

/// The bounding volumes a CollisionMesh can use: those of the bvh module
/// (obb: principal axes, obb_hull: the hull fit) and boxtree, the restricted
/// boxtree of §4.1.5 (Zachmann's Minkowski-volume criterion, AABB volumes),
/// and rss, rectangle swept spheres (bvh/rss.hpp), whose exact distance makes
/// them the tightest bound for distance queries.
enum class CollisionVolume { aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, obb_hull, boxtree, rss };
/// "aabb", ..., "boxtree", "rss"; throws geods::Error otherwise.
CollisionVolume parse_collision_volume(std::string_view name);
std::string_view to_string(CollisionVolume bv);

struct CollisionMeshOptions {
  CollisionVolume bv = CollisionVolume::obb;
  /// Builder of the hierarchy (ignored for boxtree, which is its own builder).
  bvh::Builder builder = bvh::Builder::sah;
  int leaf_size = 2;  // most triangles per leaf (1..255)
  int arity = 2;      // children per inner node: 2, 4 or 8
};

/// A triangle mesh ready for collision queries: its hierarchy and per-node
/// volumes in double. Soups work: degenerate, duplicate and non-manifold
/// triangles are kept (a degenerate triangle is a segment or a point).
class CollisionMesh {
 public:
  CollisionMesh() = default;
  /// Throws geods::Error for an invalid mesh (indices out of range, NaN or
  /// infinite coordinates) or bad options.
  explicit CollisionMesh(const TriMesh& mesh, const CollisionMeshOptions& options = {});

  const bvh::TriangleBvh& bvh() const { return bvh_; }
  const CollisionMeshOptions& options() const { return options_; }
  std::size_t num_triangles() const { return bvh_.num_triangles(); }
  /// Largest absolute coordinate (sizes the padding of the volume tests).
  double extent() const { return extent_; }
  /// Depth of the hierarchy (edges on the longest root-to-leaf path).
  int depth() const { return depth_; }

  // Volumes per topology node in double, for the pair tests (collide.cpp).
  struct Box {
    Vec3d center, half;
  };
  struct Ball {
    Vec3d center;
    double radius;
  };
  struct Oriented {
    Eigen::Matrix3d axes;  // columns
    Vec3d center, half;
    double radius;  // |half|: the bounding sphere about the centre, a cheap first test
  };
  struct Swept {
    Eigen::Matrix3d axes;  // columns: the rectangle's axes, then its normal
    Vec3d center;
    double half0, half1;  // the rectangle's half lengths
    double radius;        // of the swept sphere
    double reach;         // |half| + radius: the bounding sphere about the centre
  };
  const std::vector<Box>& boxes() const { return boxes_; }
  const std::vector<Ball>& balls() const { return balls_; }
  const std::vector<Oriented>& oriented() const { return oriented_; }
  const std::vector<Swept>& swept() const { return swept_; }
  /// Where triangle `id` of the mesh sits in bvh().triangles() (leaf order).
  std::uint32_t leaf_position(std::uint32_t id) const { return leaf_position_[id]; }
  /// Per node, the size the "larger" descend rule compares (the volume's diameter).
  const std::vector<double>& sizes() const { return sizes_; }

 private:
  CollisionMeshOptions options_;
  bvh::TriangleBvh bvh_;
  double extent_ = 0;
  int depth_ = 0;
  std::vector<Box> boxes_;         // every volume's bounding box (aabb, boxtree, k-DOPs)
  std::vector<Ball> balls_;        // sphere
  std::vector<Oriented> oriented_;  // obb, obb_hull
  std::vector<Swept> swept_;        // rss
  std::vector<double> sizes_;
  std::vector<std::uint32_t> leaf_position_;
};

/// Which node of a pair the simultaneous traversal opens.
enum class DescendRule {
  larger,  // the one with the larger volume (diameter), a leaf never (the usual rule)
  count,   // the one over more triangles
  a_first, // A down to its leaves first, then B
  b_first, // B first
};
DescendRule parse_descend_rule(std::string_view name);
std::string_view to_string(DescendRule rule);

enum class CollideMode { first, all };
CollideMode parse_collide_mode(std::string_view name);
std::string_view to_string(CollideMode mode);

struct CollideStats {
  std::size_t volume_tests = 0;    // node pairs whose volumes were tested
  std::size_t leaf_pairs = 0;      // leaf pairs reached
  std::size_t triangle_tests = 0;  // exact triangle-triangle tests
};

struct CollideRequest {
  CollideMode mode = CollideMode::first;
  DescendRule descend = DescendRule::larger;
  /// In `all` mode: stop after this many pairs (the result is then partial).
  std::size_t max_pairs = std::numeric_limits<std::size_t>::max();
};

/// A pair of intersecting triangles (indices into the two meshes).
struct Contact {
  std::uint32_t a = kNoIndex, b = kNoIndex;
  friend bool operator==(const Contact&, const Contact&) = default;
  friend auto operator<=>(const Contact&, const Contact&) = default;
};

struct CollideResult {
  bool colliding = false;
  /// first: the one pair found (none if not colliding); all: every
  /// intersecting pair, sorted by (a, b).
  std::vector<Contact> pairs;
  CollideStats stats;
};

/// Whether / where the meshes a and b intersect in the given poses. Cost:
/// proportional to the node pairs whose volumes overlap. Throws
/// geods::Error for a non-finite or zero pose.
CollideResult collide(const CollisionMesh& a, const Posed& pose_a, const CollisionMesh& b, const Posed& pose_b,
                      const CollideRequest& request = {});
CollideResult collide(const CollisionMesh& a, const Posef& pose_a, const CollisionMesh& b, const Posef& pose_b,
                      const CollideRequest& request = {});

struct DistanceRequest {
  DescendRule descend = DescendRule::larger;
  /// If >= 0: stop as soon as a pair of triangles within this distance is
  /// found (result.within); the distance is then an upper bound, not the least.
  double within = -1;
};

struct DistanceResult {
  /// Least distance between the meshes (0 if they intersect; +inf if one is empty).
  double distance = std::numeric_limits<double>::infinity();
  Vec3d point_a = Vec3d::Zero(), point_b = Vec3d::Zero();  // closest points, world coordinates
  std::uint32_t triangle_a = kNoIndex, triangle_b = kNoIndex;
  bool within = false;  // request.within >= 0 and distance <= request.within
  CollideStats stats;
};

/// Least distance between a and b in the given poses with the closest points
/// (triangle distances in double, the exact test deciding 0). Branch and
/// bound over node pairs ordered by their volumes' distance lower bounds.
DistanceResult distance(const CollisionMesh& a, const Posed& pose_a, const CollisionMesh& b, const Posed& pose_b,
                        const DistanceRequest& request = {});
DistanceResult distance(const CollisionMesh& a, const Posef& pose_a, const CollisionMesh& b, const Posef& pose_b,
                        const DistanceRequest& request = {});

}  // namespace geods::collide
