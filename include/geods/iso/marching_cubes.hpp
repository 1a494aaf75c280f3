#pragma once
// Marching cubes over a whole volume (the exhaustive scan), regular or curvilinear.
#include <cstdint>
#include <span>

#include "geods/core/grid3.hpp"
#include "geods/core/progress.hpp"
#include "geods/core/tri_mesh.hpp"

namespace geods::iso {

struct IsoOptions {
  /// Per-vertex normals from the central-difference gradient of the field,
  /// pointing from inside (samples >= iso) to outside.
  bool normals = true;
  /// A curvilinear grid: the physical position of every sample, in the
  /// volume's order (x fastest). Cases are computed in index space and the
  /// vertices placed between these positions; origin and spacing are then
  /// unused. Empty: the regular grid origin + (i, j, k) * spacing.
  std::span<const Vec3f> positions;
  /// Called from the calling thread with stage "isosurface" and the fraction
  /// done (throttled); returning false stops the extraction with
  /// geods::Error("isosurface: cancelled"). With a callback the work runs in
  /// batches between the reports (the scan in at least 32 slabs, some planes
  /// made twice); the output is the same.
  ProgressCallback progress;
};

/// The isosurface {value = iso} of a volume by marching cubes. A sample is
/// inside when it is >= iso; faces with diagonally alternating corners are
/// resolved by the asymptotic decider, identically in both cells sharing them,
/// so a level set that does not touch the border gives a closed, consistently
/// oriented 2-manifold (normals from inside to outside) with one vertex per
/// crossed grid edge and no zero-area triangles. Vertices are kept at least
/// 1e-3 of an edge away from the samples.
///
/// The scan works slab by slab in z and row by row in x, skipping the parts of
/// each row where the four rows of a cell row do not change side (as flying
/// edges does), with the vertices of the current slab in flat arrays. Slabs run
/// in parallel and are merged so that the output (vertex and triangle order
/// included) is the same for any number of threads. O(samples + output).
/// Throws geods::Error for a non-finite iso-value, a NaN or infinite sample, or positions
/// of the wrong count or not finite. T: uint8, uint16, int16, float, double.
/// If `cells_visited` is given, it receives the number of cells whose corners
/// were examined (those in the trimmed row ranges).
template <typename T>
TriMesh isosurface(const Grid3View<T>& volume, double iso, const IsoOptions& options = {},
                   std::size_t* cells_visited = nullptr);

/// The same over the samples of a Grid3, in place.
template <typename T>
TriMesh isosurface(const Grid3<T>& volume, double iso, const IsoOptions& options = {},
                   std::size_t* cells_visited = nullptr) {
  return isosurface(volume.view(), iso, options, cells_visited);
}

}  // namespace geods::iso
