// geods::voronoi::RegularTriangulation (BRIO order, visibility walk, 2-2 / 3-1 / 4-2 flips,
// exact power tests) on the power workloads. The copy of the input is part of the time.
#include "geods/voronoi/power_diagram.hpp"
#include "power_driver.hpp"

struct Geods {
  static constexpr const char* anchor = "geods";
  static power::Result triangulate(const std::vector<double>& xy, const std::vector<double>& w, std::size_t n) {
    std::vector<geods::Vec2d> points(n);
    for (std::size_t i = 0; i < n; ++i) points[i] = geods::Vec2d(xy[2 * i], xy[2 * i + 1]);
    const geods::voronoi::RegularTriangulation rt(points, w);
    const auto s = rt.stats();
    return {s.vertices, s.triangles, s.hull};
  }
};

int main(int argc, char** argv) { return power::run<Geods>(argc, argv); }
