// ConstrainedVoronoi: convex pieces of the box (triangles of DT(S, L), strips
// and wedges outside the hull) cut by shadow lines, then by bisectors among the
// candidates visible in each cell.
#include "geods/voronoi/constrained_voronoi.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/predicates.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "generalized_common.hpp"
#include "halfplane_clip.hpp"

namespace geods::voronoi {
namespace {

// Whether segment xq crosses segment s0 s1 properly (exact orientations).
bool crosses(const Vec2d& x, const Vec2d& q, const Vec2d& s0, const Vec2d& s1) {
  const double o1 = orient2d(s0, s1, x), o2 = orient2d(s0, s1, q);
  if (!((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0))) return false;
  const double o3 = orient2d(x, q, s0), o4 = orient2d(x, q, s1);
  return (o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0);
}

std::vector<Vec2d> counter_clockwise(std::vector<Vec2d> p) {
  if (polygon_area(p) < 0) std::reverse(p.begin(), p.end());
  return p;
}

Vec2d vertex_mean(const std::vector<Vec2d>& p) {
  Vec2d c(0, 0);
  for (const Vec2d& v : p) c += v;
  return c / double(p.size());
}

}  // namespace

ConstrainedVoronoi::ConstrainedVoronoi(std::span<const Vec2d> points, std::span<const Segment> segments, const AABB2d& box)
    : points_(points.begin(), points.end()), box_(box) {
  detail::check_sites_and_box(points, box, "ConstrainedVoronoi");
  for (std::size_t k = 0; k < segments.size(); ++k)
    if (segments[k][0] >= points.size() || segments[k][1] >= points.size() || segments[k][0] == segments[k][1])
      throw Error("ConstrainedVoronoi: segment " + std::to_string(k) + " is not a pair of distinct point indices");
  const Delaunay2 dt(points, segments);
  if (!dt.intersection_points().empty())
    throw Error("ConstrainedVoronoi: the segments cross (" + std::to_string(dt.intersection_points().size()) +
                " crossings); L must not cross (split them first)");
  const std::vector<std::uint32_t> sites = detail::distinct_sites(dt, representative_);
  constraints_ = dt.constrained_edges();

  // The convex pieces of the box, each with a site every point of it sees.
  struct Region {
    std::vector<Vec2d> polygon;
    std::vector<std::uint32_t> anchors;  // sites every point of the polygon sees
  };
  std::vector<Region> regions;
  const auto add = [&](std::vector<Vec2d> polygon, std::vector<std::uint32_t> anchors) {
    polygon = clip_polygon_to_box(counter_clockwise(std::move(polygon)), box_);
    if (polygon.size() >= 3) regions.push_back({std::move(polygon), std::move(anchors)});
  };
  if (dt.degenerate()) {
    add({box.lo, {box.hi[0], box.lo[1]}, box.hi, {box.lo[0], box.hi[1]}}, {sites.front()});
  } else {
    const auto& t = dt.triangles();
    for (std::size_t k = 0; k < t.size(); k += 3) add({points_[t[k]], points_[t[k + 1]], points_[t[k + 2]]}, {t[k], t[k + 1], t[k + 2]});
    AABB2d all = box;
    for (const Vec2d& p : points_) all.extend(p);
    const double far = 4 * (all.hi - all.lo).norm() + 1;
    const auto& hull = dt.hull();
    const std::size_t h = hull.size();
    const auto normal = [&](std::size_t k) {  // outward unit normal of hull edge k -> k + 1
      const Vec2d d = points_[hull[(k + 1) % h]] - points_[hull[k]];
      return Vec2d(d[1], -d[0]).normalized();
    };
    for (std::size_t k = 0; k < h; ++k) {
      const Vec2d &a = points_[hull[k]], &b = points_[hull[(k + 1) % h]];
      const Vec2d nk = normal(k), nn = normal((k + 1) % h);
      add({a, b, b + far * nk, a + far * nk}, {hull[k], hull[(k + 1) % h]});
      if (orient2d(a, b, points_[hull[(k + 2) % h]]) > 0)  // a corner at b: the wedge between the two normals
        add({b, b + far * nk, b + far * (nk + nn).normalized(), b + far * nn}, {hull[(k + 1) % h]});
    }
  }

  // Sites and constraint midpoints in k-d trees.
  std::vector<Vec2d> site_points(sites.size());
  for (std::size_t k = 0; k < sites.size(); ++k) site_points[k] = points_[sites[k]];
  const spatial::KdTree<double, 2> site_tree{spatial::PointView<double>(std::span<const Vec2d>(site_points))};
  std::vector<Vec2d> middles(constraints_.size());
  double longest = 0;
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    const Vec2d &a = points_[constraints_[k][0]], &b = points_[constraints_[k][1]];
    middles[k] = (a + b) / 2;
    longest = std::max(longest, (b - a).norm() / 2);
  }
  spatial::KdTree<double, 2> segment_tree;
  if (!middles.empty()) segment_tree = spatial::KdTree<double, 2>{spatial::PointView<double>(std::span<const Vec2d>(middles))};

  std::vector<std::vector<Piece>> found(regions.size());
  std::vector<std::size_t> cell_count(regions.size()), candidate_count(regions.size());
  parallel_for_each_index(0, regions.size(), [&](std::size_t r) {
    const Region& region = regions[r];
    const Vec2d center = vertex_mean(region.polygon);
    double reach = 0, radius = 0;
    for (const Vec2d& v : region.polygon) {
      reach = std::max(reach, (v - points_[region.anchors[0]]).norm());
      radius = std::max(radius, (v - center).norm());
    }
    // Candidates: the anchors, and sites nearer than every anchor somewhere in
    // the piece (within the anchor's reach, and the piece cut by the half-planes
    // nearer to them than to each anchor is not empty).
    std::vector<std::uint32_t> candidates = region.anchors;
    for (const auto& nb : site_tree.query_radius(center, (reach + radius) * (1 + 1e-9))) {
      const std::uint32_t q = sites[nb.index];
      if (std::find(region.anchors.begin(), region.anchors.end(), q) != region.anchors.end()) continue;
      detail::LabeledPolygon part{region.polygon, std::vector<std::uint32_t>(region.polygon.size(), 0)};
      for (std::uint32_t a : region.anchors) {
        const Vec2d d = points_[a] - points_[q];  // nearer to q than to a: 2 d.y <= |d|^2, y = x - q
        detail::clip_halfplane(part, points_[q], 2 * d, d.squaredNorm() * (1 + 1e-9), a);
      }
      if (!part.points.empty()) candidates.push_back(q);
    }
    candidate_count[r] = candidates.size();
    // Per candidate, the constraints that may hide it from part of the piece.
    std::vector<std::uint32_t> near_segments;
    if (!middles.empty())
      for (const auto& nb : segment_tree.query_radius(center, (reach + radius + longest) * (1 + 1e-9)))
        near_segments.push_back(nb.index);
    AABB2d piece_box;
    for (const Vec2d& v : region.polygon) piece_box.extend(v);
    std::vector<std::vector<std::uint32_t>> blockers(candidates.size());
    std::vector<detail::LabeledPolygon> cells{{region.polygon, std::vector<std::uint32_t>(region.polygon.size(), 0)}};
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const Vec2d& q = points_[candidates[c]];
      AABB2d reach_box = piece_box;
      reach_box.extend(q);
      for (std::uint32_t s : near_segments) {
        const auto [i, j] = constraints_[s];
        if (representative_[i] == candidates[c] || representative_[j] == candidates[c]) continue;
        AABB2d sb;
        sb.extend(points_[i]);
        sb.extend(points_[j]);
        if ((sb.lo.array() > reach_box.hi.array()).any() || (sb.hi.array() < reach_box.lo.array()).any()) continue;
        blockers[c].push_back(s);
        // The shadow boundaries: the lines from q through the segment's ends split the cells.
        for (const Vec2d& e : {points_[i], points_[j]}) {
          const Vec2d d = e - q;
          const Vec2d nrm(-d[1], d[0]);
          std::vector<detail::LabeledPolygon> next;
          for (auto& cell : cells) {
            bool below = false, above = false;
            for (const Vec2d& v : cell.points) {
              const double side = nrm.dot(v - q);
              below |= side < 0, above |= side > 0;
            }
            if (!(below && above)) {
              next.push_back(std::move(cell));
              continue;
            }
            detail::LabeledPolygon other = cell;
            detail::clip_halfplane(cell, q, nrm, 0, 0);
            detail::clip_halfplane(other, q, -nrm, 0, 0);
            if (!cell.points.empty()) next.push_back(std::move(cell));
            if (!other.points.empty()) next.push_back(std::move(other));
          }
          cells = std::move(next);
        }
      }
    }
    cell_count[r] = cells.size();
    // In each cell the same candidates are visible: split it by their bisectors.
    for (const auto& cell : cells) {
      if (detail::negligible_area(cell.points)) continue;
      const Vec2d x = vertex_mean(cell.points);
      std::vector<std::uint32_t> seen;
      for (std::size_t c = 0; c < candidates.size(); ++c) {
        bool hidden = false;
        for (std::uint32_t s : blockers[c])
          if ((hidden = crosses(x, points_[candidates[c]], points_[constraints_[s][0]], points_[constraints_[s][1]]))) break;
        if (!hidden) seen.push_back(candidates[c]);
      }
      for (std::uint32_t q : seen) {
        detail::LabeledPolygon piece = cell;
        const Vec2d& p = points_[q];
        for (std::uint32_t o : seen) {
          if (o == q) continue;
          const Vec2d d = points_[o] - p;  // nearer to p: 2 d.y <= |d|^2
          detail::clip_halfplane(piece, p, 2 * d, d.squaredNorm(), o);
          if (piece.points.empty()) break;
        }
        if (!piece.points.empty() && !detail::negligible_area(piece.points)) found[r].push_back({q, std::move(piece.points)});
      }
    }
  }, 4);
  for (std::size_t r = 0; r < regions.size(); ++r) {
    for (auto& piece : found[r]) pieces_.push_back(std::move(piece));
    cells_ += cell_count[r];
    max_candidates_ = std::max(max_candidates_, candidate_count[r]);
  }
}

bool ConstrainedVoronoi::visible(const Vec2d& x, std::uint32_t p) const {
  const Vec2d& q = points_[p];
  for (const Segment& s : constraints_)
    if (crosses(x, q, points_[s[0]], points_[s[1]])) return false;
  return true;
}

ConstrainedVoronoiStats ConstrainedVoronoi::stats() const {
  ConstrainedVoronoiStats s;
  s.sites = points_.size();
  for (std::uint32_t i = 0; i < points_.size(); ++i) s.distinct += representative_[i] == i;
  s.segments = constraints_.size();
  s.pieces = pieces_.size();
  s.cells = cells_;
  s.max_candidates = max_candidates_;
  return s;
}

void ConstrainedVoronoi::validate() const {
  for (std::size_t k = 0; k < pieces_.size(); ++k) {
    const std::string what = "ConstrainedVoronoi::validate: piece " + std::to_string(k);
    detail::check_cell(pieces_[k].polygon, box_, what);
    if (!visible(vertex_mean(pieces_[k].polygon), pieces_[k].site)) throw Error(what + " does not see its site");
  }
}

}  // namespace geods::voronoi
