#pragma once
// Boolean operations on closed triangle meshes by merging BSP trees (seed §3.3,
// Naylor et al.): both meshes are snapped to one grid (bsp_tree.hpp) and share one
// plane table; every inner node gets its face, the node's plane clipped to its cell
// (plane_based.hpp polygons). merge(T1, T2) splits T2 by the root plane of T1 with
// split-tree (cases: leaf, coplanar same/opposite orientation, the face on one side
// with the other child's cell on either side of the plane (Chin's test on the
// node's face), and mixed), recurses, and at a leaf applies the cell-op table.
//
// The boundary of the result is extracted from the merged tree: each boundary
// fragment of A (and of B, minus the parts that lie on A's boundary) is pushed down
// the merged tree; at the first node whose plane contains it, the pieces are pushed
// to the front side and then the back side, and a piece whose two sides have
// different labels is emitted, oriented from inside to outside. Pieces become a
// triangle mesh: vertices that are the same exact point are welded, vertices lying on
// a piece's side are inserted into it (T-junctions), and pieces are fanned. All the
// decisions are exact on the snapped input, so the output is closed (every directed
// edge has its opposite) and consistently oriented; its vertices are rounded to
// doubles.
//
// The default method (`local`) gives the same solid without the global trees: only
// triangles near the other operand are cut. The triangles of each operand are snapped;
// a triangle whose box, grown by one grid step, meets a triangle of the other operand
// (a uniform grid over the integer boxes) gets a local BSP: the other operand's triangles
// clipped to that box, auto-partitioned, each leaf labelled by the polygon whose plane
// bounds it (every leaf is a child of a node carrying a polygon, and the box holds all of
// the other surface there, so the labels are exact for every point of the box). The
// triangle is pushed down it like a fragment down the merged tree (coplanar pieces get
// front/back labels). The other triangles lie in no part of the other surface: each
// connected set of them (shared vertices) is inside or outside as a whole, labelled by
// locating one of its vertices in a neighbouring triangle's local BSP (or, for a component
// far from the other operand, in a BSP of the whole other operand), and kept or dropped
// whole. Same extraction rules and meshing as the merge.
#include <string_view>

#include "geods/bsp/bsp_tree.hpp"

namespace geods::bsp {

// "union" and "xor" are C++ keywords: the enum values carry a trailing underscore,
// the strings (Python, CLI) do not.
enum class CsgOp { union_, intersection, difference, xor_ };
/// Parses "union", "intersection", "difference" or "xor".
CsgOp parse_csg_op(std::string_view name);
std::string_view csg_op_name(CsgOp op);

enum class CsgMethod { local, bsp_merge };
/// Parses "local" or "bsp_merge".
CsgMethod parse_csg_method(std::string_view name);
std::string_view csg_method_name(CsgMethod m);

struct CsgStats {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  bool closed = false;       // every directed edge has its opposite
  double volume = 0;         // signed volume of the result
  double volume_a = 0;       // volumes of the snapped operands (the identities' terms)
  double volume_b = 0;
  std::size_t bsp_nodes = 0; // nodes of the merged tree (local: of all local BSPs)
  std::size_t pieces = 0;    // boundary polygons before triangulation
  std::size_t t_junctions = 0;
  double compute_s = 0;
};

struct CsgResult {
  Triangles mesh;
  CsgStats stats;
};

/// A op B for closed, outward-oriented meshes. Throws geods::Error on bad input
/// (non-finite coordinates, indices out of range, empty or fully degenerate meshes).
/// options: the BSP construction of the operands (bsp_merge; local uses it only for a
/// component far from the other operand).
CsgResult csg(const Triangles& a, const Triangles& b, CsgOp op, const BuildOptions& options = {},
              CsgMethod method = CsgMethod::local);

/// Signed volume of a triangle mesh and whether every directed edge has its opposite.
double signed_volume(const Triangles& m);
bool is_closed(const Triangles& m);

}  // namespace geods::bsp
