#pragma once
// Circle problems of seed §5.4.3: the smallest enclosing circle (Welzl) and the
// largest empty circle centred in the convex hull (from the Voronoi diagram).
#include <cstdint>
#include <span>

#include "geods/core/vec.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {

struct Circle {
  Vec2d center = Vec2d::Zero();
  double radius = 0;
};

/// The smallest circle containing every point: Welzl's randomized incremental
/// algorithm (expected O(n); the order is shuffled with a generator seeded by
/// `seed`, so the result is deterministic). Whether a point lies in the current
/// circle is decided exactly (the incircle predicate for circles through three
/// points, an exact dot product for circles on a diameter); the centre is then
/// computed in floating point and the radius is the largest distance from it to
/// any point, so every point lies within the returned circle.
/// Throws geods::Error for no points or non-finite coordinates.
Circle smallest_enclosing_circle(std::span<const Vec2d> points, std::uint64_t seed = 0);

/// The largest circle whose centre lies in the convex hull of the sites and
/// whose interior holds no site. Its centre is a Voronoi vertex inside the hull
/// or the crossing of a Voronoi edge with a hull edge (seed §5.4.3); the hull
/// edges are followed through the cells they cross. O(n log h) for h hull sites.
/// For collinear sites the hull is their segment; one distinct site gives radius 0.
Circle largest_empty_circle(const Voronoi2& diagram);
Circle largest_empty_circle(std::span<const Vec2d> points);

}  // namespace geods::voronoi
