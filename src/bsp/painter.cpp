#include "geods/bsp/painter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "geods/core/error.hpp"

namespace geods::bsp {

PainterResult paint(const BspTree& tree, const PainterView& view, bool back_to_front) {
  if (view.width <= 0 || view.height <= 0) throw Error("paint: image size must be positive");
  const Vec3d fwd0 = view.target - view.eye;
  if (!(fwd0.norm() > 0) || !std::isfinite(fwd0.norm())) throw Error("paint: eye at the target or not finite");
  const Vec3d forward = fwd0.normalized();
  const Vec3d r0 = forward.cross(view.up);
  if (!(r0.norm() > 1e-12)) throw Error("paint: up vector parallel to the view direction");
  if (!(view.vertical_fov_deg > 0 && view.vertical_fov_deg < 180)) throw Error("paint: field of view outside (0, 180)");
  const Vec3d right = r0.normalized(), up = right.cross(forward);
  const double h = std::tan(0.5 * view.vertical_fov_deg * std::numbers::pi / 180);
  const double aspect = double(view.width) / double(view.height);
  const int W = view.width, H = view.height;

  // Frustum corners for the tree's culling: the eye and four far corners.
  const double far = 1e3 * (1 + (view.target - view.eye).norm());
  std::vector<Vec3d> frustum{view.eye};
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) frustum.push_back(view.eye + far * (forward + sx * h * aspect * right + sy * h * up));

  PainterResult res;
  res.triangle.assign(std::size_t(W) * std::size_t(H), kNoIndex);
  std::vector<std::uint8_t> covered(back_to_front ? 0 : res.triangle.size(), 0);
  const std::vector<std::uint32_t> order = tree.visibility_order(view.eye, back_to_front, frustum);
  res.fragments = order.size();
  std::vector<std::array<double, 2>> p;
  for (const std::uint32_t fi : order) {
    const Polygon& f = tree.fragments()[fi];
    p.clear();
    bool behind = false;
    for (std::size_t k = 0; k < f.size(); ++k) {
      const Vec3d w = tree.grid().to_world(tree.planes().point(f.vertex(k)));
      const Vec3d d = w - view.eye;
      const double z = d.dot(forward);
      if (!(z > 1e-9)) {
        behind = true;
        break;
      }
      const double sx = d.dot(right) / (z * h * aspect), sy = d.dot(up) / (z * h);
      p.push_back({(sx + 1) * 0.5 * W, (1 - sy) * 0.5 * H});
    }
    if (behind || p.size() < 3) continue;  // (the camera is outside the scene in the demo and tests)
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300, area = 0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      x0 = std::min(x0, p[k][0]), x1 = std::max(x1, p[k][0]), y0 = std::min(y0, p[k][1]), y1 = std::max(y1, p[k][1]);
      const auto& a = p[k];
      const auto& b = p[(k + 1) % p.size()];
      area += a[0] * b[1] - a[1] * b[0];
    }
    if (area == 0) continue;
    const int ix0 = std::max(0, int(std::floor(x0 - 0.5))), ix1 = std::min(W - 1, int(std::ceil(x1 - 0.5)));
    const int iy0 = std::max(0, int(std::floor(y0 - 0.5))), iy1 = std::min(H - 1, int(std::ceil(y1 - 0.5)));
    const double s = area > 0 ? 1 : -1;
    for (int y = iy0; y <= iy1; ++y)
      for (int x = ix0; x <= ix1; ++x) {
        const std::size_t pix = std::size_t(y) * std::size_t(W) + std::size_t(x);
        if (!back_to_front && covered[pix]) continue;
        const double cx = x + 0.5, cy = y + 0.5;
        bool inside = true;
        for (std::size_t k = 0; k < p.size() && inside; ++k) {
          const auto& a = p[k];
          const auto& b = p[(k + 1) % p.size()];
          inside = s * ((b[0] - a[0]) * (cy - a[1]) - (b[1] - a[1]) * (cx - a[0])) >= 0;
        }
        if (!inside) continue;
        res.triangle[pix] = f.source;
        ++res.pixel_writes;
        if (!back_to_front) covered[pix] = 1;
      }
  }
  return res;
}

}  // namespace geods::bsp
