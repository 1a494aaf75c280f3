#pragma once
// The exact signed distance field of a triangle mesh sampled on a grid
// (seed §6.1): every sample's distance to the mesh equals that of a
// brute-force search over all faces (up to float rounding), negative inside,
// on the whole grid or in a narrow band about the surface.
//
// Algorithm: the grid is cut into tiles of 8^3 samples, computed in parallel
// and independently (the result does not depend on the thread count). A tile
// gathers the only faces that can be closest to one of its samples, then
// each of its 4^3 blocks narrows that list, and each sample takes the
// minimum over its block's list:
// - Culling is exact, by one fact: for any set S and any point q,
//   dist^2(p, S) - |p - q|^2 is a concave function of p (|p|^2 cancels and a
//   minimum of affine functions remains), so over a box it is smallest at a
//   corner. If at each of the 8 corners of a box a face (or a node of the
//   hierarchy) is farther than a surface point q, it is farther than q from
//   every point of the box and is nobody's closest face there. q is the
//   closest point to the box's centre: for far boxes the test then passes
//   only faces within a small fraction of a sample of the true distance.
// - Neighbour starts (§6.1.1): a sample's search starts from the face that
//   was closest to the sample before it, which is within the neighbour's
//   distance + the spacing; a face whose bounding sphere is farther is
//   skipped without computing its distance.
// - Sign: the mesh's SignMethod. With winding numbers on a closed mesh, the
//   sign of a sample whose neighbour (earlier in the tile) is farther from it
//   than d(p) + d(neighbour) can't differ from the neighbour's (the segment
//   between them meets no surface); only samples near the surface compute
//   their own winding number (on open meshes every sample does).
#include <cstdint>
#include <limits>
#include <vector>

#include "geods/core/grid3.hpp"
#include "geods/field/mesh_distance.hpp"

namespace geods::field {

struct SdfGridOptions {
  SignMethod sign = SignMethod::winding;
  /// Half-width of the narrow band in samples (of the smallest spacing): a
  /// sample farther from the surface gets +-infinity (the sign of its side).
  /// Infinity: the whole grid.
  double band = std::numeric_limits<double>::infinity();
  /// Also the closest face of every sample (kNoIndex outside the band).
  bool faces = false;
};

struct SdfGridStats {
  std::size_t samples = 0;
  std::size_t in_band = 0;           // samples whose distance was computed
  std::size_t tiles = 0;             // tiles of 8^3 samples
  std::size_t tiles_outside = 0;     // tiles wholly outside the band (filled without distances)
  double candidates_per_sample = 0;  // mean length of the face lists the samples searched
  std::size_t winding_numbers = 0;   // samples whose sign took a winding number
};

struct SdfGrid {
  Grid3<float> distance;              // the field (C order [z][y][x])
  std::vector<std::uint32_t> faces;   // with SdfGridOptions::faces
  SdfGridStats stats;
};

/// Samples of margin sdf_grid_geometry leaves beyond the box on each side unless told otherwise.
inline constexpr double kDefaultPadding = 3;

/// The grid about a box (usually the mesh's bounds): samples `spacing`
/// apart, or, if spacing is 0, `res` samples along the box's longest side
/// (padding included); `padding` samples of margin on each side; the grid is
/// centred on the box, its samples at the centres of the cells of a box
/// `padding` samples larger on each side. Throws geods::Error for an empty
/// or non-finite box, res < 1 + 2 padding... (nothing to sample), a
/// non-finite or non-positive spacing, or a grid of more than 2^40 samples.
Grid3Geometry sdf_grid_geometry(const AABB3f& box, std::size_t res, double spacing = 0,
                                double padding = kDefaultPadding);

/// The signed distance field of the mesh at the samples of `grid` (any
/// origin and positive spacing, also anisotropic). Throws geods::Error for
/// bad spacings or band, and, before allocating, for grids larger than the
/// machine's memory. Time about O(samples x faces near each sample);
/// memory 4 bytes a sample (8 with faces).
SdfGrid sdf_grid(const MeshDistance& mesh, const Grid3Geometry& grid, const SdfGridOptions& options = {});
/// The same, building the MeshDistance of `mesh` first.
SdfGrid sdf_grid(const TriMesh& mesh, const Grid3Geometry& grid, const SdfGridOptions& options = {});

}  // namespace geods::field
