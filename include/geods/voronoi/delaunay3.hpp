#pragma once
// Delaunay tetrahedralization of points in space (seed §5.3.1): Bowyer-Watson
// cavity insertion with exact predicates and a symbolic perturbation, so that
// every input, cospherical, coplanar or with duplicates, gives a valid result.
//
// Representation: flat arrays, per tetrahedron four vertex ids and four
// neighbour ids; neighbour i is across the face opposite vertex i. Every
// tetrahedron is positively oriented: det(b - a, c - a, d - a) > 0, which is
// geods::orient3d(a, b, c, d) < 0 in Shewchuk's convention. Internally the
// convex hull is closed by an infinite ("ghost") vertex: each hull triangle has
// a ghost tetrahedron on its outer side, so insertion outside the hull and
// inside are the same steps. The public arrays hold the finite tetrahedra only,
// over input point indices, with kNoIndex across the hull.
//
// Construction: BRIO (random rounds of doubling size, each sorted along a 3D
// Hilbert curve); each point is located by a stochastic visibility walk from
// the last tetrahedron created, the tetrahedra whose circumsphere holds it (the
// cavity, found by a breadth-first search from the one it lies in) are
// replaced by the tetrahedra joining it to the cavity's boundary. Expected
// O(n log n), near linear for uniform points.
// Options::insertion = flips inserts by flips instead (delaunay3_flip.cpp):
// the tetrahedron holding the point is split 1-4 (a point outside the hull is
// joined to the hull triangles it sees), then the non-Delaunay faces of its
// link are flipped 2-3, 3-2 or 4-4 in the stack order of Edelsbrunner-Shah;
// same predicates and perturbation, so the same tetrahedralization.
//
// Degeneracies: in_sphere == 0 is decided by the symbolic perturbation of
// CGAL's Delaunay_triangulation_3 (Devillers-Teillaud, "Perturbations and
// vertex removal in a 3D Delaunay triangulation", 2003): the points are
// ranked lexicographically and lifted by infinitesimals in that order, so the
// triangulation is unique whatever the insertion order. A ghost tetrahedron
// holds a point strictly beyond its hull face, and a point on the face's plane
// when the finite tetrahedron behind the face holds it.
//
// Parallel construction: with several threads and many points, the points
// left and right of the median x are tetrahedralized at the same time. The
// tetrahedra of each half whose circumsphere (or hull face) certainly holds
// no point of the other half are tetrahedra of the whole set (the
// perturbation depends on coordinates only); the others, near the seam, are
// replaced by the tetrahedra of the seam's vertices' own tetrahedralization
// that fill the region they leave (matched by its boundary faces, as in
// remove()). The certificates are conservative (a doubtful tetrahedron goes to
// the seam), so the result is the unique tetrahedralization, in the same
// canonical order as a sequential build.
//
// Lower-dimensional input: duplicates are merged (representative(i) is the
// first occurrence; duplicate_count()). If the distinct points are fewer than
// four or all coplanar there are no tetrahedra: dimension() says 0 (all equal),
// 1 (collinear) or 2 (coplanar), and -1 for no points. NaN or infinite
// coordinates raise geods::Error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

struct Tet3Mesh;

struct Delaunay3Stats {
  std::size_t points = 0;          // input points
  std::size_t vertices = 0;        // distinct points, vertices of the tetrahedralization
  std::size_t duplicates = 0;      // points merged into an earlier equal point
  std::size_t removed = 0;         // points removed by remove()
  std::size_t rebuilds = 0;        // removals that rebuilt everything (a flat link) instead of the star
  std::size_t tetrahedra = 0;      // finite tetrahedra
  std::size_t hull_triangles = 0;  // triangles of the convex hull
  std::size_t dimension = 0;       // affine dimension of the points (0 for none)
  std::size_t walk_steps = 0;      // tetrahedra visited by point location while inserting
  std::size_t conflicts = 0;       // tetrahedra replaced by insertions (cavity sizes summed)
  std::size_t seam_points = 0;     // parallel build: points of the seam retetrahedralized between the halves (0: sequential)
  // Flip-based insertion (Options::insertion == flips; all 0 for cavity insertion):
  std::size_t flips_14 = 0;      // 1-4 flips: a point inside a tetrahedron
  std::size_t flips_23 = 0;      // 2-3 flips (Figure 48)
  std::size_t flips_32 = 0;      // 3-2 flips
  std::size_t flips_44 = 0;      // 4-4 flips (the point coplanar with the flipped face's edge and the apex)
  std::size_t splits = 0;        // a point on a face (2-6) or an edge (n-2n) split every tetrahedron holding it
  std::size_t hull_inserts = 0;  // a point outside the hull joined to the hull triangles it sees (1-k with the ghosts)
  std::size_t unflippable = 0;   // non-Delaunay link faces whose flip was not possible when popped (resolved by later flips)
  std::size_t flip_repairs = 0;  // insertions whose flips got stuck, finished by a cavity step from the star (expected 0)
  std::size_t bytes = 0;           // memory of all arrays
};

/// How Delaunay3 inserts a point (seed §5.3.1 names both): `cavity`
/// (Bowyer-Watson: the tetrahedra whose circumsphere holds it are replaced by
/// its star) or `flips` (Joe, Edelsbrunner-Shah: the tetrahedron holding it is
/// split 1-4, then the non-Delaunay faces of its link are flipped 2-3, 3-2 or
/// 4-4). The same predicates and perturbation decide both, so the result is
/// the same tetrahedralization.
enum class Delaunay3Insertion { cavity, flips };

struct Delaunay3Options {
  Delaunay3Insertion insertion = Delaunay3Insertion::cavity;  // also used by insert()
  std::uint64_t seed = 0x5eed;  // of the randomized insertion order (the result does not depend on it)
  /// With more than one thread (geods::num_threads()) and at least this many
  /// points, the two halves of the set (split at the median x) are
  /// tetrahedralized at the same time and stitched (see Delaunay3); the
  /// result is the same as on one thread.
  std::size_t parallel_from = 100000;
};

class Delaunay3 {
 public:
  static constexpr std::uint32_t no_index = std::uint32_t(-1);
  using Options = Delaunay3Options;
  using Triangle = std::array<std::uint32_t, 3>;

  /// An empty tetrahedralization (dimension() == -1).
  Delaunay3() = default;
  /// Tetrahedralizes the points; throws geods::Error for NaN/inf coordinates
  /// or 2^31 points or more.
  explicit Delaunay3(std::span<const Vec3d> points, Options options = {});

  /// The input points, indexed as given.
  std::span<const Vec3d> points() const { return points_; }
  /// Finite tetrahedra, four positively oriented vertex indices each. After a
  /// build in a canonical order that depends only on the points (not on the
  /// insertion order or the thread count): each starts at its smallest vertex,
  /// then the smallest of the other three, and the tetrahedra are sorted by
  /// their vertices; insert() and remove() change it in place.
  const std::vector<std::uint32_t>& tetrahedra() const { return tetrahedra_; }
  /// Per tetrahedron, the four neighbouring tetrahedra: neighbour i shares
  /// the face opposite vertex i; no_index on the convex hull. Made from the
  /// internal adjacency on each call (O(m), in parallel): keep the result.
  std::vector<std::uint32_t> neighbors() const;
  std::size_t tetrahedron_count() const { return tetrahedra_.size() / 4; }
  /// Affine dimension of the points: -1 none, 0 all equal, 1 collinear,
  /// 2 coplanar (no tetrahedra in these cases), 3 a solid.
  int dimension() const { return dimension_; }
  /// The triangles of the convex hull (dimension 3), counter-clockwise seen
  /// from outside, over point indices.
  std::vector<Triangle> hull() const;

  /// The vertex that stands for point i: i itself, the first occurrence of an
  /// equal point, or no_index for a removed point.
  std::uint32_t representative(std::uint32_t i) const { return rep_[i]; }
  std::size_t duplicate_count() const;

  /// A finite tetrahedron (index into tetrahedra() / 4) whose closed volume
  /// holds q, or no_index outside the hull (or for dimension() < 3). A
  /// visibility walk from `hint` (a tetrahedron, or no_index for the last one
  /// built): O(n^(1/3)) expected steps from afar, O(1) from close by. Thread-safe.
  std::uint32_t locate(const Vec3d& q, std::uint32_t hint = no_index) const;
  /// The point nearest to q (a representative; ties broken arbitrarily), by
  /// locating q and descending greedily along Delaunay edges (for
  /// dimension() < 3, by scanning the distinct points); no_index if empty. Thread-safe.
  std::uint32_t nearest_vertex(const Vec3d& q) const;
  /// The Delaunay neighbours of the vertex of point v (a representative), ascending.
  std::vector<std::uint32_t> vertex_neighbors(std::uint32_t v) const;

  /// Inserts a point, returns its index (points().size() - 1 after the call).
  /// A duplicate is merged into the existing point. Bowyer-Watson in place, or
  /// flips with Options::insertion == flips: O(cavity) plus O(n) to renumber
  /// the public arrays.
  std::uint32_t insert(const Vec3d& p);
  /// Removes point i (its index stays, representative(i) becomes no_index; an
  /// equal point, if any, stands for the place from then on). Local, after
  /// Devillers: the tetrahedra around the vertex (its star) are replaced by
  /// those of the Delaunay tetrahedralization of its neighbours (its link)
  /// that lie in the star. The perturbation depends on coordinates only, so
  /// that small tetrahedralization agrees with the big one, and the result is
  /// the tetrahedralization of the remaining points, equal to a rebuild.
  /// O(d log d) for d neighbours plus O(n) to renumber the public arrays. A
  /// vertex whose neighbours are coplanar (a cap on a flat part of the hull)
  /// or a set that becomes flat is rebuilt from scratch (stats().rebuilds).
  void remove(std::uint32_t i);

  /// Writes the tetrahedralization to `path` as a geods archive
  /// (core/archive.hpp, kind "voronoi.Delaunay3", version 1): the points, the
  /// removal flags, the representatives and the closed tetrahedralization's
  /// slots. Throws geods::Error naming the file if it cannot be written.
  void save(const std::filesystem::path& path) const;
  /// A tetrahedralization equal to the one save()d to `path` (same arrays,
  /// same answers; insert() and remove() go on as they would have). Unlike the
  /// 2D structures it copies the sections into arrays of its own (insertion
  /// changes them in place). Every index is checked before use, then
  /// validate() runs (exact, O(n)). Throws geods::Error naming the file if it
  /// is missing, truncated, corrupt, of another kind or version, or not a
  /// Delaunay tetrahedralization of its points.
  static Delaunay3 load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);

  Delaunay3Stats stats() const;
  /// Checks every invariant; throws geods::Error naming the first violation:
  /// neighbours mutual and sharing their face, every finite tetrahedron
  /// positively oriented (exact orient3d), every face locally Delaunay: the
  /// opposite vertex of each neighbour lies outside or on the circumsphere
  /// (exact insphere) and outside after the perturbation; the hull locally
  /// convex; every representative a vertex; the public arrays what the
  /// internal ones give.
  void validate() const;

 private:
  // The closed tetrahedralization, over point indices (while building, over
  // vertices in insertion order, renumbered at the end): per slot eight words,
  // four vertices (the ghost for the infinite one, no_index in a free slot)
  // and four adjacencies, 4 * neighbour + the face's index in the neighbour.
  // With `vertex_points` (a half of a parallel build) the vertices keep their
  // insertion order, which is coherent in space: points_ becomes the vertices'
  // coordinates in that order and *vertex_points each vertex's point (no_index
  // for a duplicate's); rep_ stays over the points.
  void build(Options options, bool may_split = true, std::vector<std::uint32_t>* vertex_points = nullptr);
  // false: the halves cannot be stitched, build sequentially; `free`: how many slots it left free;
  // `storage`: a dead array, its pages touched, for canonicalize's new slots.
  bool build_split(const std::vector<std::uint32_t>& active, std::size_t& free, std::vector<std::uint32_t>& storage);
  bool remove_locally(std::uint32_t v);  // false: the link is flat, rebuild instead
  // Slots in an order that depends only on the points; publishes them too. `free`: how many
  // slots are free (sizes an array; a wrong count costs time only); `storage`: memory for
  // the new slots (its contents are overwritten).
  void canonicalize(std::size_t free, std::vector<std::uint32_t> storage = {});
  void publish();  // (only vertex_slot_ left to do right after canonicalize: `published_`)
  void index_vertices();  // vertex_slot_ from the slots
  std::uint32_t start_slot(std::uint32_t hint) const;  // a live slot to walk from
  // nearest_vertex(q) walking from `slot` (dimension 3), which becomes the slot q lies in (or a ghost beyond it).
  std::uint32_t nearest_vertex_from(const Vec3d& q, std::uint32_t& slot) const;

  Options options_;
  std::vector<Vec3d> points_;
  std::vector<std::uint32_t> rep_;     // representative per point, no_index when removed
  std::vector<std::uint8_t> removed_;  // per point: removed by remove()
  int dimension_ = -1;

  std::vector<std::uint32_t> tets_, free_slots_;
  std::size_t walk_steps_ = 0, conflicts_ = 0, rebuilds_ = 0, seam_points_ = 0;
  std::array<std::size_t, 8> flip_counts_{};  // Tet3Mesh::FlipCount order
  std::uint32_t last_ = 0;                // the slot of the last insertion
  std::vector<std::uint32_t> vertex_slot_;  // per point: a slot holding its vertex

  std::vector<std::uint32_t> tetrahedra_;  // public, finite only
  std::vector<std::uint32_t> public_of_;               // internal slot -> public tetrahedron (no_index: ghost or free)
  bool published_ = false;  // tetrahedra_ and public_of_ are already those of tets_ (set by canonicalize)
};

}  // namespace geods::voronoi
