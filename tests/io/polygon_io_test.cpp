// Reading 2D maps: WKT, .cin, SVG paths and an ESRI shapefile (GDAL/OGR); bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"
#include "geods/io/polygon_io.hpp"

namespace geods::io {
namespace {

std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("geods_polygon_io_" + name);
  std::ofstream(path) << text;
  return path;
}

TEST(PolygonIo, Wkt) {
  const auto path = write_file("a.wkt",
                               "POLYGON((0 0, 4 0, 4 4, 0 4, 0 0), (1 1, 2 1, 2 2, 1 1))\n"
                               "MULTIPOLYGON(((10 10, 11 10, 11 11, 10 10)))\nLINESTRING(0 5, 1 6, 2 5)\nPOINT(7 7)\n");
  const PolygonSet s = read_polygons(path);
  ASSERT_EQ(s.rings.size(), 3u);
  EXPECT_EQ(s.rings[0].size(), 4u);  // closing point dropped
  EXPECT_EQ(s.rings[1].size(), 3u);
  EXPECT_EQ(s.segments.size(), 2u);
  ASSERT_EQ(s.points.size(), 1u);
  EXPECT_EQ(s.points[0], Vec2d(7, 7));
  EXPECT_EQ(s.all_segments().size(), 4u * (4 + 3 + 3 + 2));
}

TEST(PolygonIo, CinAndSvg) {
  const PolygonSet c = read_polygons(write_file("a.cin", "s 0 0 1 1\np 2 3\ns 1 1 2 0\n"));
  EXPECT_EQ(c.segments.size(), 2u);
  EXPECT_EQ(c.points.size(), 1u);
  const PolygonSet v = read_polygons(write_file(
      "a.svg", "<svg><path d=\"M 0 0 L 10 0 l 0 10 H 0 Z\"/><polyline points=\"0,20 5,25 10,20\"/></svg>"));
  ASSERT_EQ(v.rings.size(), 1u);
  EXPECT_EQ(v.rings[0].size(), 4u);
  EXPECT_EQ(v.rings[0][2], Vec2d(10, -10));  // SVG's y points down
  EXPECT_EQ(v.segments.size(), 2u);
}

TEST(PolygonIo, Shapefile) {
  const PolygonSet s = read_polygons(test::data_path("nc_counties.shp"));
  EXPECT_GE(s.rings.size(), 100u);  // 100 counties, some of several parts
  for (const auto& r : s.rings)
    for (const Vec2d& p : r) {
      EXPECT_GT(p[0], -85);
      EXPECT_LT(p[0], -75);
    }
}

TEST(PolygonIo, BadInput) {
  EXPECT_THROW(read_polygons(write_file("b.wkt", "POLYGON((0 0, 1 0")), Error);
  EXPECT_THROW(read_polygons(write_file("c.cin", "s 0 0 1\n")), Error);
  EXPECT_THROW(read_polygons(write_file("d.svg", "<svg><path d=\"M 0 0 C 1 1 2 2 3 3\"/></svg>")), Error);
  EXPECT_THROW(read_polygons(write_file("e.wkt", "")), Error);
  EXPECT_THROW(read_polygons("/nonexistent/x.shp"), Error);
  EXPECT_THROW(read_polygons(write_file("f.xyz", "1 2 3")), Error);
}

}  // namespace
}  // namespace geods::io
