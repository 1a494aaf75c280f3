#include "geods/field/projection.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>

#include "geods/core/aabb.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/segment.hpp"
#include "geods/field/mesh_distance.hpp"
#include "geods/voronoi/polygon_clip.hpp"

namespace geods::field {
namespace {

constexpr std::size_t kBlock = 16;  // pixels per block of a row's depth bounds

void check_finite(const Vec3d& p, const char* what, std::size_t i) {
  if (!p.allFinite()) throw Error(fmt::format("project_distance: {} {} has a coordinate that is not finite", what, i));
}

// Each site's bounding box, checked.
std::vector<AABB3d> site_boxes(const ProjectionSites& sites) {
  std::vector<AABB3d> boxes;
  boxes.reserve(sites.size());
  for (std::size_t i = 0; i < sites.points.size(); ++i) {
    check_finite(sites.points[i], "point", i);
    boxes.push_back({sites.points[i], sites.points[i]});
  }
  for (std::size_t i = 0; i < sites.segments.size(); ++i) {
    const auto& [a, b] = sites.segments[i];
    check_finite(a, "segment", i), check_finite(b, "segment", i);
    boxes.push_back({a.cwiseMin(b), a.cwiseMax(b)});
  }
  for (std::size_t i = 0; i < sites.polygons.size(); ++i) {
    const std::vector<Vec2d>& poly = sites.polygons[i];
    if (poly.size() < 3)
      throw Error(fmt::format("project_distance: polygon {} has {} vertices, at least 3 needed", i, poly.size()));
    AABB3d box;
    for (const Vec2d& v : poly) {
      check_finite(Vec3d(v.x(), v.y(), 0), "polygon", i);
      box.extend(Vec3d(v.x(), v.y(), 0));
    }
    boxes.push_back(box);
  }
  return boxes;
}

}  // namespace

double site_distance(const ProjectionSites& sites, std::uint32_t id, const Vec3d& p) {
  std::size_t i = id;
  if (i < sites.points.size()) return (p - sites.points[i]).norm();  // a cone (a hyperboloid off its slice)
  i -= sites.points.size();
  if (i < sites.segments.size()) {  // a tent: the cones of the ends joined by a wedge
    const auto& [a, b] = sites.segments[i];
    return (closest_point_on_segment(p, a, b) - p).norm();
  }
  i -= sites.segments.size();
  if (i >= sites.polygons.size()) throw Error(fmt::format("site_distance: no site {}", id));
  // A slab at 0 over the polygon, tents along its edges, cones at its corners.
  const std::vector<Vec2d>& poly = sites.polygons[i];
  const Vec2d q(p.x(), p.y());
  double d2 = 0;
  if (!voronoi::point_in_polygon(q, poly)) {
    d2 = std::numeric_limits<double>::infinity();
    for (std::size_t e = 0; e < poly.size(); ++e)
      d2 = std::min(d2, (closest_point_on_segment(q, poly[e], poly[(e + 1) % poly.size()]) - q).squaredNorm());
  }
  return std::sqrt(d2 + p.z() * p.z());
}

double cone_tessellation_error(double max_distance, int sides) {
  if (sides < 3) throw Error(fmt::format("cone_tessellation_error: a fan needs at least 3 sides, got {}", sides));
  return max_distance * (1 / std::cos(std::numbers::pi / sides) - 1);
}

Projection project_distance(const ProjectionSites& sites, const Grid3Geometry& grid, const ProjectionOptions& options) {
  if (sites.size() == 0) throw Error("project_distance: no sites");
  if (sites.size() >= kNoIndex) throw Error("project_distance: too many sites");
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(grid.spacing[a]) || !(grid.spacing[a] > 0))
      throw Error(fmt::format("project_distance: spacing must be finite and > 0, got {} along {}", grid.spacing[a],
                              char('x' + a)));
    if (!std::isfinite(grid.origin[a])) throw Error("project_distance: the origin is not finite");
    if (grid.dims[a] == 0) throw Error("project_distance: the grid has no samples");
  }
  if (std::isnan(options.max_distance) || options.max_distance < 0)
    throw Error(fmt::format("project_distance: max_distance must be >= 0, got {}", options.max_distance));
  const std::vector<AABB3d> boxes = site_boxes(sites);
  const std::size_t n = Grid3<double>::checked_size(grid.dims[0], grid.dims[1], grid.dims[2]);
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (memory > 0 && double(n) * 12 > memory)
    throw Error(fmt::format("project_distance: {} x {} x {} samples need {:.1f} GB, more than this machine's {:.1f} GB",
                            grid.dims[0], grid.dims[1], grid.dims[2], double(n) * 12 / 1e9, memory / 1e9));

  Projection result;
  static_cast<Grid3Geometry&>(result.distance) = grid;
  result.distance.data.assign(n, options.max_distance);
  result.ids.assign(n, kNoIndex);
  const std::size_t nx = grid.dims[0], rows = grid.dims[1] * grid.dims[2];
  const double ox = grid.origin.x(), sx = grid.spacing.x();
  std::atomic<std::uint64_t> fragments{0}, culled{0};

  parallel_for(0, rows, 4, [&](std::size_t first, std::size_t last) {
    std::vector<std::pair<double, std::uint32_t>> order(boxes.size());
    std::vector<double> block_max((nx + kBlock - 1) / kBlock);
    std::uint64_t frags = 0, skipped = 0;
    for (std::size_t row = first; row < last; ++row) {
      const std::size_t j = row % grid.dims[1], k = row / grid.dims[1];
      const double y = double(grid.origin.y()) + double(j) * grid.spacing.y();
      const double z = double(grid.origin.z()) + double(k) * grid.spacing.z();
      // Each site's distance to the row's line: a lower bound of its depth on the row.
      for (std::uint32_t s = 0; s < boxes.size(); ++s) {
        const double dy = std::max({boxes[s].lo.y() - y, 0.0, y - boxes[s].hi.y()});
        const double dz = std::max({boxes[s].lo.z() - z, 0.0, z - boxes[s].hi.z()});
        order[s] = {std::sqrt(dy * dy + dz * dz), s};
      }
      std::sort(order.begin(), order.end());
      double* depth = result.distance.data.data() + row * nx;
      std::uint32_t* id = result.ids.data() + row * nx;
      std::fill(block_max.begin(), block_max.end(), options.max_distance);
      double farthest = options.max_distance;
      for (std::size_t o = 0; o < order.size(); ++o) {
        const auto [bound, s] = order[o];
        if (bound > farthest) {
          skipped += order.size() - o;
          break;
        }
        // The pixels where the site's depth can be below `farthest`: its box widened by the bounded cone.
        const double reach = std::isinf(farthest) ? farthest : std::sqrt(farthest * farthest - bound * bound);
        const double lo = (boxes[s].lo.x() - reach - ox) / sx, hi = (boxes[s].hi.x() + reach - ox) / sx;
        const std::size_t i0 = lo <= 0 ? 0 : std::size_t(std::min(std::floor(lo), double(nx)));
        const std::size_t i1 = hi < 0 ? 0 : std::size_t(std::min(std::floor(hi) + 2, double(nx)));
        bool changed = false;
        // Blocks of pixels whose farthest depth the site cannot beat are skipped whole.
        for (std::size_t b = i0 / kBlock; b * kBlock < i1; ++b) {
          const std::size_t b0 = std::max(b * kBlock, i0), b1 = std::min((b + 1) * kBlock, i1);
          const double x0 = ox + double(b0) * sx, x1 = ox + double(b1 - 1) * sx;
          const double gap = std::max({boxes[s].lo.x() - x1, 0.0, x0 - boxes[s].hi.x()});
          if (gap * gap + bound * bound > block_max[b] * block_max[b]) continue;
          bool block_changed = false;
          for (std::size_t i = b0; i < b1; ++i) {
            const double d = site_distance(sites, s, Vec3d(ox + double(i) * sx, y, z));
            if (d < depth[i] || (d == depth[i] && s < id[i])) depth[i] = d, id[i] = s, block_changed = true;
          }
          frags += b1 - b0;
          if (block_changed) {
            const std::size_t c0 = b * kBlock, c1 = std::min(c0 + kBlock, nx);
            block_max[b] = *std::max_element(depth + c0, depth + c1);
            changed = true;
          }
        }
        if (changed) farthest = *std::max_element(block_max.begin(), block_max.end());
      }
      if (std::isfinite(options.max_distance))  // the cleared depth beyond every bounded cone
        for (std::size_t i = 0; i < nx; ++i)
          if (id[i] == kNoIndex) depth[i] = std::numeric_limits<double>::infinity();
    }
    fragments += frags;
    culled += skipped;
  });
  result.stats.sites = sites.size();
  result.stats.pixels = n;
  result.stats.fragments = fragments;
  result.stats.fragments_per_pixel = double(fragments) / double(n);
  result.stats.culled_sites = culled;
  return result;
}

}  // namespace geods::field
