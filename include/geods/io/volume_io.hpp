#pragma once
// Reading and writing volumes (dense 3D grids).
#include <array>
#include <cstdint>
#include <filesystem>
#include <variant>

#include "geods/core/dtype.hpp"
#include "geods/core/grid3.hpp"

namespace geods::io {

/// A volume of any of the supported sample types.
using AnyGrid3 = std::variant<Grid3<std::uint8_t>, Grid3<std::uint16_t>, Grid3<std::int16_t>,
                              Grid3<float>, Grid3<double>>;

DType grid_dtype(const AnyGrid3& grid);
/// Converts any volume to float samples (same dims, origin, spacing).
Grid3<float> to_float(const AnyGrid3& grid);

/// Reads by extension: .npy (3D array, C order [z][y][x]), .nrrd/.nhdr (raw or
/// gzip encoding), .nii/.nii.gz (NIfTI-1 through nifticlib; origin and spacing
/// from the header). Samples keep the file's type; types without a Grid3 are
/// widened exactly (int8 to int16, 32-bit integers to double, 64-bit integers
/// to double if below 2^53, else an error). NIfTI data with a scl_slope other
/// than 0 or 1 (or a scl_inter) is converted to float as value * slope + inter.
/// Spacing is the length of each axis's direction; rotations and axis flips
/// of NRRD/NIfTI orientations are not kept. Throws geods::Error naming the
/// file and the problem; sizes are checked against the file before allocating.
AnyGrid3 read_volume(const std::filesystem::path& path);

/// Reads a headerless file of nx*ny*nz samples, x fastest, little-endian.
/// The file size must match exactly.
AnyGrid3 read_raw_volume(const std::filesystem::path& path, std::array<std::size_t, 3> dims, DType dtype);

/// Writes .npy (shape nz, ny, nx), .nrrd (raw encoding, with origin and
/// spacing) or .nii/.nii.gz by extension.
void write_volume(const std::filesystem::path& path, const AnyGrid3& grid);

}  // namespace geods::io
