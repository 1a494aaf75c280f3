#pragma once
// Projection of distance functions (seed §6.1.2, Hoff et al. 1999): the
// distance field of a set of sites and the discrete Voronoi diagram as the
// z-buffer of their distance functions. Each site's distance function,
// seen as a surface above the image plane, is "rendered" into a depth
// buffer with the depth test "less": a cone for a point, a tent (wedge) for a
// segment, a slab at height 0 over a filled polygon with tents and cones
// around it; on the slices of a 3D grid the cone of a point off the slice
// becomes a hyperboloid (sqrt(r^2 + dz^2)), and likewise for the others. The
// depth buffer then holds the distance to the nearest site and the id buffer
// (the frame buffer of the hardware method) which site it is.
//
// Here the rasterizer is the CPU's: parallel over rows, one depth and one id
// per pixel. The graphics-hardware method tessellates the distance functions
// (a cone as a fan of n triangles) and interpolates depth linearly over each
// triangle, which overestimates the distance by up to a factor 1/cos(pi/n)
// (cone_tessellation_error). This rasterizer evaluates each site's distance
// function exactly at the pixel centres instead (the "fragment shader" way),
// so the depth buffer equals the exact distance field at every pixel centre
// up to rounding: the reported error against the exact field is 0 there.
// Between pixel centres the field is a sampled one like any grid; an id
// names the site nearest to the pixel centre, not to the whole pixel.
//
// Fragments are culled exactly as a hierarchical z-buffer would: per row, the
// sites are taken in increasing order of their distance to the row's line (a
// lower bound of their depth along it); a site whose bound exceeds the
// farthest depth of the row is skipped with all that follow, and a site only
// covers the pixels where its depth can still be below the row's farthest
// depth (a bounded cone). The result does not depend on the order: ties go to
// the smaller site id.
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "geods/core/grid3.hpp"
#include "geods/core/vec.hpp"
#include "geods/field/mesh_distance.hpp"  // kNoIndex

namespace geods::field {

/// The sites. Ids: the points first (0 .. points.size() - 1), then the
/// segments, then the polygons. 2D sites have z = 0 (and a 2D image is a
/// grid of one slice at z = 0).
struct ProjectionSites {
  std::vector<Vec3d> points;
  std::vector<std::array<Vec3d, 2>> segments;
  /// Filled simple polygons (at least 3 vertices) in the plane z = 0: the
  /// distance is 0 inside (even-odd rule) and the distance to the boundary
  /// outside; in 3D, sqrt(d_plane^2 + z^2).
  std::vector<std::vector<Vec2d>> polygons;

  std::size_t size() const { return points.size() + segments.size() + polygons.size(); }
};

struct ProjectionOptions {
  /// Bounded distance functions (the cones' radius): pixels farther than
  /// this from every site keep +infinity and no id. Infinity: unbounded.
  double max_distance = std::numeric_limits<double>::infinity();
};

struct ProjectionStats {
  std::size_t sites = 0;
  std::size_t pixels = 0;
  std::uint64_t fragments = 0;        // distance function evaluations (pixels covered by a site)
  double fragments_per_pixel = 0;     // fragments / pixels: the overdraw
  std::uint64_t culled_sites = 0;     // (row, site) pairs skipped by the row's depth bound
};

struct Projection {
  /// The depth buffer: per pixel (sample) the distance to the nearest site,
  /// C order [z][y][x] on the grid given.
  Grid3<double> distance;
  /// The id buffer: the nearest site (kNoIndex where none is within max_distance).
  std::vector<std::uint32_t> ids;
  ProjectionStats stats;
};

/// The distance function of site `id` at p: the exact Euclidean distance of
/// p to the point, segment or filled polygon.
double site_distance(const ProjectionSites& sites, std::uint32_t id, const Vec3d& p);

/// Projects the sites' distance functions onto the samples of `grid` (an
/// image: dims[2] = 1). Parallel over rows, deterministic. Throws
/// geods::Error for no sites, a non-finite coordinate, a polygon of fewer
/// than 3 vertices, a grid without samples, a spacing that is not finite and
/// positive, a NaN or negative max_distance, or a grid larger than memory.
/// Time O(pixels x the sites near each row), memory 12 bytes a pixel.
Projection project_distance(const ProjectionSites& sites, const Grid3Geometry& grid,
                            const ProjectionOptions& options = {});

/// The largest overestimate of a point's distance by a cone tessellated as a
/// fan of `sides` triangles inscribed in the true cone, for distances up to
/// `max_distance` (the graphics-hardware method): max_distance (1 / cos(pi /
/// sides) - 1). The CPU rasterizer above has none.
double cone_tessellation_error(double max_distance, int sides);

}  // namespace geods::field
