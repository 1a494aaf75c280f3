// FarthestVoronoi: the hull corners' cells, cut out of the box by their bisectors.
#include "geods/voronoi/farthest_voronoi.hpp"

#include <string>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/predicates.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "generalized_common.hpp"
#include "halfplane_clip.hpp"

namespace geods::voronoi {

FarthestVoronoi::FarthestVoronoi(std::span<const Vec2d> points, const AABB2d& box)
    : points_(points.begin(), points.end()), box_(box) {
  detail::check_sites_and_box(points, box, "FarthestVoronoi");
  const Delaunay2 dt(points);
  const std::size_t n = points.size();
  detail::distinct_sites(dt, representative_);
  const auto& hull = dt.hull();
  if (dt.degenerate()) {
    // Sorted along the line: the extremes are the corners.
    if (hull.size() >= 2) corners_ = {hull[0], hull[hull.size() - 1]};
    else corners_ = {hull[0]};
  } else {
    for (std::size_t k = 0; k < hull.size(); ++k) {
      const Vec2d& a = points_[hull[(k + hull.size() - 1) % hull.size()]];
      const Vec2d& b = points_[hull[k]];
      const Vec2d& c = points_[hull[(k + 1) % hull.size()]];
      if (orient2d(a, b, c) != 0) corners_.push_back(hull[k]);
    }
  }
  cells_.resize(n);
  std::vector<std::vector<Edge>> pieces(corners_.size());
  parallel_for_each_index(0, corners_.size(), [&](std::size_t c) {
    const std::uint32_t site = corners_[c];
    const Vec2d& p = points_[site];
    detail::LabeledPolygon poly = detail::box_polygon(box_);
    for (std::uint32_t j : corners_) {
      if (j == site) continue;
      // Farther from p than from q: |y|^2 >= |y - d|^2 for y = x - p, d = q - p:  -2 d.y <= -|d|^2.
      const Vec2d d = points_[j] - p;
      detail::clip_halfplane(poly, p, -2 * d, -d.squaredNorm(), j);
      if (poly.points.empty()) break;
    }
    detail::append_bisector_edges(poly, site, pieces[c]);
    cells_[site] = std::move(poly.points);
  }, 8);
  for (std::uint32_t i = 0; i < n; ++i)
    if (representative_[i] != i) cells_[i] = cells_[representative_[i]];
  for (const auto& p : pieces) edges_.insert(edges_.end(), p.begin(), p.end());
}

FarthestVoronoiStats FarthestVoronoi::stats() const {
  FarthestVoronoiStats s;
  s.sites = points_.size();
  for (std::uint32_t i = 0; i < points_.size(); ++i) s.distinct += representative_[i] == i;
  s.corners = corners_.size();
  s.edges = edges_.size();
  for (const auto& c : cells_) s.cell_vertices += c.size();
  return s;
}

void FarthestVoronoi::validate() const {
  for (std::size_t i = 0; i < cells_.size(); ++i)
    detail::check_cell(cells_[i], box_, "FarthestVoronoi::validate: cell " + std::to_string(i));
  const double side = std::max(box_.hi[0] - box_.lo[0], box_.hi[1] - box_.lo[1]);
  for (const Edge& e : edges_)
    for (const Vec2d& x : {e.p0, e.p1}) {
      const double da = (x - points_[e.a]).norm(), db = (x - points_[e.b]).norm();
      // (|x|: far from the origin a corner is only as exact as its coordinates' own rounding.)
      if (std::abs(da - db) > 1e-9 * (da + db + side + x.cwiseAbs().maxCoeff()))
        throw Error("FarthestVoronoi::validate: an edge end is not equidistant from its sites");
    }
}

}  // namespace geods::voronoi
