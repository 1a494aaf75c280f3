#pragma once
// The exact Euclidean distance transform of a binary volume or image (seed
// §6.1: a distance field sampled on a grid, here from voxels rather than a
// mesh): for every foreground sample (nonzero), the distance to the nearest
// background sample (zero), 0 on the background; scipy's
// distance_transform_edt convention. Optionally the feature transform: which
// background sample is the nearest.
//
// Felzenszwalb and Huttenlocher's separable algorithm: the squared distance
// is a sum over the axes, so one pass per axis (x, then y, then z) replaces
// each line of the previous pass's values g by min_p g(p) + (s (q - p))^2,
// the lower envelope of one parabola per sample, in time linear in the line.
// The nearest sample's index travels with the envelope, so the feature
// transform costs one more array. Lines are independent: every pass is
// parallel over them, and the result does not depend on the thread count.
//
// Exactness: the output distance is computed from the feature found, as
// brute force computes it: ((sx dx)^2 + (sy dy)^2) + (sz dz)^2 in double.
// With integer spacings (the default spacing 1 included) every such value is
// an exact integer and the result equals brute force's bit for bit (tested);
// with other spacings a feature may differ from brute force's only where two
// background samples are nearest within rounding, so the distance differs by
// at most a few ulps.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "geods/core/grid3.hpp"

namespace geods::field {

struct EdtRequest {
  /// Sample spacing along x, y, z; unset: the mask's own spacing. Finite and > 0.
  std::optional<std::array<double, 3>> spacing;
  bool squared = false;   // squared distances (no square root)
  bool features = false;  // also the index of the nearest background sample
};

struct EdtResult {
  static constexpr std::uint64_t kNoFeature = std::numeric_limits<std::uint64_t>::max();
  /// Same dims, origin and spacing as the mask; +infinity everywhere if the
  /// mask has no background sample.
  Grid3<double> distance;
  /// With request.features: per sample, the flat index (x + nx (y + ny z)) of
  /// its nearest background sample (itself on the background; kNoFeature if
  /// there is none); ties go to the one of smallest (z, y, x).
  std::vector<std::uint64_t> features;
  std::size_t foreground = 0;  // nonzero samples of the mask
};

/// The distance transform of `mask` (nonzero = foreground). Time O(samples)
/// per axis, memory one double (and with features one index) per sample.
/// Throws geods::Error for a spacing that is not finite and positive, or so
/// small or large that squared distances would underflow or overflow
/// (below 1e-150, or above 1e150 times the side).
EdtResult edt(const Grid3View<std::uint8_t>& mask, const EdtRequest& request = {});

/// One separable pass of edt() on its own, in place: every line of g (x
/// fastest, dims) along `axis` (0 x, 1 y, 2 z) becomes
/// g'(q) = min_p g(p) + (spacing (q - p))^2 (+infinity: no sample to start
/// from). From g = 0 on the background and +infinity elsewhere, one pass per
/// axis gives the squared distances, each pass adding its axis's term in the
/// order of the passes. Lines are independent, so a caller can run the passes
/// over a volume cut in chunks, each chunk whole along the pass's axis
/// (geods.dask.edt). Throws geods::Error for a bad axis or spacing, or a size
/// mismatch.
void edt_pass(std::span<double> g, const std::array<std::size_t, 3>& dims, int axis, double spacing);

}  // namespace geods::field
