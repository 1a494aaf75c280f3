// CGAL 5.5 Delaunay_triangulation_3 with Epick (exact predicates, filtered), range insert (which
// spatially sorts the points, BRIO + Hilbert, before inserting); with more than one thread its
// Parallel_tag data structure and a lock grid over the bounding box. The copy of the input into
// Point_3 is part of the time, as geods' copy is.
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "del3_driver.hpp"

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Sequential = CGAL::Delaunay_triangulation_3<Kernel>;
#ifdef CGAL_LINKED_WITH_TBB
using ParallelTds = CGAL::Triangulation_data_structure_3<CGAL::Triangulation_vertex_base_3<Kernel>,
                                                         CGAL::Delaunay_triangulation_cell_base_3<Kernel>,
                                                         CGAL::Parallel_tag>;
using Parallel = CGAL::Delaunay_triangulation_3<Kernel, ParallelTds>;
#endif

template <class Triangulation>
del3::Result counts(const Triangulation& dt, const del3::MemoryMark& before) {
  return {dt.number_of_vertices(), dt.number_of_finite_cells(), dt.number_of_cells() - dt.number_of_finite_cells(),
          del3::memory_since(before)};
}

struct Cgal {
  static constexpr const char* workload = "del3";
  static constexpr int max_reps = 100;
  static constexpr const char* anchor = "cgal";
  static del3::Result tetrahedralize(const std::vector<double>& xyz, std::size_t n, int threads) {
    const del3::MemoryMark before = del3::memory_mark();
    std::vector<Kernel::Point_3> points;
    points.reserve(n);
    for (std::size_t i = 0; i < n; ++i) points.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
#ifdef CGAL_LINKED_WITH_TBB
    if (threads > 1) {
      Parallel::Lock_data_structure locks(CGAL::bbox_3(points.begin(), points.end()), 50);
      Parallel dt(points.begin(), points.end(), &locks);
      return counts(dt, before);
    }
#endif
    (void)threads;
    Sequential dt(points.begin(), points.end());
    return counts(dt, before);
  }
};

int main(int argc, char** argv) { return del3::run<Cgal>(argc, argv); }
