#pragma once
// A zero-copy view of n points stored row by row in the caller's array.
#include <cstddef>
#include <span>

#include "geods/core/vec.hpp"

namespace geods::spatial {

/// Point i starts at data + i * stride and has `dim` coordinates. The view does
/// not own the array: it must outlive every structure built over it, unchanged.
template <typename T>
struct PointView {
  const T* data = nullptr;
  std::size_t count = 0;
  std::size_t dim = 0;
  std::size_t stride = 0;  // elements from one point to the next, >= dim

  PointView() = default;
  /// stride 0 means tightly packed (stride = dim).
  PointView(const T* data_, std::size_t count_, std::size_t dim_, std::size_t stride_ = 0)
      : data(data_), count(count_), dim(dim_), stride(stride_ ? stride_ : dim_) {}
  /// Fixed-size Eigen vectors (e.g. std::vector<Vec3f>) are tightly packed coordinates.
  template <int N>
  PointView(std::span<const Vec<T, N>> points)  // NOLINT: implicit on purpose
      : PointView(points.empty() ? nullptr : points.data()->data(), points.size(), N,
                  sizeof(Vec<T, N>) / sizeof(T)) {}

  const T* operator[](std::size_t i) const { return data + i * stride; }
};

/// The squared Euclidean distance of two points of `dim` coordinates, summed
/// axis by axis: the one formula of the point searches, so that structures
/// that answer the same query give bit-identical distances.
template <typename T>
T squared_distance(const T* q, const T* p, std::size_t dim) {
  T d = 0;
  for (std::size_t a = 0; a < dim; ++a) {
    const T t = q[a] - p[a];
    d += t * t;
  }
  return d;
}

}  // namespace geods::spatial
