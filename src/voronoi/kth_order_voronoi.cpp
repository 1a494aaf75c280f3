// KthOrderVoronoi: order-j regions split by the nearest of their Delaunay
// candidates, pieces with equal sets merged by the convex hull of their
// corners, a corner found by two pieces joined by its name.
#include "geods/voronoi/kth_order_voronoi.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <string>
#include <utility>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "generalized_common.hpp"
#include "halfplane_clip.hpp"

namespace geods::voronoi {

namespace {

// A line that regions' edges lie on: the bisector of sites a < b (a << 32 |
// b, below 2^62), a side of the box (kBoxLine + side), or a line of its own
// (kOwnLine + a count) for an edge whose end corners share no one line.
using LineId = std::uint64_t;
constexpr LineId kOwnLine = LineId(1) << 63, kBoxLine = LineId(3) << 62;

LineId bisector_line(std::uint32_t a, std::uint32_t b) { return a < b ? LineId(a) << 32 | b : LineId(b) << 32 | a; }

// A convex polygon, counter-clockwise, with the line of each edge (lines[k]:
// from points[k] to points[k + 1]).
struct LinedPolygon {
  std::vector<Vec2d> points;
  std::vector<LineId> lines;
};

// A corner's name: the two lines it joins, or, where both are bisectors of
// three sites, those sites (all three bisectors meet there). Pieces of one
// region compute a corner they share each in its own rounding, and the name,
// not the coordinates, says it is the same corner.
struct CornerKey {
  LineId a, b, c;  // lines a < b and c = kTwoLines, or sites a < b < c
  auto operator<=>(const CornerKey&) const = default;
};
constexpr LineId kTwoLines = ~LineId(0);

CornerKey corner_key(LineId l, LineId m) {
  if (l > m) std::swap(l, m);
  if (m < kOwnLine) {  // two bisectors (not a box side's or own line)
    std::array<LineId, 4> s{l >> 32, l & 0xFFFFFFFF, m >> 32, m & 0xFFFFFFFF};
    std::sort(s.begin(), s.end());
    if (std::unique(s.begin(), s.end()) - s.begin() == 3) return {s[0], s[1], s[2]};
  }
  return {l, m, kTwoLines};
}

// The lines through a named corner (2 or 3; the unused entry kTwoLines).
std::array<LineId, 3> lines_through(const CornerKey& key) {
  if (key.c == kTwoLines) return {key.a, key.b, kTwoLines};
  const auto bisector = [](LineId a, LineId b) { return bisector_line(std::uint32_t(a), std::uint32_t(b)); };
  return {bisector(key.a, key.b), bisector(key.a, key.c), bisector(key.b, key.c)};
}

// poly cut by the bisectors of site p with `others`, the side nearer to p kept.
LinedPolygon cut(std::span<const Vec2d> sites, const LinedPolygon& poly, std::uint32_t p,
                 std::span<const std::uint32_t> others) {
  const std::uint32_t m = std::uint32_t(poly.lines.size());
  detail::LabeledPolygon clipped{poly.points, std::vector<std::uint32_t>(m)};
  std::iota(clipped.labels.begin(), clipped.labels.end(), 0u);  // poly's edges, then m + i: others[i]'s bisector
  for (std::uint32_t i = 0; i < others.size() && !clipped.points.empty(); ++i) {
    if (others[i] == p) continue;
    const Vec2d d = sites[others[i]] - sites[p];  // nearer to p: 2 d.y <= |d|^2 for y = x - p
    detail::clip_halfplane(clipped, sites[p], 2 * d, d.squaredNorm(), m + i);
  }
  LinedPolygon out{std::move(clipped.points), {}};
  for (std::uint32_t l : clipped.labels) out.lines.push_back(l < m ? poly.lines[l] : bisector_line(p, others[l - m]));
  return out;
}

// Whether a cut left nothing, or a sliver of its rounding.
bool negligible(const LinedPolygon& polygon) {
  return polygon.points.empty() || detail::negligible_area(polygon.points);
}

// The convex region whose corners these are (named; each corner once, by
// name): their hull, and each edge's line the one its end corners share.
// `own_lines` counts the lines of their own given out. (Their numbers vary
// from run to run with the threads; the regions do not.)
LinedPolygon region_of(std::vector<std::pair<CornerKey, Vec2d>>& corners, std::atomic<LineId>& own_lines) {
  std::sort(corners.begin(), corners.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  corners.erase(std::unique(corners.begin(), corners.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                corners.end());
  std::vector<Vec2d> points;
  for (const auto& c : corners) points.push_back(c.second);
  const std::vector<std::uint32_t> hull = detail::convex_hull_of(points);
  LinedPolygon region;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const CornerKey& a = corners[hull[k]].first;
    const CornerKey& b = corners[hull[(k + 1) % hull.size()]].first;
    // Corners on lines through one point (co-circular sites) have other names:
    // within a few units of rounding they count once.
    const Vec2d &x = points[hull[k]], &next = points[hull[(k + 1) % hull.size()]];
    const Vec2d tol = 8 * std::numeric_limits<double>::epsilon() * x.cwiseAbs().cwiseMax(next.cwiseAbs());
    if (k + 1 < hull.size() && ((x - next).cwiseAbs().array() <= tol.array()).all()) continue;
    // The edge's line: the one line through both its corners, else one of its own.
    LineId line = kTwoLines;
    int common = 0;
    for (LineId l : lines_through(a))
      for (LineId m : lines_through(b))
        if (l == m && l != kTwoLines) line = l, ++common;
    region.points.push_back(x);
    region.lines.push_back(common == 1 ? line : kOwnLine + own_lines++);
  }
  if (region.points.size() < 3) return {};
  return region;
}

}  // namespace

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

  struct Working {
    std::vector<std::uint32_t> sites;
    LinedPolygon polygon;
  };
  // Order 1: the Voronoi cells, the box cut by the bisectors of each site's Delaunay neighbours.
  const detail::LabeledPolygon box_corners = detail::box_polygon(box);
  const LinedPolygon whole{box_corners.points, {kBoxLine, kBoxLine + 1, kBoxLine + 2, kBoxLine + 3}};
  std::vector<Working> regions(sites.size());
  parallel_for_each_index(0, sites.size(), [&](std::size_t i) {
    regions[i] = {{sites[i]}, cut(points_, whole, sites[i], neighbors[sites[i]])};
  }, 16);
  std::erase_if(regions, [](const Working& r) { return negligible(r.polygon); });
  std::atomic<LineId> own_lines = 0;
  for (std::size_t order = 1; order < k; ++order) {
    // Each region's pieces, in parallel.
    std::vector<std::vector<Working>> pieces(regions.size());
    parallel_for_each_index(0, regions.size(), [&](std::size_t r) {
      const Working& region = regions[r];
      std::vector<std::uint32_t> candidates;
      for (std::uint32_t t : region.sites)
        for (std::uint32_t s : neighbors[t])
          if (!std::binary_search(region.sites.begin(), region.sites.end(), s)) candidates.push_back(s);
      std::sort(candidates.begin(), candidates.end());
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      for (std::uint32_t s : candidates) {
        LinedPolygon piece = cut(points_, region.polygon, s, candidates);
        if (negligible(piece)) continue;
        std::vector<std::uint32_t> set = region.sites;
        set.insert(std::upper_bound(set.begin(), set.end(), s), s);
        pieces[r].push_back({std::move(set), std::move(piece)});
      }
    }, 16);
    std::map<std::vector<std::uint32_t>, std::vector<std::pair<CornerKey, Vec2d>>> merged;
    for (auto& list : pieces)
      for (const Working& piece : list) {
        ++pieces_;
        auto& corners = merged[piece.sites];
        const std::size_t n = piece.polygon.points.size();
        for (std::size_t c = 0; c < n; ++c)
          corners.push_back({corner_key(piece.polygon.lines[(c + n - 1) % n], piece.polygon.lines[c]),
                             piece.polygon.points[c]});
      }
    regions.assign(merged.size(), {});
    std::vector<decltype(merged)::value_type*> sets;
    for (auto& entry : merged) sets.push_back(&entry);
    parallel_for_each_index(0, sets.size(), [&](std::size_t i) {
      regions[i] = {sets[i]->first, region_of(sets[i]->second, own_lines)};
    }, 64);
    std::erase_if(regions, [](const Working& r) { return negligible(r.polygon); });
  }
  // Already sorted by their sets: order 1 by site, the later orders in the map's order.
  regions_.clear();
  for (Working& r : regions) regions_.push_back({std::move(r.sites), std::move(r.polygon.points)});
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
