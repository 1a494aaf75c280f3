// CGAL 5.5 Delaunay_triangulation_2 (Epick) with the site index as vertex info:
// nearest_vertex(q), CGAL's walk to the query's face then a greedy search.
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include "nearest_driver.hpp"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vertex = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vertex>;
using Triangulation = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

struct Cgal {
  static constexpr const char* anchor = "cgal";
  using Index = Triangulation;
  static std::unique_ptr<Index> build(const double* xy, std::size_t n) {
    std::vector<std::pair<Kernel::Point_2, std::uint32_t>> points;
    points.reserve(n);
    for (std::size_t i = 0; i < n; ++i) points.push_back({Kernel::Point_2(xy[2 * i], xy[2 * i + 1]), std::uint32_t(i)});
    auto dt = std::make_unique<Triangulation>();
    dt->insert(points.begin(), points.end());
    return dt;
  }
  static std::uint32_t nearest(const Index& dt, const double* q) {
    return dt.nearest_vertex(Kernel::Point_2(q[0], q[1]))->info();
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::nearest::run<Cgal>(argc, argv); }
