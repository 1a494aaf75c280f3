#pragma once
// A 2D image of interleaved channels, rows top to bottom.
#include <cstddef>
#include <vector>

#include "geods/core/error.hpp"

namespace geods {

template <typename T>
struct Image {
  using value_type = T;

  std::size_t width = 0, height = 0, channels = 1;
  std::vector<T> data;  // (y * width + x) * channels + c

  Image() = default;
  Image(std::size_t w, std::size_t h, std::size_t c = 1, T fill = T{})
      : width(w), height(h), channels(c), data(checked_size(w, h, c), fill) {}

  std::size_t size() const { return data.size(); }
  T& operator()(std::size_t x, std::size_t y, std::size_t c = 0) { return data[(y * width + x) * channels + c]; }
  const T& operator()(std::size_t x, std::size_t y, std::size_t c = 0) const {
    return data[(y * width + x) * channels + c];
  }

  static std::size_t checked_size(std::size_t w, std::size_t h, std::size_t c) {
    const std::size_t max = std::size_t(-1) / sizeof(T);
    if (h != 0 && w > max / h) throw Error("Image: dimensions overflow");
    if (c != 0 && w * h > max / c) throw Error("Image: dimensions overflow");
    return w * h * c;
  }
};

}  // namespace geods
