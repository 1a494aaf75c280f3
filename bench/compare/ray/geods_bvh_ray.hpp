#pragma once
// geods::bvh::TriangleBvh (binned SAH, AABB: the defaults; 8 wide, as the ray module's
// accelerator builds it) as a library of the ray comparison (ray_driver.hpp).
#include <memory>

#include "geods/bvh/triangle_bvh.hpp"
#include "geods_mesh.hpp"
#include "ray_driver.hpp"

namespace compare::ray {

struct Geods {
  static constexpr const char* anchor = "geods";
  using Index = geods::bvh::TriangleBvh;
  static std::unique_ptr<Index> build(const PlyMesh& ply) {
    const geods::TriMesh& mesh = geods_mesh(ply);
    geods::bvh::BuildOptions options;
    options.arity = 8;
    return std::make_unique<Index>(Index::build(mesh, options));
  }
  static Hit intersect(const Index& bvh, const float* r) {
    geods::Ray3f ray;
    ray.origin = {r[0], r[1], r[2]};
    ray.direction = {r[3], r[4], r[5]};
    const geods::RayHit hit = bvh.intersect(ray);
    return {hit.t, hit.prim};
  }
  static bool occluded(const Index& bvh, const float* r) {
    geods::Ray3f ray;
    ray.origin = {r[0], r[1], r[2]};
    ray.direction = {r[3], r[4], r[5]};
    return bvh.occluded(ray);
  }
};

}  // namespace compare::ray
