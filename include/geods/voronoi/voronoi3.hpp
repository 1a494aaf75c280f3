#pragma once
// The Voronoi diagram of points in space (seed §5.3.1, the dual of Delaunay3):
// every site's cell clipped to a box or to the sites' convex hull, as a closed
// convex polyhedron with its volume and centroid. The cells partition the box
// (of the sites inside it) or the hull.
//
// A cell of a site off the hull is read off the tetrahedralization: a corner
// per tetrahedron around the site (its circumcentre, the same bits in every
// cell that has it), a face per Delaunay edge, through the centres of the
// tetrahedra around the edge; the box's planes cut the cells that reach it.
// The cells of hull sites, and of sites with five or more nearly cospherical
// neighbours (corners within 2^-30 of each other), are the box cut by the
// bisector planes between the site and its Delaunay neighbours, clipped in
// doubles with the corners joined by identity (closed however close they lie).
// Layout, flat per cell: its vertices, its faces as index loops into them
// (counter-clockwise seen from outside), and per face the site across it, a
// box side (Voronoi3::box_side(k), k = 0..5 for -x, +x, -y, +y, -z, +z) or a
// hull triangle (Voronoi3::hull_face(k), k indexing Delaunay3::hull()).
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay3.hpp"

namespace geods::voronoi {

struct Voronoi3Cell {
  std::uint32_t site = 0;                   // the point it belongs to
  std::vector<Vec3d> vertices;              // the cell's corners
  std::vector<std::uint32_t> face_offsets;  // face f is face_vertices[face_offsets[f] .. face_offsets[f + 1])
  std::vector<std::uint32_t> face_vertices;
  std::vector<std::uint32_t> face_neighbors;  // per face: the site across, box_side(k) or hull_face(k)
  double volume = 0;                        // 0 for a cell that misses the box (no faces)
  Vec3d centroid = Vec3d::Zero();
  std::size_t face_count() const { return face_neighbors.size(); }
};

struct Voronoi3Stats {
  std::size_t sites = 0;     // cells (distinct points)
  std::size_t faces = 0;     // cell faces, each shared face counted per cell
  std::size_t vertices = 0;  // cell corners, counted per cell
  std::size_t empty = 0;     // cells that miss the box
  std::size_t bytes = 0;
};

class Voronoi3 {
 public:
  /// The face label of box side k (0: x = lo.x, 1: x = hi.x, 2, 3: y, 4, 5: z).
  static constexpr std::uint32_t box_side(int k) { return std::uint32_t(-2 - k); }
  static bool is_box_side(std::uint32_t label) { return label >= box_side(5) && label <= box_side(0); }
  /// The face label of hull triangle k (Delaunay3::hull()[k]); sites are below 2^31.
  static constexpr std::uint32_t hull_face(std::uint32_t k) { return k | 0x80000000u; }
  static bool is_hull_face(std::uint32_t label) { return (label & 0x80000000u) && !is_box_side(label); }

  /// The cells of the points' distinct sites (representatives of Delaunay3),
  /// clipped to `box`, computed in parallel (the result does not depend on
  /// the thread count). Throws geods::Error for an empty, NaN or infinite box.
  /// O(sum of cell sizes) after the tetrahedralization; for fewer than four
  /// non-coplanar sites every other site bounds each cell: O(n^2).
  Voronoi3(const Delaunay3& dt, const AABB3d& box);
  Voronoi3(std::span<const Vec3d> points, const AABB3d& box) : Voronoi3(Delaunay3(points), box) {}
  /// The cells clipped to the convex hull of the sites (box() is the sites'
  /// bounding box). A cell is cut by the hull's planes only if its site is on
  /// the hull or a Voronoi vertex of it (a tetrahedron's circumcentre) lies
  /// outside: O(h) more per such cell for h hull triangles. Throws
  /// geods::Error unless dt.dimension() == 3.
  explicit Voronoi3(const Delaunay3& dt);

  const std::vector<Voronoi3Cell>& cells() const { return cells_; }
  const AABB3d& box() const { return box_; }
  /// The points the cells belong to (Voronoi3Cell::site indexes them), duplicates included.
  const std::vector<Vec3d>& points() const { return points_; }
  /// The hull triangles the cells were clipped to (Delaunay3::hull(), its
  /// hull_face(k) labels), empty for cells clipped to a box.
  const std::vector<std::array<std::uint32_t, 3>>& hull() const { return hull_; }
  /// The sum of the cell volumes: the box's (or the hull's) volume up to rounding.
  double volume_total() const;
  Voronoi3Stats stats() const;
  /// The cells as one triangle mesh (each face a fan), every cell a closed
  /// surface; with `explode` > 0 each cell is moved away from the box's centre
  /// by that fraction of its centroid's offset (an exploded view). The
  /// triangles of cell c are those whose index in `cell_of_triangle` (when
  /// given) holds c.
  TriMesh mesh(double explode = 0, std::vector<std::uint32_t>* cell_of_triangle = nullptr) const;

  /// Writes the cells, their points, the box and the hull to `path` as a geods
  /// archive (core/archive.hpp, kind "voronoi.Voronoi3", version 1). Throws
  /// geods::Error naming the file if it cannot be written.
  void save(const std::filesystem::path& path) const;
  /// The cells save()d to `path`. Every index and label is checked before use
  /// and every cell is a closed surface; with Verify::structure_only or full
  /// (no checksums to vouch for the geometry) all of validate() runs. Throws
  /// geods::Error naming the file if it is missing, truncated, corrupt, of
  /// another kind or version, or fails those checks.
  static Voronoi3 load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);

  /// Checks, with a tolerance for the clipping's roundings (1e-11 of the box's
  /// extent per axis and the coordinates' rounding), what the cells promise; throws
  /// geods::Error naming the first violation. Independent of Delaunay3,
  /// O(size log n), and O(size h) more for h hull triangles:
  /// - every cell's faces are index loops into its vertices, each edge used
  ///   once in each direction (a closed, oriented surface);
  /// - every face label is another site's, a box side, or (clipped to the
  ///   hull) a hull triangle; every corner of the face lies on that
  ///   bisector, box side or hull plane, no corner of the cell beyond it (the
  ///   cell is convex), and the face turns outwards;
  /// - no corner is nearer to another site than to its own (a k-d tree over
  ///   the sites), so the cells do not overlap, and their volumes add up to
  ///   the box's (or the hull's): together they cover it;
  /// - a site inside the box (or the hull) has a cell with faces that holds
  ///   it, and each cell's volume and centroid are those of its faces.
  void validate() const;

 private:
  Voronoi3() = default;  // for load()
  void build(const Delaunay3& dt);
  void check_cells() const;  // validate()'s checks of indices and labels: what makes the cells safe to walk
  std::vector<Vec3d> points_;
  AABB3d box_;
  std::vector<std::array<std::uint32_t, 3>> hull_;
  std::vector<Voronoi3Cell> cells_;
};

}  // namespace geods::voronoi
