// CGAL Polygon_mesh_processing::corefine_and_compute_union / difference / intersection on
// Surface_mesh (kernel Epick, or Epeck with -DCSG_EPECK), csg_driver.hpp.
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Surface_mesh.h>

#include "csg_driver.hpp"

#ifdef CSG_EPECK
using K = CGAL::Exact_predicates_exact_constructions_kernel;
constexpr const char* kAnchor = "cgal_epeck";
#else
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
constexpr const char* kAnchor = "cgal";
#endif
using SM = CGAL::Surface_mesh<K::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

SM to_sm(const csg_bench::Mesh& m) {
  SM s;
  std::vector<SM::Vertex_index> v;
  v.reserve(m.vertices());
  for (std::size_t i = 0; i < m.vertices(); ++i) v.push_back(s.add_vertex(K::Point_3(m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2])));
  for (const auto& t : m.tri)
    if (s.add_face(v[t[0]], v[t[1]], v[t[2]]) == SM::null_face()) throw std::runtime_error("not a manifold input");
  return s;
}

csg_bench::Mesh from_sm(const SM& s) {
  csg_bench::Mesh m;
  std::vector<std::uint32_t> id(s.number_of_vertices() + s.number_of_removed_vertices(), 0);
  std::uint32_t n = 0;
  for (auto v : s.vertices()) {
    const auto& p = s.point(v);
    m.xyz.insert(m.xyz.end(), {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
    id[v.idx()] = n++;
  }
  for (auto f : s.faces()) {
    std::array<std::uint32_t, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(s.halfedge(f), s))
      if (k < 3) t[k++] = id[v.idx()];
    m.tri.push_back(t);
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace csg_bench;
  return run(argc, argv, kAnchor, [](const Mesh& a, const Mesh& b, Op op, Mesh& out, double& build_s, double& query_s) {
    SM sa, sb, so;
    build_s = compare::time_s([&] { sa = to_sm(a), sb = to_sm(b); });
    bool ok = false;
    query_s = compare::time_s([&] {
      if (op == Op::union_) ok = PMP::corefine_and_compute_union(sa, sb, so);
      else if (op == Op::intersection) ok = PMP::corefine_and_compute_intersection(sa, sb, so);
      else ok = PMP::corefine_and_compute_difference(sa, sb, so);
    });
    if (ok) out = from_sm(so);
    return ok;
  });
}
