// CGAL Polygon_mesh_processing::corefine_and_compute_union / difference / intersection on
// Surface_mesh (kernel Epick, or Epeck with -DCSG_EPECK), csg_driver.hpp.
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Surface_mesh.h>

#include "csg_surface_mesh.hpp"

#ifdef CSG_EPECK
using K = CGAL::Exact_predicates_exact_constructions_kernel;
constexpr const char* kAnchor = "cgal_epeck";
#else
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
constexpr const char* kAnchor = "cgal";
#endif
using SM = CGAL::Surface_mesh<K::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

int main(int argc, char** argv) {
  using namespace csg_bench;
  return run(argc, argv, kAnchor, [](const Mesh& a, const Mesh& b, Op op, Mesh& out, double& build_s, double& query_s) {
    SM sa, sb, so;
    build_s = compare::time_s([&] { sa = to_surface_mesh<SM>(a), sb = to_surface_mesh<SM>(b); });
    bool ok = false;
    query_s = compare::time_s([&] {
      if (op == Op::union_) ok = PMP::corefine_and_compute_union(sa, sb, so);
      else if (op == Op::intersection) ok = PMP::corefine_and_compute_intersection(sa, sb, so);
      else ok = PMP::corefine_and_compute_difference(sa, sb, so);
    });
    if (ok) out = from_surface_mesh(so);
    return ok;
  });
}
