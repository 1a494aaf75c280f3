// geods::voronoi::Delaunay3 (BRIO + 3D Hilbert order, visibility walk, Bowyer-Watson cavities,
// exact predicates with symbolic perturbation) on the del3 workload. The copy of the input into
// Vec3d is part of the time. Memory: the resident memory the structure adds (peak while alive).
// Built twice: compare_del3_geods (cavity insertion) and, with GEODS_DEL3_FLIPS,
// compare_del3_geods_flips (the same tetrahedralization by 1-4, 2-3, 3-2 flips).
#include "del3_driver.hpp"
#include "geods/voronoi/delaunay3.hpp"

struct Geods {
  static constexpr const char* workload = "del3";
  static constexpr int max_reps = 100;
#ifdef GEODS_DEL3_FLIPS
  static constexpr const char* anchor = "geods_flips";
  static constexpr auto insertion = geods::voronoi::Delaunay3Insertion::flips;
#else
  static constexpr const char* anchor = "geods";
  static constexpr auto insertion = geods::voronoi::Delaunay3Insertion::cavity;
#endif
  static del3::Result tetrahedralize(const std::vector<double>& xyz, std::size_t n, int /*threads*/) {
    const del3::MemoryMark before = del3::memory_mark();
    std::vector<geods::Vec3d> points(n);
    for (std::size_t i = 0; i < n; ++i) points[i] = geods::Vec3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    const geods::voronoi::Delaunay3 dt(points, {.insertion = insertion});
    const geods::voronoi::Delaunay3Stats s = dt.stats();
    return {s.vertices, s.tetrahedra, s.hull_triangles, del3::memory_since(before)};
  }
};

int main(int argc, char** argv) { return del3::run<Geods>(argc, argv); }
