// geods collide: CollisionMesh (OBB, SAH, leaf size 2) of mesh_100k, shared by
// A and B, one query per pose.
#include <memory>

#include "collide_driver.hpp"
#include "geods/collide/collide.hpp"

int main(int argc, char** argv) {
  using namespace geods;
  return collide_bench::run(
      argc, argv, "geods",
      [](const collide_bench::Workload& w) {
        TriMesh m;
        for (std::size_t i = 0; i < w.mesh.vertices(); ++i)
          m.vertices.emplace_back(w.mesh.xyz[3 * i], w.mesh.xyz[3 * i + 1], w.mesh.xyz[3 * i + 2]);
        for (std::size_t i = 0; i < w.mesh.triangles(); ++i)
          m.triangles.push_back({std::uint32_t(w.mesh.tris[3 * i]), std::uint32_t(w.mesh.tris[3 * i + 1]),
                                 std::uint32_t(w.mesh.tris[3 * i + 2])});
        return std::make_shared<collide::CollisionMesh>(m);
      },
      [](const std::shared_ptr<collide::CollisionMesh>& m, const std::string& variant,
         const collide_bench::Workload& w, std::size_t i) {
        const collide::Posed pose = collide::Posed::from_row(&w.poses[7 * i]);
        collide_bench::PoseResult r;
        if (variant == "distance") {
          const auto d = collide::distance(*m, collide::Posed{}, *m, pose);
          r.distance = d.distance;
          r.colliding = d.distance == 0;
        } else {
          const auto c = collide::collide(*m, collide::Posed{}, *m, pose,
                                          {variant == "all" ? collide::CollideMode::all : collide::CollideMode::first});
          r.colliding = c.colliding;
          r.pairs = c.pairs.size();
        }
        return r;
      });
}
