#pragma once
// Reading and writing images (stb).
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

}  // namespace geods::io
