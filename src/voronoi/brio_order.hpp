#pragma once
// Biased randomized insertion order (BRIO, Amenta-Choi-Rote) for incremental
// Delaunay: random rounds of doubling size, each sorted along a Hilbert curve,
// so that insertion is randomized (expected O(n log n)) and each point lands
// close to the previous one (the walk takes a few steps).
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/vec.hpp"

namespace geods::voronoi {

/// The indices in `active` (into `points`) in BRIO order; deterministic for a seed.
std::vector<std::uint32_t> brio_order(std::span<const Vec2d> points, std::span<const std::uint32_t> active,
                                      std::uint64_t seed);
/// The same in 3D, each round sorted along a 3D Hilbert curve (Skilling's
/// transpose form on a 2^9 grid per axis).
std::vector<std::uint32_t> brio_order(std::span<const Vec3d> points, std::span<const std::uint32_t> active,
                                      std::uint64_t seed);

}  // namespace geods::voronoi
