// CGAL Nef_polyhedron_3 (Epeck, exact): both inputs to Nef polyhedra (build_s), the boolean
// and the conversion back to a triangulated Surface_mesh (query_s); csg_driver.hpp.
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Nef_polyhedron_3.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/convert_nef_polyhedron_to_polygon_mesh.h>

#include "csg_driver.hpp"

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;
using Nef = CGAL::Nef_polyhedron_3<K>;

namespace {

SM to_sm(const csg_bench::Mesh& m) {
  SM s;
  std::vector<SM::Vertex_index> v;
  for (std::size_t i = 0; i < m.vertices(); ++i) v.push_back(s.add_vertex(K::Point_3(m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2])));
  for (const auto& t : m.tri)
    if (s.add_face(v[t[0]], v[t[1]], v[t[2]]) == SM::null_face()) throw std::runtime_error("not a manifold input");
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace csg_bench;
  return run(argc, argv, "nef", [](const Mesh& a, const Mesh& b, Op op, Mesh& out, double& build_s, double& query_s) {
    std::unique_ptr<Nef> na, nb;
    build_s = compare::time_s([&] {
      SM sa = to_sm(a), sb = to_sm(b);
      na = std::make_unique<Nef>(sa);
      nb = std::make_unique<Nef>(sb);
    });
    SM so;
    query_s = compare::time_s([&] {
      const Nef r = op == Op::union_ ? *na + *nb : op == Op::intersection ? *na * *nb : *na - *nb;
      CGAL::convert_nef_polyhedron_to_polygon_mesh(r, so, true);
    });
    std::vector<std::uint32_t> id(so.number_of_vertices() + so.number_of_removed_vertices(), 0);
    std::uint32_t n = 0;
    for (auto v : so.vertices()) {
      const auto& p = so.point(v);
      out.xyz.insert(out.xyz.end(), {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
      id[v.idx()] = n++;
    }
    for (auto f : so.faces()) {
      std::array<std::uint32_t, 3> t{};
      int k = 0;
      for (auto v : CGAL::vertices_around_face(so.halfedge(f), so))
        if (k < 3) t[k++] = id[v.idx()];
      out.tri.push_back(t);
    }
    return true;
  });
}
