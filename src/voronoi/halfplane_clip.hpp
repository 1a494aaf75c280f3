#pragma once
// Convex cells cut out of a box by half-planes, each polygon edge labelled by
// the half-plane (or box side) it lies on: the cells of the power, farthest-point
// and k-th order diagrams.
#include <cstdint>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/bisector_edge.hpp"

namespace geods::voronoi::detail {

struct LabeledPolygon {
  std::vector<Vec2d> points;          // counter-clockwise
  std::vector<std::uint32_t> labels;  // labels[k]: the edge from points[k] to points[k + 1]
};

inline constexpr std::uint32_t kBoxSide = std::uint32_t(-1);

// The edges of site's clipped cell that lie on a bisector with a larger site
// (so that each edge between two cells is kept once), appended to `out`.
inline void append_bisector_edges(const LabeledPolygon& cell, std::uint32_t site, std::vector<BisectorEdge>& out) {
  for (std::size_t k = 0; k < cell.points.size(); ++k)
    if (cell.labels[k] != kBoxSide && site < cell.labels[k])
      out.push_back({site, cell.labels[k], cell.points[k], cell.points[(k + 1) % cell.points.size()]});
}

inline LabeledPolygon box_polygon(const AABB2d& box) {
  return {{box.lo, {box.hi[0], box.lo[1]}, box.hi, {box.lo[0], box.hi[1]}}, {kBoxSide, kBoxSide, kBoxSide, kBoxSide}};
}

/// Keeps the part of `poly` where normal . (x - origin) <= offset; the new edge gets `label`.
inline void clip_halfplane(LabeledPolygon& poly, const Vec2d& origin, const Vec2d& normal, double offset,
                           std::uint32_t label) {
  const std::size_t n = poly.points.size();
  if (n == 0) return;
  thread_local std::vector<double> side;  // scratch buffers: clipping runs per cell, in parallel
  thread_local LabeledPolygon out;
  side.resize(n);
  bool any_out = false, any_in = false;
  for (std::size_t k = 0; k < n; ++k) {
    side[k] = normal.dot(poly.points[k] - origin) - offset;
    any_out |= side[k] > 0;
    any_in |= side[k] <= 0;
  }
  if (!any_out) return;
  if (!any_in) {
    poly.points.clear();
    poly.labels.clear();
    return;
  }
  out.points.clear();
  out.labels.clear();
  const auto push = [&](const Vec2d& p, std::uint32_t l) {
    if (!out.points.empty() && out.points.back() == p) {
      out.labels.back() = l;
      return;
    }
    out.points.push_back(p);
    out.labels.push_back(l);
  };
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = (k + 1) % n;
    const bool in_a = side[k] <= 0, in_b = side[j] <= 0;
    if (in_a) push(poly.points[k], poly.labels[k]);
    if (in_a != in_b) {
      const double t = side[k] / (side[k] - side[j]);
      const Vec2d x = poly.points[k] + t * (poly.points[j] - poly.points[k]);
      push(x, in_a ? label : poly.labels[k]);
    }
  }
  while (out.points.size() > 1 && out.points.front() == out.points.back()) {
    out.points.pop_back();
    out.labels.pop_back();
  }
  if (out.points.size() < 3) out.points.clear(), out.labels.clear();
  std::swap(poly, out);
}

}  // namespace geods::voronoi::detail
