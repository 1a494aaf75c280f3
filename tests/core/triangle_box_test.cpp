// triangle_box_overlap against an independent oracle: polygon clipping.
#include <gtest/gtest.h>

#include <vector>

#include "geods/core/rng.hpp"
#include "geods/core/triangle_box.hpp"

namespace geods {
namespace {

Vec3f random_point(Rng& rng, float lo, float hi) {
  return {float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi))};
}

// An independent oracle for the triangle-box test: clip the triangle by the
// six box planes; it overlaps iff something is left.
bool clipped_nonempty(const Vec3f& a, const Vec3f& b, const Vec3f& c, const AABB3f& box) {
  std::vector<Vec3d> poly = {a.cast<double>(), b.cast<double>(), c.cast<double>()};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      std::vector<Vec3d> out;
      auto inside = [&](const Vec3d& p) { return side ? p[axis] <= box.hi[axis] : p[axis] >= box.lo[axis]; };
      const double plane = side ? box.hi[axis] : box.lo[axis];
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Vec3d& p = poly[i];
        const Vec3d& q = poly[(i + 1) % poly.size()];
        if (inside(p)) out.push_back(p);
        if (inside(p) != inside(q)) {
          Vec3d x = p + (plane - p[axis]) / (q[axis] - p[axis]) * (q - p);
          x[axis] = plane;
          out.push_back(x);
        }
      }
      poly = out;
      if (poly.empty()) return false;
    }
  return true;
}

TEST(TriangleBox, AgreesWithPolygonClipping) {
  Rng rng(31);
  int overlapping = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f a = random_point(rng, -1, 1), b = random_point(rng, -1, 1), c = random_point(rng, -1, 1);
    const Vec3f lo = random_point(rng, -1, 0.5f);
    const AABB3f box(lo, lo + random_point(rng, 0.01f, 0.5f));
    const bool expected = clipped_nonempty(a, b, c, box);
    ASSERT_EQ(triangle_box_overlap(a, b, c, box), expected) << i;
    overlapping += expected;
  }
  EXPECT_GT(overlapping, 1000);
}

}  // namespace
}  // namespace geods
