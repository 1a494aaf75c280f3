// CGAL 5.5 on the sdf comparison: AABB_tree over the faces of a Surface_mesh (distance queries
// accelerated, build_s) and Side_of_triangle_mesh for the sign, one sample at a time. The
// whole grid only (CGAL has no narrow band), single-threaded (the queries are sequential
// calls), one repetition (it takes about a minute).
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <memory>

#include "sdf_driver.hpp"

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

int main(int argc, char** argv) {
  Mesh mesh;
  std::unique_ptr<Tree> tree;
  std::unique_ptr<CGAL::Side_of_triangle_mesh<Mesh, K>> side;
  compare::sdf::Workload work;
  std::vector<float> values;
  return compare::sdf::run(
      argc, argv, "cgal",
      [&](const compare::sdf::Workload& w, const compare::Args&) {
        work = w;
        std::vector<Mesh::Vertex_index> vs;
        for (std::size_t v = 0; v < w.mesh.vertices(); ++v)
          vs.push_back(mesh.add_vertex(K::Point_3(w.mesh.xyz[3 * v], w.mesh.xyz[3 * v + 1], w.mesh.xyz[3 * v + 2])));
        for (std::size_t t = 0; t < w.mesh.triangles(); ++t)
          if (mesh.add_face(vs[w.mesh.tris[3 * t]], vs[w.mesh.tris[3 * t + 1]], vs[w.mesh.tris[3 * t + 2]]) ==
              Mesh::null_face())
            compare::die("mesh_100k: CGAL refused face " + std::to_string(t));
        return compare::time_s([&] {
          tree = std::make_unique<Tree>(faces(mesh).first, faces(mesh).second, mesh);
          tree->accelerate_distance_queries();
          side = std::make_unique<CGAL::Side_of_triangle_mesh<Mesh, K>>(mesh);
        });
      },
      [&](const compare::sdf::Variant&) {
        const std::size_t n = work.n;
        values.assign(n * n * n, 0.0f);
        for (std::size_t k = 0; k < n; ++k)
          for (std::size_t j = 0; j < n; ++j)
            for (std::size_t i = 0; i < n; ++i) {
              const auto p = work.position(i, j, k);
              const K::Point_3 q(p[0], p[1], p[2]);
              const double d = std::sqrt(tree->squared_distance(q));
              values[i + n * (j + n * k)] = float((*side)(q) == CGAL::ON_BOUNDED_SIDE ? -d : d);
            }
      },
      [&](std::size_t i, std::size_t j, std::size_t k) { return values[i + work.n * (j + work.n * k)]; },
      /*narrow_band=*/false, /*max_reps=*/1);
}
