// geods::voronoi::Voronoi3 on the vor3 workload: Delaunay3 of the points, then every cell as the
// unit cube cut by the bisectors of its Delaunay neighbours, in parallel (threads > 1). The copy
// of the input into Vec3d and the tetrahedralization are part of the time.
#include "geods/voronoi/voronoi3.hpp"
#include "vor3_driver.hpp"

struct Geods {
  static constexpr const char* anchor = "geods";
  static vor3::Result cells(const std::vector<double>& xyz, std::size_t n) {
    std::vector<geods::Vec3d> points(n);
    for (std::size_t i = 0; i < n; ++i) points[i] = geods::Vec3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    const geods::voronoi::Voronoi3 diagram(points, geods::AABB3d(geods::Vec3d(0, 0, 0), geods::Vec3d(1, 1, 1)));
    const geods::voronoi::Voronoi3Stats s = diagram.stats();
    return {s.sites - s.empty, s.faces, s.vertices, diagram.volume_total()};
  }
};

int main(int argc, char** argv) { return vor3::run<Geods>(argc, argv); }
