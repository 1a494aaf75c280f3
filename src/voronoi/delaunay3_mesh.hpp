#pragma once
// The closed tetrahedralization that Delaunay3 builds and queries: flat arrays
// over internal vertices, a ghost vertex on the far side of every hull face,
// and the steps of Bowyer-Watson insertion (walk, cavity, star). The arrays
// belong to the Delaunay3; a Tet3Mesh works on them by reference.
//
// Slot t holds tets[8t .. 8t+3], its vertices, and tets[8t+4 .. 8t+7], its
// adjacencies, side by side in one cache line: adjacency 4u + g means
// neighbour u, where this face is u's face g (opposite u's vertex g). Tetrahedra are positively oriented (orient() > 0); a ghost tetrahedron
// is oriented as if its ghost were a point beyond its hull face.
#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "geods/core/predicates.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

struct Tet3Mesh {
  static constexpr std::uint32_t kNone = std::uint32_t(-1);    // a free slot's vertices
  static constexpr std::uint32_t kGhost = std::uint32_t(-2);   // the vertex at infinity
  static constexpr std::uint32_t kGhostBit = 1u << 31;         // set in kGhost and kNone, never in a vertex

  Tet3Mesh(std::vector<Vec3d>& c, std::vector<std::uint32_t>& t, std::vector<std::uint32_t>& f)
      : coords(c), tets(t), free_slots(f) {}

  std::vector<Vec3d>& coords;
  std::vector<std::uint32_t>& tets;
  std::vector<std::uint32_t>& free_slots;
  std::vector<std::uint8_t> mark;  // per slot, during an insertion: in the cavity (0x10 | its boundary faces, or 1 in the flips), 2 tested and not; else 0
  std::uint32_t last = 0;  // where the next walk starts
  std::uint32_t random = 2463534242u;
  std::size_t walk_steps = 0, conflicts = 0;

  /// det(b - a, c - a, d - a): > 0 for a positively oriented tetrahedron (exact sign).
  static double orient(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
    return -orient3d(a.data(), b.data(), c.data(), d.data());
  }
  /// For a positive (a, b, c, d): > 0 if e is inside their sphere, < 0 outside, 0 on it (exact sign).
  static double in_sphere(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, const Vec3d& e) {
    return -insphere(a.data(), b.data(), c.data(), d.data(), e.data());
  }
  static bool lex_less(const Vec3d& a, const Vec3d& b) {
    if (a[0] != b[0]) return a[0] < b[0];
    if (a[1] != b[1]) return a[1] < b[1];
    return a[2] < b[2];
  }
  /// The perturbed in-sphere test for in_sphere(q...) == 0, p distinct from the q's.
  static bool perturbed_inside(const Vec3d* const q[4], const Vec3d& p);
  /// The face opposite vertex i, as indices into the tetrahedron, counter-clockwise
  /// seen from vertex i's side.
  static std::array<int, 3> face_towards(int i) {
    return i % 2 == 0 ? std::array<int, 3>{(i + 1) % 4, (i + 3) % 4, (i + 2) % 4}
                      : std::array<int, 3>{(i + 1) % 4, (i + 2) % 4, (i + 3) % 4};
  }

  bool is_ghost(std::uint32_t t) const {
    const std::uint32_t* v = &tets[8 * std::size_t(t)];
    return ((v[0] | v[1] | v[2] | v[3]) & kGhostBit) != 0;
  }
  int ghost_index(std::uint32_t t) const {
    const std::uint32_t* v = &tets[8 * std::size_t(t)];
    for (int k = 0; k < 4; ++k)
      if (v[k] == kGhost) return k;
    return -1;
  }
  /// p inside the (perturbed) circumsphere of t; for a ghost t: p beyond its
  /// hull face, or on its plane and in conflict with the tetrahedron behind it.
  bool in_conflict(std::uint32_t t, const Vec3d& p) const {
    return conflict(coords.data(), tets.data(), t, p);
  }
  /// The same over raw arrays (the insertion's hot loop).
  static bool conflict(const Vec3d* C, const std::uint32_t* T, std::uint32_t t, const Vec3d& p) {
    const std::uint32_t* v = &T[8 * std::size_t(t)];
    if (((v[0] | v[1] | v[2] | v[3]) & kGhostBit) == 0) [[likely]] {
      const double s = in_sphere(C[v[0]], C[v[1]], C[v[2]], C[v[3]], p);
      if (s != 0) [[likely]]
        return s > 0;
      const Vec3d* q[4] = {&C[v[0]], &C[v[1]], &C[v[2]], &C[v[3]]};
      return perturbed_inside(q, p);
    }
    return ghost_conflict(C, T, t, p);
  }
  /// conflict() for a ghost tetrahedron.
  static bool ghost_conflict(const Vec3d* C, const std::uint32_t* T, std::uint32_t t, const Vec3d& p);
  /// Where adjacency a = 4u + g is stored (u's face g), and u's vertex g opposite it.
  static std::size_t entry(std::uint32_t a) { return 8 * std::size_t(a >> 2) + 4 + (a & 3); }
  static std::size_t opposite(std::uint32_t a) { return 8 * std::size_t(a >> 2) + (a & 3); }
  /// The tetrahedron whose closed volume holds p, or a ghost one whose hull
  /// face p lies strictly beyond: a stochastic visibility walk from t.
  std::uint32_t walk(const Vec3d& p, std::uint32_t t, std::size_t& steps, std::uint32_t& random) const;

  /// The first tetrahedron of four vertices (not coplanar) and its four ghosts.
  void make_first(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d);
  /// Inserts vertex pv (coords[pv] set): kNone, or the vertex at the same place (nothing changes).
  std::uint32_t insert(std::uint32_t pv);
  std::uint32_t new_slot();
  void free_slot(std::uint32_t s);

  struct Boundary {
    std::uint32_t v[4];  // the new tetrahedron: the cavity one with p in place of the vertex facing out
    std::uint32_t face;  // its face on the cavity's boundary
    std::uint32_t outer;  // the adjacency across it
    std::uint32_t cell;  // the cavity slot it is made from
  };
  std::vector<std::uint32_t> stack, cavity;
  std::vector<Boundary> boundary;
  struct EdgeEntry {  // a new tetrahedron's face through p, by its directed edge (a, b)
    std::uint32_t a = 0, b = 0, adjacency = 0, stamp = 0;
  };
  std::vector<EdgeEntry> edge_table;  // open addressing; an entry is used if its stamp is edge_stamp
  std::uint32_t edge_stamp = 0;

  // Flip-based insertion (delaunay3_flip.cpp): insert() defers to
  // insert_by_flips() when `flips` is set; same answer, same tetrahedralization.
  enum FlipCount { flip_14, flip_23, flip_32, flip_44, flip_split, flip_hull, flip_unflippable, flip_repair };
  bool flips = false;
  std::array<std::size_t, 8> flip_counts{};
  /// Flips per insertion after which the rest of the stack is left to the
  /// repair step (a cavity step from the star, as if the flips were stuck):
  /// unlimited in Delaunay3; tests lower it to exercise the repair.
  std::size_t flip_budget = std::size_t(-1);
  std::uint32_t insert_by_flips(std::uint32_t pv);
  std::vector<std::uint32_t> flip_stack, flip_skipped;
  struct FaceKey {
    std::array<std::uint32_t, 3> key;  // the face's vertices, ascending
    std::uint32_t adjacency;           // 4 * slot + face index
    bool outer;                        // a face outside the replaced set
  };
  std::vector<FaceKey> faces;
};

/// Refilling a region of a closed tetrahedralization (a removed vertex's star,
/// the seam of a parallel build) from another tetrahedralization, the filler,
/// over the region's vertices: the filler's slots inside the region are those
/// with one of the region's boundary faces (oriented: the side towards the
/// region), and those reached from them across other faces.
struct RegionFill {
  using Face = std::array<std::uint32_t, 3>;
  /// A face as its three vertices counter-clockwise seen from the side of
  /// vertex `opposite`, rotated to start at the smallest.
  static Face face_of(const std::uint32_t* vertices, int opposite);

  std::vector<std::pair<Face, std::uint32_t>> boundary;  // seen from inside the region; the adjacency across it
  std::vector<std::uint32_t> mapped;  // the filler's slots over the region's vertex ids
  std::vector<std::uint32_t> outer;   // per filler slot face: the adjacency across it on the boundary, or kNone
  std::vector<std::uint32_t> fill;    // the filler's slots inside the region
  std::vector<std::uint32_t> slot;    // per filler slot: where it goes (the caller sets it for fill's)

  /// Matches the boundary against the filler's slots (vertex k of the filler
  /// is ids[k]); false if there is no boundary or a face of it has no match.
  bool match(const std::vector<std::uint32_t>& filler, std::span<const std::uint32_t> ids);
  /// Writes the fill into `tets` at its slots, linked to each other and across the boundary.
  void write(std::vector<std::uint32_t>& tets) const;
};

}  // namespace geods::voronoi
