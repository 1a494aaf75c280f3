// libFuzzer target: read_image and read_image16 (PNG, JPEG, BMP by content).
#include "fuzz_common.hpp"
#include "geods/io/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  geods::fuzz::read_as(data, size, "in.png", [](const auto& p) { geods::io::read_image(p); });
  return geods::fuzz::read_as(data, size, "in.png", [](const auto& p) { geods::io::read_image16(p); });
}
