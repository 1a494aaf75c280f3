#pragma once
// Shared by the volume readers and writers (not public API).
#include <span>

#include "geods/io/volume_io.hpp"

namespace geods::io::detail {

/// Builds a volume from nx*ny*nz samples of `dtype` in native byte order.
/// Types without a Grid3 of their own are widened exactly: i8 to i16, 32-bit
/// integers to double, 64-bit integers to double if every value is below 2^53.
AnyGrid3 grid_from_samples(const std::filesystem::path& path, std::array<std::size_t, 3> dims, DType dtype,
                           std::span<const std::uint8_t> samples);

/// The samples' bytes (native order) and element type of any volume.
std::span<const std::uint8_t> grid_bytes(const AnyGrid3& grid);
std::array<std::size_t, 3> grid_dims(const AnyGrid3& grid);
Vec3f grid_origin(const AnyGrid3& grid);
Vec3f grid_spacing(const AnyGrid3& grid);
void set_geometry(AnyGrid3& grid, const Vec3f& origin, const Vec3f& spacing);

AnyGrid3 read_nrrd(const std::filesystem::path& path);
void write_nrrd(const std::filesystem::path& path, const AnyGrid3& grid);
AnyGrid3 read_nifti(const std::filesystem::path& path);
void write_nifti(const std::filesystem::path& path, const AnyGrid3& grid);

}  // namespace geods::io::detail
