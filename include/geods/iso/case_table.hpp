#pragma once
// The marching-cubes case table, derived programmatically: for each of the 256
// inside/outside patterns of a cell's corners and each resolution of its
// ambiguous faces (asymptotic decider), the triangles as triples of cube edges.
//
// Cube conventions (shared by everything in geods::iso):
//   corner c = x + 2y + 4z (x, y, z in {0, 1});
//   edge e: 0-3 run along x at (y, z) = (e & 1, e >> 1), 4-7 along y at
//   (x, z) = (e & 1, (e - 4) >> 1), 8-11 along z at (x, y) = (e & 1, (e - 8) >> 1);
//   face f = 2 * axis + side (side 0: the face at coordinate 0 on that axis).
// A corner is inside when its sample is >= the iso-value. Triangles are
// oriented so that their normals point from inside to outside.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace geods::iso {

/// The two corners of cube edge e, lower corner first.
std::array<int, 2> edge_corners(int e);
/// The four corners of face f in face-local cyclic order (u, v) = (0,0), (1,0),
/// (1,1), (0,1), where u and v are the two other axes in increasing order. Both
/// cells sharing a face list its samples in the same order.
std::array<int, 4> face_corners(int f);

/// Faces of case `c` (bit f set) whose corners alternate inside/outside
/// diagonally, so that the contour on the face needs a decision.
std::uint8_t ambiguous_faces(int c);

/// Asymptotic decider on one face: the values relative to the iso-value at its
/// face-local corners (00, 10, 11, 01). Returns true if the two inside corners
/// are joined through the face (the bilinear saddle is inside, >= 0). Only
/// meaningful for an ambiguous face. Both cells sharing the face get the same
/// answer because they pass the same samples in the same order.
inline bool face_joins_inside(double v00, double v10, double v11, double v01) {
  const double d = v00 * v11 - v10 * v01;  // sign of the saddle value times the denominator's sign
  return v00 >= 0 ? d >= 0 : d <= 0;
}

/// Triangles of case `c` with face decisions `joined` (bit f set: the inside
/// corners of face f are joined; bits of non-ambiguous faces are ignored): a
/// flat list of vertices, three per triangle. 0-11 are the vertices on cube
/// edges; 12 + i is a vertex inside the cell, the mean of the edge vertices in
/// case_centres(c, joined)[i]: a contour loop that cannot be closed by
/// triangles between its edge points without an edge inside a cube face (which
/// the neighbour cell might use too) is fanned around such a centre.
std::span<const std::uint8_t> case_triangles(int c, std::uint8_t joined);

/// At most this many centre vertices per cell.
inline constexpr std::size_t kMaxCentres = 2;
/// Bit masks of the cube edges whose vertices average to each centre vertex.
std::span<const std::uint16_t> case_centres(int c, std::uint8_t joined);

/// Largest number of triangles of any table entry.
int max_case_triangles();

}  // namespace geods::iso
