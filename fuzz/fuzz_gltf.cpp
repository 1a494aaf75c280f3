// libFuzzer target: read_mesh on glTF, as .glb for binary input ("glTF" magic) and .gltf otherwise.
#include <cstring>

#include "fuzz_common.hpp"
#include "geods/io/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  return geods::fuzz::read_as(data, size, glb ? "in.glb" : "in.gltf", [](const auto& p) { geods::io::read_mesh(p); });
}
