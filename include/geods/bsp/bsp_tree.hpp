#pragma once
// BSP trees over 3D polygons (seed §3): auto-partitions with the cost heuristic of
// equation (5) (alpha, beta, the k largest polygons), the random-k heuristic of
// Fuchs et al., and balanced axis-aligned planes (§3.4.1, planes through the median
// of the polygons' centroids when they separate, an auto-partition plane otherwise).
// Straddling polygons are split, coplanar ones stored at the node.
//
// Solids (§3.2): the input is a closed, outward-oriented triangle mesh; a leaf is
// created only at an auto-partition node, when one side of a polygon's plane has no
// polygon left, and that empty cell touches the polygon from behind (inside) or in
// front (outside). Every side decision is exact (plane_based.hpp): vertices are first
// snapped to the grid of Grid (2^19 steps on each side of the centre of the box of
// the input, a power-of-two step), and the tree is exact for the snapped mesh.
// Triangles that the snapping makes degenerate are dropped.
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string_view>
#include <vector>

#include "geods/bsp/plane_based.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/core/vec.hpp"

namespace geods::bsp {

inline constexpr std::uint32_t kNoIndex = std::numeric_limits<std::uint32_t>::max();

enum class Heuristic { cost, random, balanced, custom };
/// Parses "cost", "random", "balanced" or "custom"; throws geods::Error naming the choices.
Heuristic parse_heuristic(std::string_view name);
std::string_view heuristic_name(Heuristic h);

/// Rays for BspTree::first_hits (request): ray i is origins[i] + t directions[i], 0 <= t <= t_max.
struct RayQuery {
  std::vector<Vec3d> origins, directions;
  double t_max = std::numeric_limits<double>::infinity();
};
struct RayQueryStats {
  std::size_t rays = 0, hits = 0;
  double nodes_per_ray = 0;   // tree nodes visited per ray (mean)
  double tests_per_ray = 0;   // fragment (polygon) tests per ray (mean)
  double query_s = 0;
};
/// Answers of first_hits (result): per ray the distance t and the input triangle (kNoIndex: no hit).
struct RayQueryResult {
  std::vector<double> t;
  std::vector<std::uint32_t> triangle;
  RayQueryStats stats;
};

struct BuildOptions {
  Heuristic heuristic = Heuristic::cost;
  double alpha = 0.8;       // equation (5): weight of |S-|^alpha + |S+|^alpha
  double beta = 0.5;        // equation (5): penalty per split polygon
  std::uint32_t k = 8;      // candidates: the k largest (cost), k random (random) or k best-scoring (custom) polygons
  std::uint64_t seed = 1;   // random choices
  std::size_t sample = 128; // polygons a candidate is scored on (a random sample if more)
  /// custom (§3.4.3, the customized BSP): a sample of the rays the tree will answer (t_max
  /// unused). A polygon p scores Area(p) times the sum, over the sample rays whose line passes
  /// p's bounding sphere ahead of the origin, of sin^2 of the angle between the ray and p's
  /// plane ((n_p . r)^2 for unit n_p, r), divided by the sample size; each node takes the
  /// plane of a random one of its k best-scoring polygons. Required (non-empty, finite rays,
  /// non-zero directions) for custom; the cost is polygons x rays once.
  RayQuery rays;
};

struct BspStats {
  std::size_t nodes = 0;       // inner nodes and leaves
  std::size_t leaves = 0;
  std::size_t depth = 0;       // longest root-to-leaf path, in edges
  std::size_t polygons = 0;    // input polygons (non-degenerate triangles)
  std::size_t fragments = 0;   // polygons stored at the nodes after splitting
  double expected_cost = 0;    // equation (4), P(child) = volume fraction in the input's box (sampled)
  double build_s = 0;
};

/// The snapping grid: grid = round(world * 2^shift) - center, |grid| <= 2^kGridBits.
struct Grid {
  int shift = 0;
  std::array<std::int64_t, 3> center{0, 0, 0};
  /// The grid of a box (lo, hi), finite; throws geods::Error if it cannot be represented.
  static Grid fit(const Vec3d& lo, const Vec3d& hi);
  std::array<std::int64_t, 3> snap(const Vec3d& p) const;
  Vec3d to_grid(const Vec3d& p) const;
  Vec3d to_world(const std::array<double, 3>& g) const;
  double step() const;  // world size of one grid unit
};

enum class Label : std::uint8_t { none, inside, outside };

struct Node {
  std::uint32_t plane = kNoIndex;  // plane reference; kNoIndex for a leaf
  std::uint32_t neg = kNoIndex, pos = kNoIndex;
  std::uint32_t first = 0, count = 0;  // fragments stored at the node: fragments()[first, first + count)
  Label label = Label::none;           // leaves of solids
  bool leaf() const { return plane == kNoIndex; }
};

struct Triangles {
  std::vector<Vec3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Conversions from and to the library's float meshes.
Triangles from_tri_mesh(const TriMesh& m);
TriMesh to_tri_mesh(const Triangles& m);

class BspTree {
 public:
  BspTree() = default;
  /// The BSP of a triangle mesh; leaves are labelled inside/outside (meaningful for closed,
  /// outward-oriented meshes; for an open mesh the labels are a best effort). Throws
  /// geods::Error for non-finite coordinates, out-of-range indices or no non-degenerate triangle.
  BspTree(const std::vector<Vec3d>& vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles,
          const BuildOptions& options = {});
  /// The same on a given grid and plane table (the operands of a boolean share both).
  BspTree(std::shared_ptr<PlaneSet> planes, const Grid& grid, const std::vector<Vec3d>& vertices,
          const std::vector<std::array<std::uint32_t, 3>>& triangles, const BuildOptions& options = {});

  /// -1 inside, +1 outside, 0 on the boundary; exact for the point's grid coordinates
  /// (the world point times a power of two, minus an integer, rounded once).
  int classify(const Vec3d& p) const;
  /// Fragments (indices into fragments(); fragments()[i].source is the input triangle) in
  /// visibility order from eye (back to front, or front to back). If frustum
  /// points are given (the corners of the view volume, e.g. the eye and four far corners),
  /// subtrees on the far side of a node plane from all of them are skipped.
  std::vector<std::uint32_t> visibility_order(const Vec3d& eye, bool back_to_front = true,
                                              const std::vector<Vec3d>& frustum = {}) const;
  struct Hit {
    double t = std::numeric_limits<double>::infinity();
    std::uint32_t triangle = kNoIndex;
  };
  /// First fragment hit by origin + t dir, 0 <= t <= t_max (front to back along the ray).
  /// If given, nodes and tests are increased by the nodes visited and the fragments tested.
  Hit first_hit(const Vec3d& origin, const Vec3d& dir, double t_max = std::numeric_limits<double>::infinity(),
                std::size_t* nodes = nullptr, std::size_t* tests = nullptr) const;
  /// first_hit for every ray of the query, with the work per ray (nodes visited, fragments
  /// tested) and the time. Throws geods::Error for sizes that differ or non-finite rays.
  RayQueryResult first_hits(const RayQuery& query) const;

  /// Archive kind and layout version of save().
  static constexpr const char* kArchiveKind = "bsp.BspTree";
  static constexpr std::uint32_t kArchiveVersion = 1;
  /// Writes the tree (grid, plane table, nodes, fragments) to one archive (core/archive.hpp).
  void save(const std::filesystem::path& path) const;
  /// Reads a file written by save(): the nodes are viewed in place in the mapped file, the
  /// plane table and the fragments' plane lists are read into memory. Throws geods::Error
  /// for a missing, truncated, corrupt or wrong-version file, and checks that every index
  /// it read is in range (children, planes, fragment ranges, points) and that the nodes form a tree.
  static BspTree load(const std::filesystem::path& path);

  const BspStats& stats() const { return stats_; }
  /// Checks the structure (indices, plane references, every fragment on its node's plane
  /// and inside its node's cell, leaves labelled); throws geods::Error.
  void validate() const;

  const FlatArray<Node>& nodes() const { return nodes_; }
  const std::vector<Polygon>& fragments() const { return fragments_; }
  std::uint32_t root() const { return root_; }
  const PlaneSet& planes() const { return *planes_; }
  const std::shared_ptr<PlaneSet>& plane_set() const { return planes_; }
  const Grid& grid() const { return grid_; }
  /// The fragments as a triangle mesh (world coordinates, fan-triangulated, not welded).
  Triangles fragment_mesh() const;

 private:
  friend class Merger;
  void build(const std::vector<Vec3d>& vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles,
             const BuildOptions& options);
  void compute_stats();

  std::shared_ptr<PlaneSet> planes_;
  Grid grid_;
  FlatArray<Node> nodes_;  // in place in the file after load()
  std::vector<Polygon> fragments_;
  std::uint32_t root_ = kNoIndex;
  BspStats stats_;
};

/// Bounds of vertices that triangles use, after checking them (finite, indices in range).
void check_mesh(const std::vector<Vec3d>& vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                const char* what);

}  // namespace geods::bsp
