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

#include <climits>
#include <cstring>
#include <memory>

#include "file_util.hpp"
#include "geods/io/image_io.hpp"

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

void write_png(const fs::path& path, const Image<std::uint8_t>& image) {
  if (image.channels < 1 || image.channels > 4)
    fail(path, "cannot write PNG with " + std::to_string(image.channels) + " channels (1 to 4)");
  if (image.width == 0 || image.height == 0) fail(path, "cannot write an empty image");
  if (image.width > INT_MAX / image.channels || image.height > INT_MAX)
    fail(path, "image too large for PNG writing");
  if (image.data.size() != image.width * image.height * image.channels)
    fail(path, "image holds " + std::to_string(image.data.size()) + " samples, expected " +
                   std::to_string(image.width * image.height * image.channels));
  std::vector<std::uint8_t> out;
  if (!stbi_write_png_to_func(append, &out, int(image.width), int(image.height), int(image.channels),
                              image.data.data(), int(image.width * image.channels)))
    fail(path, "PNG encoding failed");
  detail::write_file(path, out);
}

}  // namespace geods::io
