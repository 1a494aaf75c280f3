// Shared by the segvoronoi comparison programs: the inputs and the timing loop.
//
// Variants (the same integer segments for every library; geods' own snap keeps them exactly):
//   random: 100k segments, one in each cell of a 317 x 317 grid of 65536-unit cells, endpoints
//           uniform strictly inside the cell (so no two segments meet), SplitMix64 seed 15;
//   map:    the distinct boundary edges of data/nc_counties.shp (North Carolina counties,
//           lon/lat), snapped as geods snaps them (x 2^k around the box centre, within +-2^25).
// A library provides   static Result build(const std::vector<std::array<std::int64_t, 4>>& segments)
// returning its counts, and max_reps; the driver times it (median of min(--reps, max_reps)).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "common.hpp"
#include "geods/io/polygon_io.hpp"

namespace segvoronoi {

using Segments = std::vector<std::array<std::int64_t, 4>>;

struct Result {
  std::size_t vertices = 0;  // Voronoi vertices (or Delaunay faces), as the library counts them
  std::size_t edges = 0;     // Voronoi edges (or Delaunay edges)
};

inline Segments random_segments(std::size_t cells_per_side) {
  compare::SplitMix64 rng(15);
  Segments out;
  const std::int64_t cell = 65536;
  auto coord = [&](std::int64_t base) { return base + 1 + static_cast<std::int64_t>(rng.next() % (cell - 2)); };
  for (std::size_t j = 0; j < cells_per_side; ++j)
    for (std::size_t i = 0; i < cells_per_side; ++i) {
      const std::int64_t x = static_cast<std::int64_t>(i) * cell, y = static_cast<std::int64_t>(j) * cell;
      std::array<std::int64_t, 4> s{coord(x), coord(y), coord(x), coord(y)};
      if (s[0] == s[2] && s[1] == s[3]) s[2] += 1;
      out.push_back(s);
    }
  return out;
}

inline Segments map_segments(const std::string& path) {
  const geods::io::PolygonSet set = geods::io::read_polygons(path);
  const std::vector<double> flat = set.all_segments();
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (std::size_t i = 0; i < flat.size(); ++i) lo[i % 2] = std::min(lo[i % 2], flat[i]), hi[i % 2] = std::max(hi[i % 2], flat[i]);
  const double c[2] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])};
  const double half = 0.5 * std::max(hi[0] - lo[0], hi[1] - lo[1]);
  const double scale = std::ldexp(1.0, std::ilogb(33554432.0 / half));
  std::set<std::array<std::int64_t, 4>> seen;
  Segments out;
  for (std::size_t i = 0; i + 3 < flat.size(); i += 4) {
    std::array<std::int64_t, 4> s;
    for (int k = 0; k < 4; ++k) s[k] = static_cast<std::int64_t>(std::nearbyint((flat[i + k] - c[k % 2]) * scale));
    if (s[0] == s[2] && s[1] == s[3]) continue;
    std::array<std::int64_t, 4> key = s;
    if (std::make_pair(key[2], key[3]) < std::make_pair(key[0], key[1])) key = {s[2], s[3], s[0], s[1]};
    if (seen.insert(key).second) out.push_back(s);
  }
  return out;
}

template <class Library>
void run_variant(const compare::Args& args, const std::string& variant) {
  Segments segments;
  if (variant == "random") {
    const auto side = static_cast<std::size_t>(std::lround(317 * std::sqrt(args.scale)));
    segments = random_segments(std::max<std::size_t>(side, 2));
  } else {
    segments = map_segments(std::string(GEODS_DATA_DIR) + "/nc_counties.shp");
  }
  Result result;
  const int reps = std::min(args.reps, Library::max_reps);
  const double build_s = compare::median_time_s(reps, [&] { result = Library::build(segments); });
  compare::Record("segvoronoi", Library::anchor, variant, args.threads)
      .timing(build_s, 0.0, segments.size(), reps)
      .set("segments", static_cast<unsigned long long>(segments.size()))
      .set("vertices", static_cast<unsigned long long>(result.vertices))
      .set("edges", static_cast<unsigned long long>(result.edges))
      .print(result.vertices > 0);
}

template <class Library>
int run(int argc, char** argv) {
  return compare::run_variants(argc, argv, {"random", "map"}, run_variant<Library>);
}

}  // namespace segvoronoi
