// CGAL Nef_polyhedron_3 (Epeck, exact): both inputs to Nef polyhedra (build_s), the boolean
// and the conversion back to a triangulated Surface_mesh (query_s); csg_driver.hpp.
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/convert_nef_polyhedron_to_polygon_mesh.h>

#include "csg_surface_mesh.hpp"

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;
using Nef = CGAL::Nef_polyhedron_3<K>;

int main(int argc, char** argv) {
  using namespace csg_bench;
  return run(argc, argv, "nef", [](const Mesh& a, const Mesh& b, Op op, Mesh& out, double& build_s, double& query_s) {
    std::unique_ptr<Nef> na, nb;
    build_s = compare::time_s([&] {
      SM sa = to_surface_mesh<SM>(a), sb = to_surface_mesh<SM>(b);
      na = std::make_unique<Nef>(sa);
      nb = std::make_unique<Nef>(sb);
    });
    SM so;
    query_s = compare::time_s([&] {
      const Nef r = op == Op::union_ ? *na + *nb : op == Op::intersection ? *na * *nb : *na - *nb;
      CGAL::convert_nef_polyhedron_to_polygon_mesh(r, so, true);
    });
    out = from_surface_mesh(so);
    return true;
  });
}
