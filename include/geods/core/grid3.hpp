#pragma once
// A dense 3D grid of samples (a volume) with origin and spacing.
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/error.hpp"

namespace geods {

/// Samples in C order [z][y][x] (x fastest): sample (i, j, k) sits at
/// origin + (i, j, k) * spacing in world space.
template <typename T>
struct Grid3 {
  using value_type = T;

  std::array<std::size_t, 3> dims{0, 0, 0};  // nx, ny, nz
  Vec3f origin = Vec3f::Zero();
  Vec3f spacing = Vec3f::Ones();
  std::vector<T> data;

  Grid3() = default;
  Grid3(std::size_t nx, std::size_t ny, std::size_t nz, T fill = T{})
      : dims{nx, ny, nz}, data(checked_size(nx, ny, nz), fill) {}

  std::size_t size() const { return data.size(); }
  std::size_t index(std::size_t i, std::size_t j, std::size_t k) const {
    return i + dims[0] * (j + dims[1] * k);
  }
  T& operator()(std::size_t i, std::size_t j, std::size_t k) { return data[index(i, j, k)]; }
  const T& operator()(std::size_t i, std::size_t j, std::size_t k) const { return data[index(i, j, k)]; }

  Vec3f position(std::size_t i, std::size_t j, std::size_t k) const {
    return origin + Vec3f(float(i), float(j), float(k)).cwiseProduct(spacing);
  }
  /// World-space box spanned by the sample positions.
  AABB3f bounds() const {
    if (size() == 0) return {};
    return {origin, position(dims[0] - 1, dims[1] - 1, dims[2] - 1)};
  }

  /// nx * ny * nz, or geods::Error if it overflows.
  static std::size_t checked_size(std::size_t nx, std::size_t ny, std::size_t nz) {
    const std::size_t max = std::size_t(-1) / sizeof(T);
    if (ny != 0 && nx > max / ny) throw Error("Grid3: dimensions overflow");
    const std::size_t nxy = nx * ny;
    if (nz != 0 && nxy > max / nz) throw Error("Grid3: dimensions overflow");
    return nxy * nz;
  }
};

/// The volume grown by one sample of `border` on every side, at the same
/// spacing (the origin moves one sample back, so every sample keeps its world
/// position). Each isosurface at an iso-value above (or below) `border` then
/// closes at the border of the volume.
template <typename T>
Grid3<T> padded(const Grid3<T>& volume, T border) {
  Grid3<T> p(volume.dims[0] + 2, volume.dims[1] + 2, volume.dims[2] + 2, border);
  p.spacing = volume.spacing;
  p.origin = volume.origin - volume.spacing;
  if (volume.size() == 0) return p;
  for (std::size_t k = 0; k < volume.dims[2]; ++k)
    for (std::size_t j = 0; j < volume.dims[1]; ++j)
      std::copy_n(&volume(0, j, k), volume.dims[0], &p(1, j + 1, k + 1));
  return p;
}

}  // namespace geods
