// Height fields in: PNG (8 and 16 bits), BMP, .npy, Terragen .ter, GeoTIFF through
// GDAL (geotransform, no-data); bad and truncated files raise geods::Error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/data_files.hpp"
#include "geods/core/error.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/terrain/height_field.hpp"

namespace geods::terrain {
namespace {

std::filesystem::path temp(const std::string& name) { return std::filesystem::temp_directory_path() / ("geods_hf_" + name); }

TEST(HeightField, ImagesAndArrays) {
  Image<std::uint8_t> g8(5, 3, 1);
  Image<std::uint16_t> g16(5, 3, 1);
  for (std::size_t i = 0; i < 15; ++i) g8.data[i] = std::uint8_t(i * 7), g16.data[i] = std::uint16_t(i * 4000);
  io::write_png(temp("8.png"), g8);
  io::write_png(temp("16.png"), g16);
  const HeightField a = read_height_field(temp("8.png")), b = read_height_field(temp("16.png"));
  EXPECT_EQ(a.width, 5u);
  EXPECT_EQ(a.height, 3u);
  EXPECT_EQ(a(2, 1), 7.0f * 7);
  EXPECT_EQ(b(2, 1), 4000.0f * 7);  // 16 bits kept
  const std::vector<float> f32{1, 2, 3, 4, NAN, 6};
  io::write_npy(temp("f.npy"), std::span<const float>(f32), {2, 3});
  const HeightField c = read_height_field(temp("f.npy"));
  EXPECT_EQ(c.width, 3u);
  EXPECT_EQ(c(2, 1), 6.0f);
  EXPECT_EQ(c.missing(), 1u);
  const std::vector<std::int16_t> i16{-5, 2, 3, 4};
  io::write_npy(temp("i.npy"), std::span<const std::int16_t>(i16), {2, 2});
  EXPECT_EQ(read_height_field(temp("i.npy"))(0, 0), -5.0f);
  // Real data: the Jacksboro DEM, and a 24-bit BMP (grey in all channels; the first
  // one is read) written from its top-left 128 x 96 samples as (z - 236) / 4
  // (integer division): sample for sample the same field, rows in the same order.
  const HeightField dem = read_height_field(test::data_path("jacksboro_dem.npy"));
  EXPECT_EQ(dem.width, 403u);
  EXPECT_EQ(dem.height, 344u);
  const HeightField bmp = read_height_field(test::data_path("jacksboro_dem_crop.bmp"));
  ASSERT_EQ(bmp.width, 128u);
  ASSERT_EQ(bmp.height, 96u);
  for (std::size_t y = 0; y < bmp.height; ++y)
    for (std::size_t x = 0; x < bmp.width; ++x)
      ASSERT_EQ(bmp(x, y), float((int(dem(x, y)) - 236) / 4)) << x << "," << y;
}

TEST(HeightField, GeoTiffThroughGdal) {
  const HeightField f = read_height_field(test::data_path("terra_lux_elev.tif"));
  EXPECT_EQ(f.width, 95u);
  EXPECT_EQ(f.height, 90u);
  // Geotransform: 0.00833 degrees per sample, rows going south.
  EXPECT_NEAR(f.spacing[0], 0.008333, 1e-5);
  EXPECT_NEAR(f.spacing[1], -0.008333, 1e-5);
  EXPECT_NEAR(f.origin[0], 5.741667 + 0.5 * 0.008333, 1e-4);
  // Outside Luxembourg the raster holds its no-data value: missing samples.
  EXPECT_GT(f.missing(), 1000u);
  EXPECT_LT(f.missing(), f.heights.size() / 2);
  for (const float z : f.heights) {
    if (!std::isnan(z)) {
      EXPECT_TRUE(z > 100 && z < 700) << z;
    }
  }
}

void write_ter(const std::filesystem::path& p, int w, int h, bool truncate) {
  std::ofstream o(p, std::ios::binary);
  auto put = [&](const void* d, std::size_t n) { o.write(static_cast<const char*>(d), std::streamsize(n)); };
  auto i16 = [&](std::int16_t v) { put(&v, 2); };
  o << "TERRAGENTERRAIN ";
  o << "SIZE";
  i16(std::int16_t(std::min(w, h) - 1)), i16(0);
  o << "XPTS";
  i16(std::int16_t(w)), i16(0);
  o << "YPTS";
  i16(std::int16_t(h)), i16(0);
  o << "SCAL";
  const float scal[3] = {10, 20, 2};
  put(scal, 12);
  o << "ALTW";
  i16(16384), i16(100);  // height scale, base height
  for (int k = 0; k < w * h - (truncate ? 3 : 0); ++k) i16(std::int16_t(k * 100));
  if (!truncate) o << "EOF ";
}

TEST(HeightField, Terragen) {
  write_ter(temp("a.ter"), 4, 3, false);
  const HeightField f = read_height_field(temp("a.ter"));
  EXPECT_EQ(f.width, 4u);
  EXPECT_EQ(f.height, 3u);
  EXPECT_EQ(f.spacing[0], 10);
  EXPECT_EQ(f.spacing[1], 20);
  // (base + v * scale / 65536) * SCAL z = (100 + 500 * 0.25) * 2 for sample 5.
  EXPECT_FLOAT_EQ(f(1, 1), float((100 + 500 * 0.25) * 2));
  write_ter(temp("b.ter"), 4, 3, true);
  EXPECT_THROW(read_height_field(temp("b.ter")), Error);
}

TEST(HeightField, BadFiles) {
  const std::vector<float> row{1, 2, 3, 4};
  io::write_npy(temp("row.npy"), std::span<const float>(row), {1, 4});
  EXPECT_THROW(read_height_field(temp("row.npy")), Error);
  io::write_npy(temp("1d.npy"), std::span<const float>(row), {4});
  EXPECT_THROW(read_height_field(temp("1d.npy")), Error);
  const std::vector<float> nan4(4, NAN);
  io::write_npy(temp("nan.npy"), std::span<const float>(nan4), {2, 2});
  EXPECT_THROW(read_height_field(temp("nan.npy")), Error);
  const std::vector<double> inf4{1, 2, INFINITY, 4};
  io::write_npy(temp("inf.npy"), std::span<const double>(inf4), {2, 2});
  EXPECT_THROW(read_height_field(temp("inf.npy")), Error);
  EXPECT_THROW(read_height_field(temp("missing.tif")), Error);
  {
    std::ofstream o(temp("junk.tif"));
    o << "not a raster";
  }
  EXPECT_THROW(read_height_field(temp("junk.tif")), Error);
  // A truncated GeoTIFF.
  const auto src = test::data_path("terra_lux_elev.tif");
  std::filesystem::copy_file(src, temp("cut.tif"), std::filesystem::copy_options::overwrite_existing);
  std::filesystem::permissions(temp("cut.tif"), std::filesystem::perms::owner_write, std::filesystem::perm_options::add);
  std::filesystem::resize_file(temp("cut.tif"), 3000);
  EXPECT_THROW(read_height_field(temp("cut.tif")), Error);
  EXPECT_THROW(make_height_field(row, 2, 3), Error);
}

}  // namespace
}  // namespace geods::terrain
