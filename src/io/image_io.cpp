// stb is compiled here, static and limited to the formats we read, so that its
// symbols cannot clash with another copy (Assimp embeds one) and the decoders
// exposed to hostile files are few.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_BMP
#define STBI_NO_STDIO
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STBI_WRITE_NO_STDIO
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#include <zlib.h>

#include <climits>
#include <cmath>
#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "file_util.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/output.hpp"

namespace geods::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

// Decodes with stb after checking the header's dimensions against the file:
// no real PNG, JPEG or BMP expands more than about 2000:1, so a tiny file
// claiming a gigapixel image is rejected before stb allocates for it.
template <typename T>
Image<T> decode(const fs::path& path) {
  const std::vector<std::uint8_t> bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  if (bytes.size() > std::size_t(INT_MAX)) fail(path, "image file larger than 2 GiB");
  const int len = int(bytes.size());
  int w = 0, h = 0, c = 0;
  if (!stbi_info_from_memory(bytes.data(), len, &w, &h, &c))
    fail(path, std::string("not a readable PNG, JPEG or BMP image (") + stbi_failure_reason() + ")");
  const double samples = double(w) * double(h) * double(c) * sizeof(T);
  if (w <= 0 || h <= 0 || samples > 2048.0 * double(bytes.size()) + double(1 << 24))
    fail(path, "header claims " + std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(c) +
                   " samples, more than a " + std::to_string(bytes.size()) + "-byte file can hold");
  std::unique_ptr<T, StbFree> pixels;
  if constexpr (sizeof(T) == 2) {
    pixels.reset(stbi_load_16_from_memory(bytes.data(), len, &w, &h, &c, 0));
  } else {
    pixels.reset(stbi_load_from_memory(bytes.data(), len, &w, &h, &c, 0));
  }
  if (!pixels) fail(path, std::string("cannot decode image (") + stbi_failure_reason() + ")");
  Image<T> image;
  image.width = std::size_t(w);
  image.height = std::size_t(h);
  image.channels = std::size_t(c);
  image.data.assign(pixels.get(), pixels.get() + Image<T>::checked_size(image.width, image.height, image.channels));
  return image;
}

void append(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  const auto* p = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}

}  // namespace

Image<std::uint8_t> read_image(const fs::path& path) { return decode<std::uint8_t>(path); }

Image<std::uint16_t> read_image16(const fs::path& path) { return decode<std::uint16_t>(path); }

int image_bit_depth(const fs::path& path) {
  const std::vector<std::uint8_t> bytes = detail::read_file(path);
  if (bytes.empty()) fail(path, "empty file");
  if (bytes.size() > std::size_t(INT_MAX)) fail(path, "image file larger than 2 GiB");
  return stbi_is_16_bit_from_memory(bytes.data(), int(bytes.size())) ? 16 : 8;
}

namespace {

template <typename T>
void check_writable(const fs::path& path, const Image<T>& image) {
  check_output_extension(path, OutputKind::image);
  if (image.channels < 1 || image.channels > 4)
    fail(path, "cannot write PNG with " + std::to_string(image.channels) + " channels (1 to 4)");
  if (image.width == 0 || image.height == 0) fail(path, "cannot write an empty image");
  if (image.width > INT_MAX / image.channels / sizeof(T) || image.height > INT_MAX)
    fail(path, "image too large for PNG writing");
  if (image.data.size() != image.width * image.height * image.channels)
    fail(path, "image holds " + std::to_string(image.data.size()) + " samples, expected " +
                   std::to_string(image.width * image.height * image.channels));
}

void put_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(std::uint8_t(v >> s));
}

void put_chunk(std::vector<std::uint8_t>& out, const char (&type)[5], std::span<const std::uint8_t> body) {
  put_be32(out, std::uint32_t(body.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), body.begin(), body.end());
  put_be32(out, std::uint32_t(crc32(0, out.data() + start, uInt(out.size() - start))));
}

template <typename T>
Image<std::uint8_t> unit_to_8_bit(const fs::path& path, const Image<T>& image) {
  Image<std::uint8_t> out;
  out.width = image.width;
  out.height = image.height;
  out.channels = image.channels;
  out.data.resize(image.data.size());
  for (std::size_t i = 0; i < image.data.size(); ++i) {
    const T v = image.data[i];
    if (!(v >= 0 && v <= 1)) {
      const std::size_t pixel = i / image.channels;
      fail(path, fmt::format("cannot write PNG: sample {:g} at x {}, y {}, channel {} is outside [0, 1] (floating-point "
                             "images are written as round(255 v) for v in [0, 1]; scale or clip it first)",
                             double(v), pixel % image.width, pixel / image.width, i % image.channels));
    }
    out.data[i] = std::uint8_t(std::lround(double(v) * 255.0));
  }
  return out;
}

}  // namespace

void write_png(const fs::path& path, const Image<std::uint8_t>& image) {
  check_writable(path, image);
  std::vector<std::uint8_t> out;
  if (!stbi_write_png_to_func(append, &out, int(image.width), int(image.height), int(image.channels),
                              image.data.data(), int(image.width * image.channels)))
    fail(path, "PNG encoding failed");
  detail::write_file(path, out);
}

// stb writes 8-bit PNG only: the 16-bit one is written here, each row with
// filter 0 (none) and the samples big-endian, as the PNG format has them.
void write_png(const fs::path& path, const Image<std::uint16_t>& image) {
  check_writable(path, image);
  const std::size_t row = image.width * image.channels;
  std::vector<std::uint8_t> raw;
  raw.reserve(image.height * (1 + 2 * row));
  for (std::size_t y = 0; y < image.height; ++y) {
    raw.push_back(0);
    for (std::size_t i = 0; i < row; ++i) {
      const std::uint16_t v = image.data[y * row + i];
      raw.push_back(std::uint8_t(v >> 8));
      raw.push_back(std::uint8_t(v & 0xff));
    }
  }
  uLongf packed_size = compressBound(uLong(raw.size()));
  std::vector<std::uint8_t> packed(packed_size);
  if (compress2(packed.data(), &packed_size, raw.data(), uLong(raw.size()), Z_DEFAULT_COMPRESSION) != Z_OK)
    fail(path, "PNG encoding failed (zlib)");
  packed.resize(packed_size);
  static constexpr std::uint8_t colour_type[5] = {0, 0, 4, 2, 6};  // grey, grey+alpha, RGB, RGBA
  std::vector<std::uint8_t> header;
  put_be32(header, std::uint32_t(image.width));
  put_be32(header, std::uint32_t(image.height));
  header.insert(header.end(), {16, colour_type[image.channels], 0, 0, 0});
  std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  put_chunk(out, "IHDR", header);
  // One IDAT chunk holds at most 2^31 - 1 bytes.
  for (std::size_t at = 0; at < packed.size() || at == 0; at += 0x7fffffff) {
    const std::size_t n = std::min<std::size_t>(packed.size() - at, 0x7fffffff);
    put_chunk(out, "IDAT", std::span<const std::uint8_t>(packed.data() + at, n));
    if (packed.empty()) break;
  }
  put_chunk(out, "IEND", {});
  detail::write_file(path, out);
}

void write_png(const fs::path& path, const Image<float>& image) {
  check_writable(path, image);
  write_png(path, unit_to_8_bit(path, image));
}

void write_png(const fs::path& path, const Image<double>& image) {
  check_writable(path, image);
  write_png(path, unit_to_8_bit(path, image));
}

}  // namespace geods::io
