// KthOrderVoronoi: order-j regions split by the nearest of their Delaunay
// candidates, pieces with equal sets merged by their convex hull.
#include "geods/voronoi/kth_order_voronoi.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "generalized_common.hpp"
#include "halfplane_clip.hpp"

namespace geods::voronoi {

KthOrderVoronoi::KthOrderVoronoi(std::span<const Vec2d> points, std::size_t k, const AABB2d& box)
    : points_(points.begin(), points.end()), k_(k), box_(box) {
  detail::check_sites_and_box(points, box, "KthOrderVoronoi");
  const Delaunay2 dt(points);
  const std::vector<std::uint32_t> sites = detail::distinct_sites(dt, representative_);
  distinct_ = sites.size();
  if (k == 0 || k > distinct_)
    throw Error("KthOrderVoronoi: k = " + std::to_string(k) + " must be between 1 and the " +
                std::to_string(distinct_) + " distinct points");
  std::vector<std::vector<std::uint32_t>> neighbors(points.size());
  for (std::uint32_t s : sites) neighbors[s] = dt.neighbors(s);

  // Order 1: the Voronoi cells.
  const Voronoi2 vd(dt);
  regions_.clear();
  for (std::uint32_t s : sites) {
    std::vector<Vec2d> cell = vd.cell_polygon(s, box);
    if (!cell.empty() && !detail::negligible_area(cell)) regions_.push_back({{s}, std::move(cell)});
  }
  for (std::size_t order = 1; order < k; ++order) {
    // Each region's pieces, in parallel: (set, corners).
    std::vector<std::vector<std::pair<std::vector<std::uint32_t>, std::vector<Vec2d>>>> pieces(regions_.size());
    parallel_for_each_index(0, regions_.size(), [&](std::size_t r) {
      const Region& region = regions_[r];
      std::vector<std::uint32_t> candidates;
      for (std::uint32_t t : region.sites)
        for (std::uint32_t s : neighbors[t])
          if (!std::binary_search(region.sites.begin(), region.sites.end(), s)) candidates.push_back(s);
      std::sort(candidates.begin(), candidates.end());
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      for (std::uint32_t s : candidates) {
        detail::LabeledPolygon poly{region.polygon, std::vector<std::uint32_t>(region.polygon.size(), detail::kBoxSide)};
        const Vec2d& p = points_[s];
        for (std::uint32_t o : candidates) {
          if (o == s) continue;
          const Vec2d d = points_[o] - p;  // nearer to p: 2 d.y <= |d|^2
          detail::clip_halfplane(poly, p, 2 * d, d.squaredNorm(), o);
          if (poly.points.empty()) break;
        }
        if (poly.points.empty() || detail::negligible_area(poly.points)) continue;
        std::vector<std::uint32_t> set = region.sites;
        set.insert(std::upper_bound(set.begin(), set.end(), s), s);
        pieces[r].push_back({std::move(set), std::move(poly.points)});
      }
    }, 16);
    std::map<std::vector<std::uint32_t>, std::vector<Vec2d>> merged;
    for (auto& list : pieces)
      for (auto& [set, corners] : list) {
        ++pieces_;
        auto& all = merged[set];
        all.insert(all.end(), corners.begin(), corners.end());
      }
    regions_.clear();
    for (auto& [set, corners] : merged) {
      std::vector<Vec2d> polygon = detail::convex_polygon_of(std::move(corners));
      if (!polygon.empty() && !detail::negligible_area(polygon)) regions_.push_back({set, std::move(polygon)});
    }
  }
  std::sort(regions_.begin(), regions_.end(), [](const Region& a, const Region& b) { return a.sites < b.sites; });
}

KthOrderVoronoiStats KthOrderVoronoi::stats() const {
  KthOrderVoronoiStats s;
  s.sites = points_.size();
  s.distinct = distinct_;
  s.k = k_;
  s.regions = regions_.size();
  s.pieces = pieces_;
  for (const Region& r : regions_) s.region_vertices += r.polygon.size();
  return s;
}

void KthOrderVoronoi::validate() const {
  for (std::size_t r = 0; r < regions_.size(); ++r) {
    const Region& region = regions_[r];
    const std::string what = "KthOrderVoronoi::validate: region " + std::to_string(r);
    detail::check_cell(region.polygon, box_, what);
    if (region.sites.size() != k_) throw Error(what + " has " + std::to_string(region.sites.size()) + " sites");
    for (std::size_t i = 0; i < region.sites.size(); ++i)
      if (region.sites[i] >= points_.size() || representative_[region.sites[i]] != region.sites[i] ||
          (i > 0 && region.sites[i - 1] >= region.sites[i]))
        throw Error(what + " has a bad site set");
    if (r > 0 && !(regions_[r - 1].sites < region.sites)) throw Error(what + ": sets not sorted and unique");
  }
}

}  // namespace geods::voronoi
