// CGAL 5.5 Regular_triangulation_2 with Epick (exact predicates, filtered), range insert of
// Weighted_point_2 (spatially sorted inside). The copy of the input is part of the time.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>

#include "power_driver.hpp"

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangulation = CGAL::Regular_triangulation_2<Kernel>;

struct Cgal {
  static constexpr const char* anchor = "cgal";
  static power::Result triangulate(const std::vector<double>& xy, const std::vector<double>& w, std::size_t n) {
    std::vector<Kernel::Weighted_point_2> points;
    points.reserve(n);
    for (std::size_t i = 0; i < n; ++i) points.emplace_back(Kernel::Point_2(xy[2 * i], xy[2 * i + 1]), w[i]);
    Triangulation rt;
    rt.insert(points.begin(), points.end());
    const std::size_t all_faces = rt.tds().number_of_faces();  // with the infinite ones, one per hull edge
    return {rt.number_of_vertices(), rt.number_of_faces(), all_faces - rt.number_of_faces()};
  }
};

int main(int argc, char** argv) { return power::run<Cgal>(argc, argv); }
