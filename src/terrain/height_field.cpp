// Height fields in: images, .npy, Terragen .ter and GDAL rasters; the no-data rule.
#include "geods/terrain/height_field.hpp"

#include <gdal.h>
#include <cpl_error.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <string>

#include "geods/core/error.hpp"
#include "geods/field/edt.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/npy.hpp"

namespace geods::terrain {
namespace {

constexpr float kMissing = std::numeric_limits<float>::quiet_NaN();

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

template <typename T>
HeightField from_image(const Image<T>& im) {
  HeightField f;
  f.width = im.width;
  f.height = im.height;
  f.heights.resize(im.width * im.height);
  for (std::size_t i = 0; i < f.heights.size(); ++i) f.heights[i] = float(im.data[i * im.channels]);
  return f;
}

HeightField read_npy_field(const std::filesystem::path& path) {
  const io::NpyArray a = io::read_npy(path);
  if (a.shape.size() != 2)
    throw Error(path.string() + ": a height field must be a 2-D array (rows = y), got " +
                std::to_string(a.shape.size()) + "-D");
  HeightField f;
  f.height = a.shape[0];
  f.width = a.shape[1];
  const std::vector<double> values = a.to_vector<double>();
  f.heights.resize(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isinf(values[i]) || (std::isfinite(values[i]) && std::abs(values[i]) > 3e38))
      throw Error(path.string() + ": sample " + std::to_string(i) + " is " + format_number(values[i]) +
                  " (heights must be finite floats; NaN marks a missing sample)");
    f.heights[i] = float(values[i]);
  }
  return f;
}

// Terragen .ter: "TERRAGEN" "TERRAIN " then 4-byte chunks (each padded to 4 bytes), ALTW last but EOF.
HeightField read_ter(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string name = path.string();
  if (bytes.size() < 16 || std::memcmp(bytes.data(), "TERRAGENTERRAIN ", 16) != 0)
    throw Error(name + ": not a Terragen terrain (no TERRAGENTERRAIN header)");
  std::size_t pos = 16;
  auto need = [&](std::size_t n, const char* what) {
    if (pos + n > bytes.size()) throw Error(name + ": truncated in " + std::string(what));
  };
  auto i16 = [&]() {
    std::int16_t v;
    std::memcpy(&v, bytes.data() + pos, 2);
    pos += 2;
    return v;
  };
  auto f32 = [&]() {
    float v;
    std::memcpy(&v, bytes.data() + pos, 4);
    pos += 4;
    return v;
  };
  long size = -1, xpts = -1, ypts = -1;
  float scale[3] = {30, 30, 30};
  while (true) {
    need(4, "a chunk marker");
    const std::string marker(bytes.data() + pos, 4);
    pos += 4;
    if (marker == "SIZE" || marker == "XPTS" || marker == "YPTS") {
      need(4, marker.c_str());
      const long v = i16();
      pos += 2;
      (marker == "SIZE" ? size : marker == "XPTS" ? xpts : ypts) = v;
    } else if (marker == "SCAL") {
      need(12, "SCAL");
      for (float& s : scale) s = f32();
    } else if (marker == "CRAD" || marker == "CRVM") {
      need(4, marker.c_str());
      pos += 4;
    } else if (marker == "ALTW") {
      if (size < 0) throw Error(name + ": ALTW before SIZE");
      const long w = xpts > 0 ? xpts : size + 1, h = ypts > 0 ? ypts : (xpts > 0 ? size + 1 : size + 1);
      if (w <= 0 || h <= 0) throw Error(name + ": bad SIZE/XPTS/YPTS");
      need(4, "ALTW");
      const double height_scale = i16(), base = i16();
      need(std::size_t(w) * std::size_t(h) * 2, "the ALTW samples");
      HeightField f;
      f.width = std::size_t(w);
      f.height = std::size_t(h);
      f.heights.resize(f.width * f.height);
      for (float& z : f.heights) z = float((base + i16() * height_scale / 65536.0) * scale[2]);
      f.spacing = {scale[0], scale[1]};
      return f;
    } else if (marker == "EOF ") {
      throw Error(name + ": no ALTW chunk (no heights)");
    } else {
      throw Error(name + ": unknown Terragen chunk '" + marker + "'");
    }
  }
}

HeightField read_gdal(const std::filesystem::path& path) {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
  CPLPushErrorHandler(CPLQuietErrorHandler);
  struct Pop {
    GDALDatasetH ds = nullptr;
    ~Pop() {
      if (ds) GDALClose(ds);
      CPLPopErrorHandler();
    }
  } guard;
  const std::string name = path.string();
  guard.ds = GDALOpen(name.c_str(), GA_ReadOnly);
  if (!guard.ds) {
    const std::string why = CPLGetLastErrorMsg();
    throw Error(name + ": cannot read as a raster" + (why.empty() ? "" : " (" + why + ")"));
  }
  if (GDALGetRasterCount(guard.ds) < 1) throw Error(name + ": the raster has no band");
  HeightField f;
  f.width = std::size_t(GDALGetRasterXSize(guard.ds));
  f.height = std::size_t(GDALGetRasterYSize(guard.ds));
  double gt[6];
  if (GDALGetGeoTransform(guard.ds, gt) == CE_None) {
    if (gt[2] != 0 || gt[4] != 0) throw Error(name + ": a rotated geotransform is not supported");
    // Sample centres: the geotransform gives the corner of pixel (0, 0).
    f.origin = {gt[0] + 0.5 * gt[1], gt[3] + 0.5 * gt[5]};
    f.spacing = {gt[1], gt[5]};
  }
  if (f.width < 2 || f.height < 2) throw Error(name + ": " + std::to_string(f.width) + " x " +
                                               std::to_string(f.height) + " samples, a height field needs 2 x 2");
  GDALRasterBandH band = GDALGetRasterBand(guard.ds, 1);
  f.heights.resize(f.width * f.height);
  if (GDALRasterIO(band, GF_Read, 0, 0, int(f.width), int(f.height), f.heights.data(), int(f.width), int(f.height),
                   GDT_Float32, 0, 0) != CE_None)
    throw Error(name + ": cannot read the samples (" + std::string(CPLGetLastErrorMsg()) + ")");
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata)
    for (float& z : f.heights)
      if (z == float(nodata) || (std::isnan(nodata) && std::isnan(z))) z = kMissing;
  return f;
}

}  // namespace

std::size_t HeightField::missing() const {
  return std::size_t(std::count_if(heights.begin(), heights.end(), [](float z) { return std::isnan(z); }));
}

std::size_t check_height_field(const HeightField& f) {
  if (f.width < 2 || f.height < 2)
    throw Error("height field of " + std::to_string(f.width) + " x " + std::to_string(f.height) +
                " samples: at least 2 x 2 are needed");
  if (f.width > (std::size_t(1) << 30) || f.height > (std::size_t(1) << 30))
    throw Error("height field of " + std::to_string(f.width) + " x " + std::to_string(f.height) +
                " samples: at most 2^30 per side");
  if (f.heights.size() != f.width * f.height)
    throw Error("height field: " + std::to_string(f.heights.size()) + " samples for " + std::to_string(f.width) +
                " x " + std::to_string(f.height));
  for (const double s : f.spacing)
    if (!std::isfinite(s) || s == 0) throw Error("height field: spacing " + format_number(s) + " is not finite and nonzero");
  for (const double o : f.origin)
    if (!std::isfinite(o)) throw Error("height field: origin " + format_number(o) + " is not finite");
  std::size_t valid = 0, infinite = 0;
  // No early exit, and 32-bit counts per block: the loop vectorizes four samples an instruction.
  constexpr std::size_t kBlock = std::size_t(1) << 30;
  for (std::size_t b = 0; b < f.heights.size(); b += kBlock) {
    const std::size_t e = std::min(f.heights.size(), b + kBlock);
    std::uint32_t inf = 0, nan = 0;
    for (std::size_t i = b; i < e; ++i) {
      inf += std::isinf(f.heights[i]);
      nan += std::isnan(f.heights[i]);
    }
    infinite += inf, valid += e - b - nan;
  }
  if (infinite) throw Error("height field: an infinite sample");
  if (valid == 0) throw Error("height field: every sample is missing (NaN or no-data)");
  return f.heights.size() - valid;
}

std::size_t fill_missing(HeightField& f) {
  const std::size_t missing = f.missing();
  if (missing == 0) return 0;
  Grid3<std::uint8_t> mask(f.width, f.height, 1);
  for (std::size_t i = 0; i < f.heights.size(); ++i) mask.data[i] = std::isnan(f.heights[i]);
  field::EdtRequest request;
  request.features = true;
  request.squared = true;
  const field::EdtResult r = field::edt(mask.view(), request);
  for (std::size_t i = 0; i < f.heights.size(); ++i)
    if (mask.data[i]) f.heights[i] = f.heights[r.features[i]];
  return missing;
}

HeightField make_height_field(std::span<const float> heights, std::size_t width, std::size_t height,
                              std::array<double, 2> spacing) {
  HeightField f;
  f.width = width;
  f.height = height;
  f.heights.assign(heights.begin(), heights.end());
  f.spacing = spacing;
  check_height_field(f);
  return f;
}

HeightField read_height_field(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error(path.string() + ": no such file");
  const std::string ext = lower_extension(path);
  HeightField f;
  if (ext == ".png") {
    f = io::image_bit_depth(path) == 16 ? from_image(io::read_image16(path)) : from_image(io::read_image(path));
  } else if (ext == ".bmp") {
    f = from_image(io::read_image(path));
  } else if (ext == ".npy") {
    f = read_npy_field(path);
  } else if (ext == ".ter") {
    f = read_ter(path);
  } else {
    f = read_gdal(path);
  }
  try {
    check_height_field(f);
  } catch (const Error& e) {
    throw Error(path.string() + ": " + e.what());
  }
  return f;
}

}  // namespace geods::terrain
