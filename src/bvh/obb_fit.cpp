// Orientation of a fitted OBB: the principal axes, or the smallest of boxes
// along the principal axes, the principal axes of the hull surface, and
// hull-face-flush boxes.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "geods/bvh/obb.hpp"
#include "geods/core/convex_hull3.hpp"

namespace geods::bvh::detail {
namespace {

constexpr std::size_t kFaceCandidates = 16;

// Eigenvectors of a covariance matrix, largest variance first, right-handed;
// the coordinate axes if the solver fails.
Eigen::Matrix3d principal_axes(const Eigen::Matrix3d& cov) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  if (solver.info() == Eigen::Success && std::isfinite(solver.eigenvectors().sum())) {
    axes = solver.eigenvectors();
    axes.col(0).swap(axes.col(2));
    axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
  }
  return axes;
}

Eigen::Matrix3d point_covariance(std::span<const Vec3d> points) {
  Vec3d mean = Vec3d::Zero();
  for (const Vec3d& p : points) mean += p;
  mean /= double(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3d& p : points) cov += (p - mean) * (p - mean).transpose();
  return cov;
}

// Covariance of the hull's surface as a uniform area density (Gottschalk's
// continuous formula): unlike the points' covariance it ignores how densely
// the mesh samples each region.
Eigen::Matrix3d surface_covariance(std::span<const Vec3d> p, const ConvexHull3& hull) {
  double area = 0;
  Vec3d centroid = Vec3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& f : hull.faces) {
    const Vec3d &a = p[f[0]], &b = p[f[1]], &c = p[f[2]];
    const double w = (b - a).cross(c - a).norm() / 2;
    const Vec3d m = (a + b + c) / 3;
    area += w;
    centroid += w * m;
    second += w / 12 * (9 * m * m.transpose() + a * a.transpose() + b * b.transpose() + c * c.transpose());
  }
  if (!(area > 0)) return Eigen::Matrix3d::Zero();
  centroid /= area;
  return second / area - centroid * centroid.transpose();
}

// Direction (unit 2D vector) of the minimum-area rectangle around the points
// (their hull by Andrew's chain, then rotating calipers over its edges).
Vec2d min_area_rectangle_direction(std::vector<Vec2d> q) {
  std::sort(q.begin(), q.end(), [](const Vec2d& a, const Vec2d& b) { return a[0] != b[0] ? a[0] < b[0] : a[1] < b[1]; });
  auto cross = [](const Vec2d& o, const Vec2d& a, const Vec2d& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::vector<Vec2d> h;
  for (int pass = 0; pass < 2; ++pass) {
    const std::size_t base = h.size();
    for (std::size_t k = 0; k < q.size(); ++k) {
      const Vec2d& v = pass == 0 ? q[k] : q[q.size() - 1 - k];
      while (h.size() >= base + 2 && cross(h[h.size() - 2], h.back(), v) <= 0) h.pop_back();
      h.push_back(v);
    }
    h.pop_back();
  }
  const std::size_t n = h.size();
  if (n < 3) return n == 2 && h[1] != h[0] ? Vec2d((h[1] - h[0]).normalized()) : Vec2d(1, 0);
  // For the edge from h[i]: the farthest vertex along the edge (j), along its
  // inner normal (k) and against the edge (l) move forward monotonically.
  std::size_t j = 0, k = 0, l = 0;
  double best = std::numeric_limits<double>::infinity();
  Vec2d best_dir(1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2d e = h[(i + 1) % n] - h[i];
    const double len = e.norm();
    if (!(len > 0)) continue;
    const Vec2d d = e / len, nrm(-d[1], d[0]);
    auto along = [&](std::size_t v) { return d.dot(h[v % n]); };
    auto across = [&](std::size_t v) { return nrm.dot(h[v % n] - h[i]); };
    if (i == 0) j = k = l = 0;
    for (std::size_t s = 0; s < n && along(j + 1) >= along(j); ++s) j = (j + 1) % n;
    if (i == 0) k = j;
    for (std::size_t s = 0; s < n && across(k + 1) >= across(k); ++s) k = (k + 1) % n;
    if (i == 0) l = k;
    for (std::size_t s = 0; s < n && along(l + 1) <= along(l); ++s) l = (l + 1) % n;
    const double area = (along(j) - along(l)) * across(k);
    if (area < best) best = area, best_dir = d;
  }
  return best_dir;
}

// Axes flush with a plane of the given normal: the direction of the
// minimum-area rectangle of the points projected on the plane, its
// perpendicular in the plane, and the normal; right-handed.
Eigen::Matrix3d flush_axes(std::span<const Vec3d> points, const std::vector<std::uint32_t>& ids, const Vec3d& normal) {
  const Vec3d n = normal.normalized();
  const Vec3d u = (std::abs(n[0]) < 0.9 ? Vec3d::UnitX() : Vec3d::UnitY()).cross(n).normalized();
  const Vec3d w = n.cross(u);
  std::vector<Vec2d> q;
  q.reserve(ids.size());
  for (std::uint32_t i : ids) q.emplace_back(u.dot(points[i]), w.dot(points[i]));
  const Vec2d d = min_area_rectangle_direction(std::move(q));
  Eigen::Matrix3d axes;
  axes.col(0) = (d[0] * u + d[1] * w).normalized();
  axes.col(2) = n;
  axes.col(1) = axes.col(2).cross(axes.col(0));
  return axes;
}

}  // namespace

Eigen::Matrix3d obb_fit_axes(std::span<const Vec3d> points, ObbFit fit) {
  std::vector<Eigen::Matrix3d> candidates{principal_axes(point_covariance(points))};
  if (fit == ObbFit::pca) return candidates[0];
  const ConvexHull3 hull = convex_hull3(points);
  if (hull.dimension == 3) {
    candidates.push_back(principal_axes(surface_covariance(points, hull)));
    std::vector<std::size_t> order(hull.faces.size());
    std::vector<Vec3d> normals(hull.faces.size());
    std::vector<double> area(hull.faces.size());
    for (std::size_t f = 0; f < hull.faces.size(); ++f) {
      const auto& v = hull.faces[f];
      normals[f] = (points[v[1]] - points[v[0]]).cross(points[v[2]] - points[v[0]]);
      area[f] = normals[f].norm();
    }
    std::iota(order.begin(), order.end(), std::size_t(0));
    const std::size_t m = std::min(kFaceCandidates, order.size());
    std::partial_sort(order.begin(), order.begin() + std::ptrdiff_t(m), order.end(),
                      [&](std::size_t a, std::size_t b) { return area[a] != area[b] ? area[a] > area[b] : a < b; });
    for (std::size_t k = 0; k < m; ++k)
      if (area[order[k]] > 0) candidates.push_back(flush_axes(points, hull.vertices, normals[order[k]]));
  } else if (hull.dimension == 2) {
    // The plane's normal: the sum of the normals of a fan over the corners
    // (sorted by index, not in cyclic order, so each is flipped to agree).
    const Vec3d& o = points[hull.vertices[0]];
    Vec3d normal = Vec3d::Zero();
    for (std::size_t k = 1; k + 1 < hull.vertices.size(); ++k) {
      const Vec3d c = (points[hull.vertices[k]] - o).cross(points[hull.vertices[k + 1]] - o);
      normal += normal.dot(c) < 0 ? Vec3d(-c) : c;
    }
    if (normal.squaredNorm() > 0 && normal.allFinite()) candidates.push_back(flush_axes(points, hull.vertices, normal));
  }
  // Compare on the hull's corners: the extremes along any axis are among them.
  const std::vector<std::uint32_t>& ids = hull.vertices;
  Vec3d lo = points[ids[0]], hi = lo;
  for (std::uint32_t i : ids) lo = lo.cwiseMin(points[i]), hi = hi.cwiseMax(points[i]);
  const double grow = 1e-6 * (hi - lo).norm();
  double best = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d best_axes = candidates[0];
  for (const Eigen::Matrix3d& axes : candidates) {
    if (!axes.allFinite()) continue;
    Vec3d a = Vec3d::Constant(std::numeric_limits<double>::infinity()), b = -a;
    for (std::uint32_t i : ids) {
      const Vec3d s = axes.transpose() * points[i];
      a = a.cwiseMin(s);
      b = b.cwiseMax(s);
    }
    const double size = ((b - a).array() + grow).prod();
    if (size < best) best = size, best_axes = axes;
  }
  return best_axes;
}

}  // namespace geods::bvh::detail
