#pragma once
// Height fields: a regular grid of heights, read from images (8- and 16-bit
// grey PNG, BMP), NumPy arrays, Terragen .ter files and GDAL rasters
// (GeoTIFF...), with the sample spacing and origin of the file where it has them.
#include <array>
#include <cstddef>
#include <filesystem>
#include <span>
#include <vector>

namespace geods::terrain {

/// Heights on a width x height grid, rows first (sample (x, y) is
/// heights[y * width + x]); sample (x, y) lies at origin + (x * spacing[0], y * spacing[1]).
/// A NaN height is a missing sample ("no data").
struct HeightField {
  std::size_t width = 0, height = 0;
  std::vector<float> heights;
  std::array<double, 2> spacing{1, 1};  // along x and y; nonzero and finite (a geotransform may make y negative)
  std::array<double, 2> origin{0, 0};

  float operator()(std::size_t x, std::size_t y) const { return heights[y * width + x]; }
  std::size_t missing() const;  // NaN samples
};

/// Reads a height field by the file's extension:
/// - .png: 8- or 16-bit grey (or the first channel of RGB), samples as they are (0..255 or 0..65535);
/// - .bmp: the first channel, 0..255;
/// - .npy: a 2-D array (rows = y) of any integer or floating dtype;
/// - .ter: Terragen (SIZE/XPTS/YPTS/SCAL/ALTW chunks): heights in metres
///   (BaseHeight + v * HeightScale / 65536) * SCAL[2], spacing SCAL[0], SCAL[1];
/// - anything else through GDAL (.tif GeoTIFF, .asc, .dem, .hgt, ...): band 1,
///   the geotransform as origin and spacing (a rotated one is refused), the
///   band's no-data value read as missing (NaN).
/// Throws geods::Error naming the file for unreadable, truncated or malformed
/// files, fewer than 2 x 2 samples, more than 2^31 per side, or no valid sample.
HeightField read_height_field(const std::filesystem::path& path);

/// A field from rows-first samples (as Python passes them); NaN samples are missing.
HeightField make_height_field(std::span<const float> heights, std::size_t width, std::size_t height,
                              std::array<double, 2> spacing = {1, 1});

/// Checks the rules every field obeys: at least 2 x 2 samples, heights.size() ==
/// width * height, finite nonzero spacing, at least one non-NaN sample, no
/// infinite sample. Throws geods::Error saying what is wrong. Returns the
/// number of missing (NaN) samples, counted in the same pass.
std::size_t check_height_field(const HeightField& field);

/// The no-data rule: every missing (NaN) sample takes the height of its
/// nearest valid sample (Euclidean distance in samples; ties to the lowest
/// row, then column), so the surface stays closed: no holes, no cracks.
/// Returns the number of samples filled.
std::size_t fill_missing(HeightField& field);

}  // namespace geods::terrain
