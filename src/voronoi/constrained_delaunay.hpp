#pragma once
// Constrained Delaunay triangulation (seed §5.3.2) on DelaunayCore: segments
// are inserted after the points, each as a union of edges marked constrained
// (per half-edge, twins alike); the triangles a segment crosses are removed and
// each side of it is retriangulated (Anglada's algorithm). The marks then ride
// along as the core's Hooks: splits keep them on both halves of an edge, flips
// never touch a marked edge.
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "geods/core/vec.hpp"
#include "geods/voronoi/delaunay_core.hpp"

namespace geods::voronoi {

class ConstrainedDelaunay {
 public:
  /// Segments to insert, as pairs of internal vertices.
  using Pending = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
  /// A segment crossing a constrained edge: both split at `point` (their
  /// intersection rounded to doubles), which the caller inserts as a vertex and
  /// then inserts the four pieces from the end points `u`, `w` of the edge and
  /// those of the segment.
  struct Crossing {
    std::uint32_t edge, u, w;
    Vec2d point;
  };

  /// `marks` holds one flag per half-edge of `core` (resized as the core grows);
  /// the core's vertex_edge must be current (publish() leaves it so).
  ConstrainedDelaunay(DelaunayCore& core, std::vector<std::uint8_t>& marks) : core_(&core), marks_(&marks) {}

  /// Makes segment a-b (internal vertices) a path of constrained edges. A vertex
  /// on the segment splits it: the rest is pushed to `pending`. Returns the
  /// crossing when a-b crosses a constrained edge (that edge is then unmarked,
  /// and flipped as Delaunay asks).
  std::optional<Crossing> insert_segment(std::uint32_t a, std::uint32_t b, Pending& pending);

  // Hooks.
  void split_triangle(std::uint32_t t, std::uint32_t t1, std::uint32_t t2);
  void split_edge(std::uint32_t e, std::uint32_t twin, std::uint32_t t1, std::uint32_t t2);
  void flip(std::uint32_t e, std::uint32_t f);
  bool fixed(std::uint32_t e) const { return (*marks_)[e] != 0; }

 private:
  void mark(std::uint32_t e);
  void grow();  // one mark per half-edge of the core
  void note_vertex_edges(std::initializer_list<std::uint32_t> half_edges);
  Crossing split_crossing(std::uint32_t a, std::uint32_t b, std::uint32_t crossing);
  void fill_cavity(std::uint32_t a, std::uint32_t b, std::vector<std::uint32_t> cavity, std::vector<std::uint32_t> left,
                   std::vector<std::uint32_t> right);
  void flip_in(std::uint32_t a, std::uint32_t b, const std::vector<std::uint32_t>& crossed);
  std::uint32_t find_edge(std::uint32_t u, std::uint32_t w) const;  // the half-edge u -> w, or none

  DelaunayCore* core_;
  std::vector<std::uint8_t>* marks_;
};

}  // namespace geods::voronoi
