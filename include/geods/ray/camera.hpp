#pragma once
// A pinhole camera: eye, look-at target, up vector and vertical field of view.
#include "geods/core/aabb.hpp"
#include "geods/core/ray.hpp"

namespace geods::ray {

struct Camera {
  Vec3f eye = Vec3f(0, 0, 3);
  Vec3f target = Vec3f::Zero();
  Vec3f up = Vec3f::UnitY();
  float vertical_fov_deg = 40;

  /// A pleasant three-quarter view of the box from above and to the front
  /// right (+x, +y, +z side), or from `direction` (from the box's centre
  /// towards the eye), far enough that the whole box fits the field of view.
  static Camera framing(const AABB3f& bounds, const Vec3f& direction = Vec3f(0.55f, 0.45f, 0.70f));

  /// Throws geods::Error for an eye at the target, a non-finite value, an up
  /// vector parallel to the view direction or a field of view outside (0, 180).
  void check() const;

  /// The primary ray through the point (x, y) of a width x height image, in
  /// pixels from the top left corner (x = 0.5, y = 0.5 is the first pixel's
  /// centre); the direction is normalized.
  Ray3f primary_ray(float x, float y, int width, int height) const;
};

}  // namespace geods::ray
