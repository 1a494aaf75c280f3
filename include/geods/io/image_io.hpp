#pragma once
// Reading and writing images (stb; 16-bit PNG written with zlib).
#include <cstdint>
#include <filesystem>

#include "geods/core/image.hpp"

namespace geods::io {

/// Reads PNG, JPEG or BMP as 8-bit samples with the file's own channel count
/// (1 grey, 2 grey+alpha, 3 RGB, 4 RGBA).
Image<std::uint8_t> read_image(const std::filesystem::path& path);
/// Bits per sample of the image file at `path`: 16 for a 16-bit PNG, else 8
/// (what read_image returns; it scales 16-bit samples down to 8 bits).
int image_bit_depth(const std::filesystem::path& path);
/// Reads a PNG keeping 16-bit samples (8-bit files are scaled to 16 bits).
Image<std::uint16_t> read_image16(const std::filesystem::path& path);

/// Writes an 8-bit PNG with 1 to 4 channels.
void write_png(const std::filesystem::path& path, const Image<std::uint8_t>& image);
/// Writes a 16-bit PNG with 1 to 4 channels (samples as they are, 0..65535).
void write_png(const std::filesystem::path& path, const Image<std::uint16_t>& image);
/// Writes an 8-bit PNG of samples in [0, 1]: each is written as round(v * 255).
/// Throws geods::Error naming the first sample that is NaN or outside [0, 1]
/// (nothing is clamped; scale or clip the image first).
void write_png(const std::filesystem::path& path, const Image<float>& image);
void write_png(const std::filesystem::path& path, const Image<double>& image);

}  // namespace geods::io
