// geods::voronoi::Delaunay2 (BRIO + Hilbert order, visibility walk, Lawson flips, exact
// predicates) on the del2 workloads. Single-threaded algorithm; the copy of the input into
// Vec2d is part of the time.
#include <span>

#include "del2_driver.hpp"
#include "geods/voronoi/delaunay2.hpp"

struct Geods {
  static constexpr const char* workload = "del2";
  static constexpr int max_reps = 100;
  static constexpr const char* anchor = "geods";
  static del2::Result triangulate(const std::vector<double>& xy, std::size_t n) {
    std::vector<geods::Vec2d> points(n);
    for (std::size_t i = 0; i < n; ++i) points[i] = geods::Vec2d(xy[2 * i], xy[2 * i + 1]);
    const geods::voronoi::Delaunay2 dt(points);
    const geods::voronoi::Delaunay2Stats s = dt.stats();
    return {s.vertices, s.triangles, s.hull};
  }
};

int main(int argc, char** argv) { return del2::run<Geods>(argc, argv); }
