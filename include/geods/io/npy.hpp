#pragma once
// NumPy .npy arrays (format versions 1.0-3.0, C or Fortran order and little- or
// big-endian in; C order, little-endian out).
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
  /// The elements converted to T (any numeric dtype converts). Throws
  /// geods::Error for a value T cannot hold (NaN or 300.0 to u8, -1 to u32).
  template <typename T> std::vector<T> to_vector() const;
};

/// Reads dtypes u1..u8, i1..i8, f4, f8 in any byte order and bool (as u8);
/// a Fortran-order array is rearranged into C order (same shape, same values).
/// Throws geods::Error naming the file for malformed headers,
/// structured or unsupported dtypes, shapes whose size overflows, and data
/// that does not exactly fill the rest of the file (checked before allocating).
NpyArray read_npy(const std::filesystem::path& path);
/// Writes format 1.0 (2.0 for huge headers), little-endian, C order, to a
/// path ending in .npy, or to standard output for "-"; another name is an error.
void write_npy(const std::filesystem::path& path, const NpyArray& array);

/// Writes `data` with the given shape; T is any type with a dtype_of<T>().
template <typename T>
void write_npy(const std::filesystem::path& path, std::span<const T> data, std::vector<std::size_t> shape);

}  // namespace geods::io
