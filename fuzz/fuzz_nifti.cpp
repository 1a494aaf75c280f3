// libFuzzer target: read_volume on .nii files (gzip-compressed ones are recognized by content).
#include "fuzz_common.hpp"
#include "geods/io/volume_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return geods::fuzz::read_as(data, size, "in.nii", [](const auto& p) { geods::io::read_volume(p); });
}
