#pragma once
// A dense 3D grid of samples (a volume) with origin and spacing: owned (Grid3) or
// viewed in place (Grid3View), with one geometry and index arithmetic (Grid3Geometry).
#include <algorithm>
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/error.hpp"

namespace geods {

/// Where the samples of a volume sit and in which order, shared by Grid3 (which
/// owns its samples) and Grid3View (which reads them where they are): samples in
/// C order [z][y][x] (x fastest), sample (i, j, k) at origin + (i, j, k) * spacing
/// in world space.
struct Grid3Geometry {
  std::array<std::size_t, 3> dims{0, 0, 0};  // nx, ny, nz
  Vec3f origin = Vec3f::Zero();
  Vec3f spacing = Vec3f::Ones();

  std::size_t index(std::size_t i, std::size_t j, std::size_t k) const {
    return i + dims[0] * (j + dims[1] * k);
  }
  Vec3f position(std::size_t i, std::size_t j, std::size_t k) const {
    return origin + Vec3f(float(i), float(j), float(k)).cwiseProduct(spacing);
  }
  /// World-space box spanned by the sample positions (empty without samples).
  AABB3f bounds() const {
    if (dims[0] == 0 || dims[1] == 0 || dims[2] == 0) return {};
    return {origin, position(dims[0] - 1, dims[1] - 1, dims[2] - 1)};
  }
};

/// A read-only volume whose samples live elsewhere (in a Grid3, in a mapped
/// file): what the extractions read, so that a loaded MinMaxOctree gives its
/// mapped samples without a copy. Copying it copies no samples; they must
/// outlive it.
template <typename T>
struct Grid3View : Grid3Geometry {
  using value_type = T;

  std::span<const T> data;  // dims[0] * dims[1] * dims[2] samples

  Grid3View() = default;
  Grid3View(const Grid3Geometry& geometry, std::span<const T> samples) : Grid3Geometry(geometry), data(samples) {}

  std::size_t size() const { return data.size(); }
  const T& operator()(std::size_t i, std::size_t j, std::size_t k) const { return data[index(i, j, k)]; }
};

/// A volume that owns its samples.
template <typename T>
struct Grid3 : Grid3Geometry {
  using value_type = T;

  std::vector<T> data;

  Grid3() = default;
  Grid3(std::size_t nx, std::size_t ny, std::size_t nz, T fill = T{})
      : Grid3Geometry{{nx, ny, nz}}, data(checked_size(nx, ny, nz), fill) {}

  std::size_t size() const { return data.size(); }
  T& operator()(std::size_t i, std::size_t j, std::size_t k) { return data[index(i, j, k)]; }
  const T& operator()(std::size_t i, std::size_t j, std::size_t k) const { return data[index(i, j, k)]; }

  /// The samples in place (valid while this grid is neither changed in size nor destroyed).
  Grid3View<T> view() const { return {*this, data}; }

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
