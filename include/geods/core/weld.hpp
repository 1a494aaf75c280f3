#pragma once
// Welding vertices at equal positions (the same floats, -0 and +0 alike): an
// STL file's corners become shared vertices, and field::MeshDistance finds the
// faces around a vertex that a mesh stores more than once.
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/vec.hpp"

namespace geods {

/// Per vertex, the smallest index of a vertex at the same position. No NaN coordinates.
std::vector<std::uint32_t> weld(std::span<const Vec3f> vertices);

}  // namespace geods
