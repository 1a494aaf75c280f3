// libFuzzer target: read_segments (and read_table for .npy/.csv); the first
// byte picks the format (.npy, .edg, .cin, .csv).
#include "fuzz_common.hpp"
#include "geods/io/point_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* names[] = {"in.npy", "in.edg", "in.cin", "in.csv"};
  return geods::fuzz::read_as(data + 1, size - 1, names[data[0] % 4], [](const auto& p) { geods::io::read_segments(p); });
}
