#pragma once
// A dense 3D grid of samples (a volume) with origin and spacing.
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

}  // namespace geods
