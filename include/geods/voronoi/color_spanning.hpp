#pragma once
// The smallest color-spanning circle (seed §5.4.3): among points of m colors,
// the smallest circle that holds at least one point of every color.
//
// The optimum is the smallest enclosing circle of one point per color, so it
// is the circle on the diameter of two points or through three. An upper bound
// U comes first (the best circle centred at an input point: the farthest of
// its nearest point per color, by one k-d tree per color); then, for each
// point p, the circles through p and one or two points within 2U of p are
// tried in turn, each checked against the points within 2U of p, and U shrinks
// as better circles are found. O(n m log n + n d^3) for d points within 2U of
// a point (d is about the number of points a spanning circle holds: a few per
// color on spread-out input). Whether a point lies in a candidate circle is
// decided exactly (incircle, or an exact dot product for a diameter); radii
// are compared in floating point, so among circles whose radii tie to rounding
// either may be returned.
//
// Degenerate input: one color gives radius 0 at its first point; equal
// points of different colors give radius 0 where they lie; collinear triples
// have no circle (their pairs do). No points, a color count other than the
// point count, or NaN/infinite coordinates: geods::Error. Coordinates follow
// the range rule of core/coordinate_range.hpp (degree 3, as circumcentres).
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/vec.hpp"
#include "geods/voronoi/circles.hpp"

namespace geods::voronoi {

struct ColorSpanningCircle {
  Circle circle;
  std::vector<std::uint32_t> support;  // the 1 to 3 points that define the circle (on its boundary)
  std::vector<std::uint32_t> colors;   // the distinct colors, ascending
  std::vector<std::uint32_t> chosen;   // per color of `colors`, a point of that color in the circle (the nearest to its centre)
};

/// The smallest circle holding a point of every color; colors[i] is the color of point i (any values).
ColorSpanningCircle smallest_color_spanning_circle(std::span<const Vec2d> points, std::span<const std::uint32_t> colors);

}  // namespace geods::voronoi
