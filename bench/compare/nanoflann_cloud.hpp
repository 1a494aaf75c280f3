#pragma once
// nanoflann's dataset adaptor over a row-major float32 xyz array, shared by the
// nanoflann programs of bench/compare (no bounding box: nanoflann computes it).
#include <cstddef>

/// n points of 3 floats at `points`.
struct Cloud {
  const float* points;
  std::size_t n;
  std::size_t kdtree_get_point_count() const { return n; }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return points[3 * i + d]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};
