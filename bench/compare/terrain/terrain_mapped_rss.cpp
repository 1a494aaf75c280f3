// The memory a view of a large memory-mapped terrain file needs (issue 11):
// maps a saved .geodsterrain (structure checked, records not read), refines
// one view and prints, as JSON, the file's size and the process's resident
// set (VmRSS, VmHWM from /proc/self/status) before and after the view, and
// after it its file-backed part (RssFile: the records' pages the view read)
// and its anonymous part (RssAnon: mostly the output mesh).
// Not part of compare.json (the file is several GB); docs/terrain.md has the
// commands that make the file and run this.
//   terrain_mapped_rss FILE.geodsterrain EYE_X EYE_Y EYE_Z TARGET_X TARGET_Y TARGET_Z PIXEL_ERROR
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "geods/terrain/terrain.hpp"

using namespace geods;

static long status_kb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size());
  return -1;
}

int main(int argc, char** argv) {
  if (argc != 9) {
    std::fprintf(stderr, "usage: %s FILE.geodsterrain EX EY EZ TX TY TZ PIXEL_ERROR\n", argv[0]);
    return 2;
  }
  const long rss_start = status_kb("VmRSS:");
  const terrain::Terrain t = terrain::Terrain::load(argv[1], Archive::Verify::structure_only);
  const long rss_loaded = status_kb("VmRSS:");
  terrain::Refinement r;
  terrain::TerrainView v;
  v.camera.eye = Vec3f(std::strtof(argv[2], nullptr), std::strtof(argv[3], nullptr), std::strtof(argv[4], nullptr));
  v.camera.target = Vec3f(std::strtof(argv[5], nullptr), std::strtof(argv[6], nullptr), std::strtof(argv[7], nullptr));
  v.camera.up = Vec3f(0, 0, 1);
  v.camera.vertical_fov_deg = 60;
  r.view = v;
  r.pixel_error = std::strtod(argv[8], nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  const terrain::TerrainMesh m = t.refine(r);
  const double refine_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "{\"file_bytes\": %llu, \"grid\": %llu, \"triangles\": %zu, \"refine_s\": %.3f, \"rss_start_kb\": %ld, "
      "\"rss_loaded_kb\": %ld, \"rss_after_view_kb\": %ld, \"rss_file_kb\": %ld, \"rss_anon_kb\": %ld, \"hwm_kb\": %ld}\n",
      static_cast<unsigned long long>(std::filesystem::file_size(argv[1])),
      static_cast<unsigned long long>(t.layout().n()), m.triangles.size(), refine_s, rss_start, rss_loaded,
      status_kb("VmRSS:"), status_kb("RssFile:"), status_kb("RssAnon:"), status_kb("VmHWM:"));
  return 0;
}
