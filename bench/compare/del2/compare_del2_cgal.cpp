// CGAL 5.5 Delaunay_triangulation_2 with Epick (exact predicates, filtered), range insert
// (which spatially sorts the points, BRIO + Hilbert, before inserting). The copy of the input
// into Point_2 is part of the time, as geods' copy is.
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "del2_driver.hpp"

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangulation = CGAL::Delaunay_triangulation_2<Kernel>;

struct Cgal {
  static constexpr const char* workload = "del2";
  static constexpr int max_reps = 100;
  static constexpr const char* anchor = "cgal";
  static del2::Result triangulate(const std::vector<double>& xy, std::size_t n) {
    std::vector<Kernel::Point_2> points;
    points.reserve(n);
    for (std::size_t i = 0; i < n; ++i) points.emplace_back(xy[2 * i], xy[2 * i + 1]);
    Triangulation dt;
    dt.insert(points.begin(), points.end());
    const std::size_t all_faces = dt.tds().number_of_faces();  // with the infinite ones, one per hull edge
    return {dt.number_of_vertices(), dt.number_of_faces(), all_faces - dt.number_of_faces()};
  }
};

int main(int argc, char** argv) { return del2::run<Cgal>(argc, argv); }
