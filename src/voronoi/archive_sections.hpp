#pragma once
// Sections of the voronoi structures' archives (core/archive.hpp): points as
// pairs of doubles, and index arrays checked against their range on load, so
// that a loaded structure never indexes outside its arrays; both viewed in place.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

/// The coordinates of `points`, x0, y0, x1, y1, ... (a view).
inline std::span<const double> coordinates_of(std::span<const Vec2d> points) {
  return {points.empty() ? nullptr : points.data()->data(), 2 * points.size()};
}

/// The same for points in space: x0, y0, z0, x1, ...
inline std::span<const double> coordinates_of(std::span<const Vec3d> points) {
  return {points.empty() ? nullptr : points.data()->data(), 3 * points.size()};
}

/// The points of section `name` (pairs, or triples for Vec3d, of doubles) viewed in place, checked finite.
template <class Point = Vec2d>
inline FlatArray<Point> read_points(const Archive& archive, std::string_view name) {
  FlatArray<Point> points = archive.grouped<Point, double>(name);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw archive.error(std::string(name) + ": point " + std::to_string(i) + " is not finite");
  return points;
}

/// The indices of section `name` (of `count` elements unless count is -1)
/// viewed in place, each below `limit` or one of `special`.
inline FlatArray<std::uint32_t> read_indices(const Archive& archive, std::string_view name, std::uint64_t limit,
                                             std::initializer_list<std::uint32_t> special = {},
                                             std::uint64_t count = std::uint64_t(-1)) {
  FlatArray<std::uint32_t> a =
      count == std::uint64_t(-1) ? archive.array<std::uint32_t>(name) : archive.array<std::uint32_t>(name, count);
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k] >= limit && std::find(special.begin(), special.end(), a[k]) == special.end())
      throw archive.error(std::string(name) + ": entry " + std::to_string(k) + " (" + std::to_string(a[k]) +
                          ") is out of range");
  return a;
}

}  // namespace geods::voronoi
