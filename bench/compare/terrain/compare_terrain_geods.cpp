// geods::terrain on the terrain comparison: the USGS Jacksboro DEM (data/jacksboro_dem.npy,
// 344 x 403 int16 metres, public domain) mirrored into 1025^2 (as field.mjs does for martini
// and delatin): sample (x, y) is the DEM's (reflect(x, 403), reflect(y, 344)).
// Variants: e<T>: the 4-8 mesh within T of every sample (build_s = the hierarchy, query_s =
// the refinement; the default layout, matrix); tin_e<T>: the greedy TIN within T; view: view-dependent refinement
// (tau = 1 pixel, 1024 x 768, 60 degrees) from 16 low viewpoints, query_s = per view;
// view_matrix: the same with the matrix layout; stream_bound: the floor of the exact nested
// errors, one streaming pass per level (2 log2(n - 1) passes) of the library's row kernel (AVX2 where the CPU has it)
// max |z - plane| over every row of the grid. Every mesh's error is measured against
// every sample (max_error) and must be <= T.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/terrain/terrain.hpp"
#include "triangle_raster.hpp"

using namespace geods;

// i reflected into 0..n-1 (period 2n - 2, the border samples not repeated).
static std::size_t reflect(std::size_t i, std::size_t n) {
  const std::size_t p = 2 * (n - 1), k = i % p;
  return k < n ? k : p - k;
}

static terrain::HeightField field_1025() {
  const terrain::HeightField in = terrain::read_height_field(GEODS_DATA_DIR "/jacksboro_dem.npy");
  terrain::HeightField f;
  f.width = f.height = 1025;
  f.heights.resize(1025 * 1025);
  for (std::size_t y = 0; y < 1025; ++y)
    for (std::size_t x = 0; x < 1025; ++x) f.heights[y * 1025 + x] = in(reflect(x, in.width), reflect(y, in.height));
  return f;
}

namespace {
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
}  // namespace

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  const terrain::HeightField field = field_1025();
  terrain::Terrain t;
  // Each repetition's field is copied and the previous hierarchy freed outside the timing:
  // the constructor takes the field by value (a caller moves it in), and martini's createTile
  // gets its array as it is.
  std::vector<double> build_times;
  for (int r = 0; r < args.reps; ++r) {
    terrain::HeightField copy = field;
    t = terrain::Terrain();
    build_times.push_back(compare::time_s([&] { t = terrain::Terrain(std::move(copy)); }));
  }
  const double build_s = compare::median(std::move(build_times));
  if (args.wants("stream_bound")) {
    // What the exact errors cost at least: every sample against one plane per level,
    // as whole rows (no triangle boundaries, no planes to set up, nothing to nest).
    const std::int64_t n = 1025;
    const int passes = 2 * 10;
    // The kernel the build runs on long rows (AVX2 where the CPU has it; the
    // SSE2 one, two doubles at a time, took twice as long).
    const bool avx2 = simd_level() >= SimdLevel::avx2;
    double worst = 0;
    const double s = compare::median_time_s(args.reps, [&] {
      worst = 0;
      for (int level = 0; level < passes; ++level)
        for (std::int64_t y = 0; y < n; ++y)
          worst = std::max(worst, terrain::detail::row_max_picked(avx2, field.heights.data() + y * n, 0, n - 1,
                                                                  300.0 + 0.01 * double(y), 1e-3 * level, 0));
    });
    compare::Record("terrain", "geods", "stream_bound", args.threads)
        .timing(s, 0, std::size_t(passes) * std::size_t(n * n), args.reps)
        .set("passes", passes)
        .set("samples", std::size_t(passes) * std::size_t(n * n))
        .set("ns_per_sample", 1e9 * s / double(passes * n * n))
        .print(worst > 0);
  }
  for (const double target : {2.0, 4.0, 8.0, 16.0, 32.0}) {
    const std::string e = std::to_string(int(target));
    if (args.wants("e" + e)) {
      terrain::Refinement r;
      r.max_error = target;
      terrain::TerrainMesh m;
      const double s = compare::median_time_s(args.reps, [&] { m = t.refine(r); });
      const double err = t.measure_error(m);
      compare::Record("terrain", "geods", "e" + e, args.threads)
          .timing(build_s, s, m.triangles.size(), args.reps)
          .set("triangles", m.triangles.size())
          .set("max_error", err)
          .set("strip_length", m.strip.size())
          .print(err <= target);
    }
    if (args.wants("tin_e" + e)) {
      terrain::TerrainMesh m;
      double cpu_s = 1e300;  // the least thread CPU time of a construction (the load disturbs it less than wall time)
      const double s = compare::median_time_s(args.reps, [&] {
        const double c0 = thread_cpu_s();
        m = t.tin(target);
        cpu_s = std::min(cpu_s, thread_cpu_s() - c0);
      });
      const double err = t.measure_error(m);
      compare::Record("terrain", "geods", "tin_e" + e, args.threads)
          .timing(0, s, m.triangles.size(), args.reps)
          .set("cpu_s", cpu_s)
          .set("triangles", m.triangles.size())
          .set("max_error", err)
          .print(err <= target);
    }
  }
  // Views: a low flight across the field (at the DEM's spacing, about 90 m, heights in
  // metres: 236..1076), 1400 m high, looking ahead about 28 km and a little down.
  terrain::HeightField metres = field;
  metres.spacing = {90, 90};
  for (const auto layout : {terrain::Layout::interleaved, terrain::Layout::matrix}) {
    const std::string name = layout == terrain::Layout::matrix ? "view_matrix" : "view";
    if (!args.wants(name)) continue;
    terrain::TerrainOptions o;
    o.layout = layout;
    const terrain::Terrain tv(metres, o);
    std::size_t triangles = 0;
    const int views = 16;
    const double s = compare::median_time_s(args.reps, [&] {
      triangles = 0;
      for (int k = 0; k < views; ++k) {
        const double a = 2 * M_PI * k / views;
        terrain::Refinement r;
        terrain::TerrainView v;
        v.camera.eye = Vec3f(float(90 * (512 + 400 * std::cos(a))), float(90 * (512 + 400 * std::sin(a))), 1400.0f);
        v.camera.target =
            Vec3f(float(90 * (512 + 400 * std::cos(a + 0.8))), float(90 * (512 + 400 * std::sin(a + 0.8))), 400.0f);
        v.camera.up = Vec3f(0, 0, 1);
        v.camera.vertical_fov_deg = 60;
        r.view = v;
        r.pixel_error = 1;
        triangles += tv.refine(r).triangles.size();
      }
    });
    compare::Record("terrain", "geods", name, args.threads)
        .timing(build_s, s / views, triangles / views, args.reps)
        .set("triangles", triangles / views)
        .set("ms_per_view", 1e3 * s / views)
        .print(triangles > 0);
  }
  return 0;
}
