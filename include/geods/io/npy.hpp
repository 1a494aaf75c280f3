#pragma once
// NumPy .npy arrays (format versions 1.0-3.0, C order, little- or big-endian in,
// little-endian out).
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "geods/core/dtype.hpp"

namespace geods::io {

/// An n-dimensional array of one element type, C order, native byte order.
struct NpyArray {
  DType dtype = DType::f64;
  std::vector<std::size_t> shape;
  std::vector<std::uint8_t> bytes;  // product(shape) * dtype_size(dtype) bytes

  std::size_t size() const;  // number of elements
  /// The elements converted to T (any numeric dtype converts).
  template <typename T> std::vector<T> to_vector() const;
};

/// Throws geods::Error for malformed headers, Fortran order, object or
/// unsupported dtypes, shapes whose size overflows or exceeds the file.
NpyArray read_npy(const std::filesystem::path& path);
void write_npy(const std::filesystem::path& path, const NpyArray& array);

template <typename T>
void write_npy(const std::filesystem::path& path, std::span<const T> data, std::vector<std::size_t> shape);

}  // namespace geods::io
