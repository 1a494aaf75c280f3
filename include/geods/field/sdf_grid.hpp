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
// - Block lists: the same concavity bounds a face's squared distance at a
//   block corner from below by the trilinear interpolation of its distances
//   from the tile's corners less the spread of those corners about the
//   block corner; one vectorized pass over the tile's list evaluates these
//   bounds on the 4^3 lattice of block corners (shared along its rows) and
//   keeps, for each block, only the faces whose bound passes the block's
//   corner test, and only those get exact corner distances (on the sdf
//   workload a third of the tile's list instead of all of it).
// - Samples (§6.1.1's neighbour start): a sample's search starts from the
//   group of 8 faces that held its predecessor's closest face (within the
//   neighbour's distance + the spacing); by the same concavity, dist^2(p, f)
//   is at least the trilinear interpolation of f's distances from the
//   block's corners less the spread of the corners about p, so a group
//   whose bounds all exceed the best distance so far is skipped; a block's
//   list is sorted by each face's smallest corner distance, and the search
//   stops at the first group whose floor (that less the largest spread)
//   exceeds the best distance.
// - Sign: the mesh's SignMethod. With winding numbers on a closed mesh, a
//   sample whose distance and that of a neighbour earlier in the tile add up
//   to more than their separation takes the neighbour's sign (the segment
//   between them meets no surface); only samples near the surface compute
//   their own winding number (on open meshes every sample does).
#include <cstdint>
#include <limits>
#include <vector>

#include "geods/core/grid3.hpp"
#include "geods/field/mesh_distance.hpp"

namespace geods::field {

/// How the samples' distances are found: exact (the default), or by the
/// vector propagation of §6.1.1: exact closest points on a shell of samples
/// within sqrt 3 samples of the surface, then each sample takes the closest
/// of its 26 neighbours' closest points in a forward and a backward scan
/// (and the exact distance to that point's face). Never below the exact
/// distance, exact on the shell; elsewhere an upper bound whose error
/// docs/field.md measures.
enum class SdfMethod : std::uint8_t { exact, propagation };

/// "exact", "propagation"; geods::Error otherwise.
SdfMethod parse_sdf_method(std::string_view name);
std::string_view to_string(SdfMethod method);

struct SdfGridOptions {
  SdfMethod method = SdfMethod::exact;
  SignMethod sign = SignMethod::winding;
  /// Half-width of the narrow band in samples (of the smallest spacing): a
  /// sample farther from the surface gets +-infinity (the sign of its side).
  /// Infinity: the whole grid. (Exact method only.)
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
