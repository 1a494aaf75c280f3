#pragma once
// csg_driver.hpp meshes to and from CGAL Surface_mesh (the CGAL programs of this folder).
#include <CGAL/Surface_mesh.h>

#include <stdexcept>

#include "csg_driver.hpp"

namespace csg_bench {

template <class SM>
SM to_surface_mesh(const Mesh& m) {
  using Point = typename SM::Point;
  SM s;
  std::vector<typename SM::Vertex_index> v;
  v.reserve(m.vertices());
  for (std::size_t i = 0; i < m.vertices(); ++i) v.push_back(s.add_vertex(Point(m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2])));
  for (const auto& t : m.tri)
    if (s.add_face(v[t[0]], v[t[1]], v[t[2]]) == SM::null_face()) throw std::runtime_error("not a manifold input");
  return s;
}

/// The triangles of a Surface_mesh (the first three corners of each face).
template <class SM>
Mesh from_surface_mesh(const SM& s) {
  Mesh m;
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

}  // namespace csg_bench
