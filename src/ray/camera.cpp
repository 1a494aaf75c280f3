#include "geods/ray/camera.hpp"

#include <cmath>
#include <numbers>

#include "geods/core/error.hpp"

namespace geods::ray {

Camera Camera::framing(const AABB3f& bounds, const Vec3f& direction) {
  Camera camera;
  const AABB3f box = bounds.empty() ? AABB3f(Vec3f::Constant(-1), Vec3f::Constant(1)) : bounds;
  const float radius = std::max(0.5f * box.extent().norm(), 1e-6f * std::max(1.0f, box.hi.cwiseAbs().maxCoeff()));
  camera.target = box.center();
  const float half_fov = 0.5f * camera.vertical_fov_deg * std::numbers::pi_v<float> / 180.0f;
  // The bounding sphere fits the vertical field of view with 5% to spare.
  const float distance = 1.05f * radius / std::sin(half_fov);
  camera.eye = camera.target + distance * direction.normalized();
  return camera;
}

void Camera::check() const {
  if (!eye.allFinite() || !target.allFinite() || !up.allFinite() || !std::isfinite(vertical_fov_deg))
    throw Error("camera: non-finite eye, target, up or field of view");
  if (eye == target) throw Error("camera: the eye is at the target");
  if (!(vertical_fov_deg > 0 && vertical_fov_deg < 180)) throw Error("camera: field of view must be in (0, 180) degrees");
  const Vec3f forward = (target - eye).normalized();
  if (up.isZero(0) || forward.cross(up.normalized()).norm() < 1e-6f)
    throw Error("camera: the up vector is zero or parallel to the view direction");
}

Ray3f Camera::primary_ray(float x, float y, int width, int height) const {
  const Vec3f forward = (target - eye).normalized();
  const Vec3f right = forward.cross(up).normalized();
  const Vec3f true_up = right.cross(forward);
  const float h = std::tan(0.5f * vertical_fov_deg * std::numbers::pi_v<float> / 180.0f);
  const float aspect = float(width) / float(height);
  const float sx = (2.0f * x / float(width) - 1.0f) * h * aspect;
  const float sy = (1.0f - 2.0f * y / float(height)) * h;
  Ray3f ray;
  ray.origin = eye;
  ray.direction = (forward + sx * right + sy * true_up).normalized();
  return ray;
}

}  // namespace geods::ray
