// libFuzzer target: read_points and the read_table under it; the first byte
// picks the format (.npy, .xyz, .csv, .ply, .txt).
#include "fuzz_common.hpp"
#include "geods/io/point_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* names[] = {"in.npy", "in.xyz", "in.csv", "in.ply", "in.txt"};
  return geods::fuzz::read_as(data + 1, size - 1, names[data[0] % 5], [](const auto& p) { geods::io::read_points(p); });
}
