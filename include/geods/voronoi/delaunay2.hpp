#pragma once
// Delaunay triangulation of points in the plane (seed §5.1.2, §5.2): incremental
// insertion with Lawson flips, exact predicates for every decision.
//
// Representation (as Delaunator): flat arrays of half-edges, three per triangle.
// Half-edge e runs from triangles()[e] to triangles()[next(e)] with
// next(e) = e % 3 == 2 ? e - 2 : e + 1; halfedges()[e] is the opposite half-edge
// or no_edge on the convex hull. Triangles are counter-clockwise.
//
// Internally the triangulation is a DelaunayCore (delaunay_core.hpp), closed by
// a "ghost" vertex at infinity: every hull edge has a ghost triangle on its
// outer side (seed §5.2's infinite triangles), so insertion outside the hull, on
// the hull and inside are the same steps (walk, split a triangle or an edge,
// flip). Constrained edges, the history DAG and removal are parts of their own
// beside the core (src/voronoi/constrained_delaunay, history_dag,
// vertex_removal). The public arrays are the finite triangles only, renumbered
// densely after each construction, insert() and remove(). Every array is a
// FlatArray: the triangulation's own, or after load() a view into the file.
//
// Order of insertion: BRIO (biased randomized insertion order: random rounds of
// doubling size, each sorted along a Hilbert curve); each point is located by a
// visibility walk from the triangle of the previous point. Expected O(n log n),
// near linear in practice.
//
// Degenerate input: duplicates are merged (representative(i) is the first
// occurrence, which is the vertex used in triangles()); co-circular points give
// one of the valid Delaunay triangulations; if all distinct points are collinear
// (or fewer than 3) there are no triangles, degenerate() is true and hull() is
// the distinct points sorted by (x, y). NaN or infinite coordinates raise
// geods::Error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay_core.hpp"

namespace geods::voronoi {

struct Delaunay2Stats {
  std::size_t points = 0;      // input points, including inserted ones
  std::size_t vertices = 0;    // distinct points present in the triangulation
  std::size_t duplicates = 0;  // points merged into an earlier equal point
  std::size_t removed = 0;     // points removed by remove()
  std::size_t triangles = 0;   // finite triangles
  std::size_t hull = 0;        // hull vertices
  std::size_t flips = 0;       // Lawson flips since construction
  std::size_t walk_steps = 0;  // triangles visited by point location while inserting
  std::size_t dag_nodes = 0;   // history DAG nodes created by the construction (history_dag location)
  std::size_t bytes = 0;       // memory of all arrays
};

/// How construction finds the triangle of each new point.
enum class Delaunay2Location {
  /// BRIO order (random rounds, Hilbert order in each), visibility walk from the
  /// previous point: a few steps per point. The fast default.
  walk,
  /// Random order, descent in the history DAG of all triangles ever created
  /// (seed §5.2; Guibas-Knuth-Sharir, the Delaunay tree of Boissonnat-Teillaud
  /// without its conflict lists): O(log i) expected per point whatever the
  /// order. Outside the hull the DAG's regions are the cones from a fixed
  /// interior point through the hull edges (the centroid of the first
  /// triangle; if rounding puts it outside, as with wildly mixed magnitudes,
  /// construction walks instead). The DAG (about 9 nodes of 28 bytes per
  /// point) lives during construction only; stats().dag_nodes counts it.
  history_dag,
};

struct Delaunay2Options {
  std::uint64_t seed = 0x5eed;  // of the randomized insertion order (results are deterministic)
  Delaunay2Location location = Delaunay2Location::walk;
};

class Delaunay2 {
 public:
  static constexpr std::uint32_t no_edge = std::uint32_t(-1);

  using Options = Delaunay2Options;

  using Segment = std::array<std::uint32_t, 2>;

  /// An empty triangulation.
  Delaunay2() = default;
  /// Triangulates the points; throws geods::Error for NaN/inf coordinates or
  /// 2^30 points or more.
  explicit Delaunay2(std::span<const Vec2d> points, Options options = {});
  /// Constrained Delaunay triangulation (seed §5.3.2): every segment (a pair of
  /// point indices) is a union of edges, every other edge is locally Delaunay,
  /// so no triangle's circle holds a point visible from inside it. Segments that cross are split at their intersection,
  /// a new point (rounded to doubles) appended to points() and listed in
  /// intersection_points(); a segment through a vertex is split there.
  /// Throws geods::Error for an index out of range or a segment (i, i).
  Delaunay2(std::span<const Vec2d> points, std::span<const Segment> segments, Options options = {});
  /// The same with segments given by their end points' coordinates: the end
  /// points are appended to `points` (points().size() grows by 2 per segment;
  /// equal points merge as duplicates), segment k joins points n + 2k and n + 2k + 1.
  static Delaunay2 from_segment_ends(std::span<const Vec2d> points, std::span<const std::array<Vec2d, 2>> segments,
                                     Options options = {});

  /// The input points (and inserted ones), indexed as given.
  std::span<const Vec2d> points() const { return points_; }
  /// Finite triangles, three counter-clockwise vertex indices each.
  const FlatArray<std::uint32_t>& triangles() const { return triangles_; }
  /// The opposite half-edge of each half-edge, no_edge on the hull.
  const FlatArray<std::uint32_t>& halfedges() const { return halfedges_; }
  /// Hull vertices counter-clockwise, collinear hull points included; for a
  /// degenerate set the distinct points sorted by (x, y).
  const FlatArray<std::uint32_t>& hull() const { return hull_; }
  std::size_t triangle_count() const { return triangles_.size() / 3; }

  /// Constrained triangulations: per half-edge of triangles(), 1 if it lies on
  /// a segment (empty without segments).
  const FlatArray<std::uint8_t>& constrained() const { return constrained_; }
  /// The constrained edges, each once, as point index pairs.
  std::vector<Segment> constrained_edges() const;
  /// The input segments as given.
  const std::vector<Segment>& segments() const { return segments_; }
  /// Points added where segments cross (indices into points()).
  const std::vector<std::uint32_t>& intersection_points() const { return intersections_; }
  /// Per triangle: 1 if it lies inside the segments (reached from outside the
  /// hull by crossing an odd number of constrained edges), else 0. For polygons
  /// with holes: the triangles of the polygon minus its holes.
  std::vector<std::uint8_t> inside() const;
  /// True when there are no triangles (fewer than 3 distinct points, or all collinear).
  bool degenerate() const { return triangles_.empty(); }

  static std::uint32_t next(std::uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }
  static std::uint32_t prev(std::uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }

  /// The vertex that stands for point i: i itself, the first occurrence of an
  /// equal point, or no_edge for a removed point.
  std::uint32_t representative(std::uint32_t i) const;
  /// Number of input points merged into an earlier one.
  std::size_t duplicate_count() const;

  /// A finite triangle (index into triangles() / 3) whose closed area contains q,
  /// or no_edge if q lies outside the hull (or the triangulation is degenerate).
  /// A visibility walk from `hint` (a triangle index, or no_edge for a fixed
  /// start): O(sqrt n) expected for a far hint, O(1) for a close one.
  /// Thread-safe.
  std::uint32_t locate(const Vec2d& q, std::uint32_t hint = no_edge) const;
  /// The nearest vertex to q (a representative; ties broken arbitrarily), by a
  /// greedy walk along Delaunay edges; no_edge if the triangulation is empty.
  /// Thread-safe.
  std::uint32_t nearest(const Vec2d& q) const;
  /// The Delaunay neighbours of vertex v counter-clockwise (empty for a point
  /// that is not a vertex); for a hull vertex from the next hull vertex to the
  /// previous one; for a degenerate set, v's neighbours in hull().
  std::vector<std::uint32_t> neighbors(std::uint32_t v) const;

  /// Inserts a point, returns its index (points().size() - 1 before the call).
  /// A duplicate is merged into the existing point. Keeps the triangulation
  /// Delaunay; O(expected degree) flips plus O(n) to renumber the public arrays.
  std::uint32_t insert(const Vec2d& p);
  class Inserter;

  /// Removes vertex v (a representative; not supported with segments; removing a duplicate only drops the
  /// alias, removing a vertex that has aliases promotes the next alias). The hole
  /// is retriangulated by flipping v's edges away (Delaunay ears, Devillers),
  /// then v is cut out at degree 3. O(d^2) for degree d plus O(n) renumbering.
  void remove(std::uint32_t v);

  /// Writes the triangulation to `path` as a geods archive (core/archive.hpp,
  /// kind "voronoi.Delaunay2", version 2): points, segments, the internal
  /// arrays and the public ones (triangles(), halfedges(), hull()...).
  /// Throws geods::Error naming the file if it cannot be written.
  void save(const std::filesystem::path& path) const;
  /// A triangulation equal to the one save()d to `path`: the same arrays, the
  /// same answers, and insert() and remove() go on as they would have. The
  /// arrays are views of the mapped file (FlatArray::mapped()): queries read
  /// its pages in place, nothing is rebuilt; the first insert() or remove()
  /// copies them into arrays of the triangulation's own. O(n) for the checks.
  /// Throws geods::Error naming the file if it is missing, truncated, corrupt
  /// (the checksums), of another kind or version (version 1 files, written
  /// before the public arrays were saved, too: save them again), or its arrays
  /// are not a closed triangulation of its points: indices in range, twins
  /// mutual, triangles counter-clockwise, every representative a vertex, the
  /// public arrays what the internal ones give (validate()'s checks but the
  /// costly ones, incircle and the segments' paths, which a checksummed file
  /// written by save() cannot fail; Verify::full and structure_only, which
  /// skips the checksums, run those too).
  static Delaunay2 load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);

  Delaunay2Stats stats() const;
  /// Checks every invariant; throws geods::Error naming the first violation:
  /// twins consistent, triangles counter-clockwise, every edge locally Delaunay
  /// (exact incircle), the hull convex, Euler's formula (t = 2n - h - 2), every
  /// representative in a triangle, and the public arrays match the internal ones.
  void validate() const;

 private:
  struct Editor;  // the arrays as vectors while they change (delaunay2.cpp)
  DelaunayView view() const { return {{}, coords_, vert_, twin_}; }
  struct TriangleCounts {
    std::size_t live, ghosts;
  };
  // validate()'s cheap parts, safe on any arrays of the right sizes: what load() checks.
  std::size_t check_representatives() const;  // returns the number of distinct vertices
  TriangleCounts check_triangles(std::size_t representatives) const;
  void check_public_view(std::size_t finite) const;  // for `finite` triangles: every public array is what publish() makes

  // Every array is read only (its own after a construction or a change, a
  // view into the file after load()); Editor changes them.
  Options options_;
  FlatArray<Vec2d> points_;
  std::vector<Segment> segments_;
  std::vector<std::uint32_t> intersections_;
  FlatArray<std::uint32_t> rep_;  // representative per point, no_edge when removed

  // The closed triangulation: DelaunayCore's arrays. Its vertices are numbered
  // in insertion order, their coordinates copied in that order, so that the
  // spatially sorted insertion reads memory sequentially.
  FlatArray<Vec2d> coords_;
  FlatArray<std::uint32_t> vert_, twin_, free_triangles_, vertex_edge_;
  std::uint32_t last_triangle_ = 0;
  std::size_t flips_ = 0, walk_steps_ = 0;
  FlatArray<std::uint32_t> original_of_;  // internal vertex -> the point it stands for
  FlatArray<std::uint32_t> internal_of_;  // point -> its internal vertex, no_edge if removed
  FlatArray<std::uint8_t> fixed_;         // per internal half-edge: on a segment (only with segments)
  bool has_constraints_ = false;
  std::size_t dag_nodes_ = 0;

  // The public, finite-only view.
  FlatArray<std::uint32_t> triangles_, halfedges_, hull_;
  FlatArray<std::uint8_t> constrained_;
  FlatArray<std::uint32_t> public_triangle_;    // internal triangle -> public index or no_edge
  FlatArray<std::uint32_t> internal_triangle_;  // public -> internal
};

/// Many insertions in a row at O(1) expected each, for algorithms that grow a
/// triangulation point by point and look at the triangles each point makes
/// (greedy TIN refinement, Ruppert-style refinement): Delaunay2::insert()
/// renumbers the public arrays after every point (O(n)); an Inserter takes the
/// triangulation's arrays, inserts into them, reports the triangles each
/// insertion created or changed, and renumbers the public arrays once, when it
/// goes. The Delaunay2 must not be used while an Inserter on it lives.
///
/// Triangles are named by handles (the internal slots: in [0, handle_count()),
/// not the public numbers). A handle keeps naming the same triangle until an
/// insertion lists it in changed(); insertions only add handles.
class Delaunay2::Inserter {
 public:
  explicit Inserter(Delaunay2& dt);
  ~Inserter();  // renumbers the public arrays
  Inserter(const Inserter&) = delete;
  Inserter& operator=(const Inserter&) = delete;

  /// Inserts p as Delaunay2::insert() does (same checks, duplicates merged) and
  /// returns its point index. `near` is the handle of a triangle at or near p
  /// (the walk to p starts there; no_edge: where the last change was), so a
  /// caller that knows p's triangle pays no point location.
  std::uint32_t insert(const Vec2d& p, std::uint32_t near = no_edge);
  /// A finite triangle: its handle and its corners, counter-clockwise.
  struct Triangle {
    std::uint32_t handle;
    std::array<Vec2d, 3> corners;
  };
  /// The finite triangles the last insert() created or changed, each once (in
  /// increasing handle order; all of them when it made the first triangles):
  /// the triangles with the new point as a corner, read while they are in
  /// cache, so that rescanning them costs no lookups.
  std::span<const Triangle> changed() const { return changed_; }
  /// Room for `more` points without reallocation, the large arrays on
  /// transparent huge pages where the system allows (insertions read them at
  /// random; with 4 KiB pages nearly every read also misses the TLB). The
  /// memory is touched as the triangulation grows, but for the small pages
  /// before each array's first huge page, which are mapped at once.
  void reserve(std::size_t more);
  /// A hint that a coming insert() starts at triangle h: its arrays are
  /// fetched into the cache meanwhile (they lie anywhere in memory); nothing
  /// is read, so the hint does not wait for them.
  void prefetch(std::uint32_t h) const;
  /// The next step of that hint, some time after prefetch(h): h's corners and
  /// the arrays of h's neighbours across its edges (which the split relinks
  /// and the flips test), found through h's arrays, which prefetch(h) fetched.
  void prefetch_neighbors(std::uint32_t h) const;
  /// One more than the largest handle.
  std::uint32_t handle_count() const;
  /// Whether handle h names a finite triangle now.
  bool is_triangle(std::uint32_t h) const;
  /// The point indices of triangle h, counter-clockwise.
  std::array<std::uint32_t, 3> triangle(std::uint32_t h) const;
  /// The points (the input ones and those inserted so far).
  std::span<const Vec2d> points() const;

 private:
  std::unique_ptr<Editor> editor_;
  std::vector<std::uint32_t> touched_;
  std::vector<Triangle> changed_;
};

}  // namespace geods::voronoi
