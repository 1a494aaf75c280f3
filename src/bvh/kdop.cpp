// Volume and surface area of a k-DOP: the box of the first three slabs is
// clipped by the half-spaces of the other slabs (each face polygon clipped,
// the cut closed by a new face), then measured face by face.
#include <algorithm>
#include <cmath>
#include <vector>

#include "geods/bvh/kdop.hpp"

namespace geods::bvh {
namespace {

using Polygon = std::vector<Vec3d>;

// Keeps the part of the polytope where n·x <= d; returns the cut points too.
void clip(std::vector<Polygon>& faces, const Vec3d& n, double d) {
  std::vector<Polygon> kept;
  std::vector<Vec3d> cut;
  for (const Polygon& f : faces) {
    Polygon out;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Vec3d& p = f[i];
      const Vec3d& q = f[(i + 1) % f.size()];
      const double sp = n.dot(p) - d, sq = n.dot(q) - d;
      if (sp <= 0) out.push_back(p);
      if ((sp < 0 && sq > 0) || (sp > 0 && sq < 0)) {
        const Vec3d x = p + (sp / (sp - sq)) * (q - p);
        out.push_back(x);
        cut.push_back(x);
      } else if (sp == 0) {
        cut.push_back(p);
      }
    }
    if (out.size() >= 3) kept.push_back(std::move(out));
  }
  if (cut.size() >= 3) {
    // The new face: the cut points sorted by angle around their centroid.
    Vec3d centroid = Vec3d::Zero();
    for (const auto& x : cut) centroid += x;
    centroid /= double(cut.size());
    const Vec3d u = n.unitOrthogonal(), w = n.normalized().cross(u);
    std::sort(cut.begin(), cut.end(), [&](const Vec3d& a, const Vec3d& b) {
      return std::atan2((a - centroid).dot(w), (a - centroid).dot(u)) <
             std::atan2((b - centroid).dot(w), (b - centroid).dot(u));
    });
    kept.push_back(std::move(cut));
  }
  faces = std::move(kept);
}

}  // namespace

std::pair<double, double> slab_polytope_measures(std::span<const Vec3d> directions, std::span<const double> lo,
                                                 std::span<const double> hi) {
  const Vec3d a(lo[0], lo[1], lo[2]), b(hi[0], hi[1], hi[2]);
  if ((b - a).minCoeff() < 0) return {0.0, 0.0};
  auto corner = [&](int i) { return Vec3d((i & 1) ? b[0] : a[0], (i & 2) ? b[1] : a[1], (i & 4) ? b[2] : a[2]); };
  std::vector<Polygon> faces = {{corner(0), corner(2), corner(6), corner(4)}, {corner(1), corner(5), corner(7), corner(3)},
                                {corner(0), corner(4), corner(5), corner(1)}, {corner(2), corner(3), corner(7), corner(6)},
                                {corner(0), corner(1), corner(3), corner(2)}, {corner(4), corner(6), corner(7), corner(5)}};
  for (std::size_t i = 3; i < directions.size(); ++i) {
    clip(faces, directions[i], hi[i]);
    clip(faces, -directions[i], -lo[i]);
  }
  // Area: each face's polygon area. Volume: pyramids from an interior point,
  // |base area x height| summed (orientation-free, the polytope is convex).
  Vec3d inside = Vec3d::Zero();
  std::size_t count = 0;
  for (const auto& f : faces)
    for (const auto& p : f) inside += p, ++count;
  if (count == 0) return {0.0, 0.0};
  inside /= double(count);
  double area = 0, volume = 0;
  for (const auto& f : faces) {
    Vec3d normal = Vec3d::Zero();
    for (std::size_t i = 1; i + 1 < f.size(); ++i) normal += (f[i] - f[0]).cross(f[i + 1] - f[0]);
    const double face_area = normal.norm() / 2;
    area += face_area;
    if (face_area > 0) volume += face_area * std::abs((f[0] - inside).dot(normal.normalized())) / 3;
  }
  return {volume, area};
}

}  // namespace geods::bvh
