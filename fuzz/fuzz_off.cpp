// libFuzzer target: read_mesh on .off files.
#include "fuzz_common.hpp"
#include "geods/io/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return geods::fuzz::read_as(data, size, "in.off", [](const auto& p) { geods::io::read_mesh(p); });
}
