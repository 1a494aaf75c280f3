#pragma once
// Chamfer distance transforms (seed §6.1.1, the propagation method, Figure
// 61): the distance of every foreground sample of a mask to the nearest
// background sample, approximated by propagating known distances to
// neighbours through a small "distance matrix" d_M of local steps:
// D(x) = min over offsets m of D(x + m) + d_M(m), in a forward raster scan
// (z, y, x increasing, the half of the matrix already visited) and a backward
// one (the other half). The convention is edt()'s (scipy's): 0 on the
// background, the distance to the nearest zero elsewhere.
//
// Matrices (local steps scaled by the spacing, Euclidean lengths as in
// Figure 61): size 3 = the 26 neighbours (steps 1, sqrt 2, sqrt 3); size 5 =
// the 5x5x5 matrix without the steps that are multiples of smaller ones (98
// steps: also sqrt 5, sqrt 6, 3). The two scans give the exact chamfer
// distance: the length of the shortest path of such steps to a background
// sample (tested against Dijkstra's algorithm on the grid). It is never below
// the Euclidean distance and, with unit spacing, at most (1 + e) times it,
// e = chamfer_max_error(size): 12.8 % for size 3 (the worst direction is
// (1, sqrt 2 - 1, sqrt 3 - sqrt 2)), 4.9 % for size 5 (tested against edt()).
#include <array>
#include <cstdint>
#include <optional>

#include "geods/core/grid3.hpp"

namespace geods::field {

struct ChamferRequest {
  int size = 3;  // 3 or 5: the side of the distance matrix
  /// Sample spacing along x, y, z; unset: the mask's own. Finite and > 0.
  std::optional<std::array<double, 3>> spacing;
};

/// Largest relative overestimate (chamfer / Euclidean - 1) of the chamfer
/// distance with unit spacing, for size 3 and 5: the worst direction of the
/// chamfer norm (taken over directions with integer coordinates up to 64).
double chamfer_max_error(int size);

/// The chamfer distance transform of `mask` (nonzero = foreground): +infinity
/// everywhere if it has no background sample. Time O(samples x steps), two
/// scans (sequential: each sample needs its predecessors). Throws
/// geods::Error for a size other than 3 or 5 or a bad spacing.
Grid3<double> chamfer(const Grid3View<std::uint8_t>& mask, const ChamferRequest& request = {});

}  // namespace geods::field
