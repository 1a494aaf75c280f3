// geods::bvh::TriangleBvh (binned SAH, AABB, 4 wide: the defaults) on the ray comparison.
#include "geods/bvh/triangle_bvh.hpp"
#include "ray_driver.hpp"

namespace {

struct Geods {
  static constexpr const char* anchor = "geods";
  using Index = geods::bvh::TriangleBvh;
  static std::unique_ptr<Index> build(const compare::PlyMesh& ply) {
    // The TriMesh is the input, as a PLY reader would give it; copying it is part of the build.
    static thread_local geods::TriMesh mesh;
    if (mesh.num_triangles() != ply.triangles()) {
      mesh.vertices.resize(ply.vertices());
      for (std::size_t i = 0; i < ply.vertices(); ++i)
        mesh.vertices[i] = {ply.xyz[3 * i], ply.xyz[3 * i + 1], ply.xyz[3 * i + 2]};
      mesh.triangles.resize(ply.triangles());
      for (std::size_t i = 0; i < ply.triangles(); ++i)
        mesh.triangles[i] = {std::uint32_t(ply.tris[3 * i]), std::uint32_t(ply.tris[3 * i + 1]),
                             std::uint32_t(ply.tris[3 * i + 2])};
    }
    return std::make_unique<Index>(Index::build(mesh));
  }
  static compare::ray::Hit intersect(const Index& bvh, const float* r) {
    geods::Ray3f ray;
    ray.origin = {r[0], r[1], r[2]};
    ray.direction = {r[3], r[4], r[5]};
    const geods::RayHit hit = bvh.intersect(ray);
    return {hit.t, hit.prim};
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::ray::run<Geods>(argc, argv); }
