#pragma once
// Polygons, polylines and points of 2D maps: WKT (.wkt), GeoJSON (.geojson,
// .json), ESRI shapefiles (.shp), GeoPackage (.gpkg) through GDAL/OGR; CGAL's
// segment-site files (.cin: lines "s x0 y0 x1 y1" and "p x y"); SVG figures
// (.svg: <polygon>, <polyline> and <path> with straight commands M L H V Z).
#include <array>
#include <filesystem>
#include <vector>

#include "geods/core/vec.hpp"

namespace geods::io {

struct PolygonSet {
  std::vector<std::vector<Vec2d>> rings;         // closed rings (polygon boundaries and holes), without the closing point
  std::vector<std::array<double, 4>> segments;   // segments of open polylines and .cin segment lines
  std::vector<Vec2d> points;                     // isolated points
  bool empty() const { return rings.empty() && segments.empty() && points.empty(); }
  /// Every ring edge and segment as rows x0 y0 x1 y1.
  std::vector<double> all_segments() const;
};

/// Reads the file; throws geods::Error when it cannot be read, has no
/// geometry, or has a coordinate that is not finite.
PolygonSet read_polygons(const std::filesystem::path& path);

}  // namespace geods::io
