// libFuzzer target: read_npy, then the conversion every caller makes.
#include "fuzz_common.hpp"
#include "geods/io/npy.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return geods::fuzz::read_as(data, size, "in.npy", [](const auto& p) {
    const geods::io::NpyArray a = geods::io::read_npy(p);
    a.to_vector<double>();
    a.to_vector<std::int32_t>();
  });
}
