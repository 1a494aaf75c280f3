// OpenVDB 10 on the sdf comparison: tools::meshToSignedDistanceField over the world-space
// mesh with a transform whose voxel (i, j, k) sits at origin + (i, j, k) * voxel. "band 3":
// exterior and interior bands of 3 voxels (its sign elsewhere by its own flood fill); "whole":
// bands of 80 voxels outside and 40 inside, wider than the grid's farthest samples (75.8 and
// 31.2 voxels), so every sample gets a distance. Threads: TBB (global_control).
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include "sdf_driver.hpp"

int main(int argc, char** argv) {
  openvdb::initialize();
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  openvdb::math::Transform::Ptr xform;
  openvdb::FloatGrid::Ptr grid;
  return compare::sdf::run(
      argc, argv, "openvdb",
      [&](const compare::sdf::Workload& w, const compare::Args&) {
        for (std::size_t v = 0; v < w.mesh.vertices(); ++v)
          points.emplace_back(w.mesh.xyz[3 * v], w.mesh.xyz[3 * v + 1], w.mesh.xyz[3 * v + 2]);
        for (std::size_t t = 0; t < w.mesh.triangles(); ++t)
          triangles.emplace_back(w.mesh.tris[3 * t], w.mesh.tris[3 * t + 1], w.mesh.tris[3 * t + 2]);
        xform = openvdb::math::Transform::createLinearTransform(w.voxel);
        xform->postTranslate(openvdb::Vec3d(w.origin[0], w.origin[1], w.origin[2]));
        return 0.0;
      },
      [&](const compare::sdf::Variant& v) {
        const bool whole = !std::isfinite(v.band);
        const std::vector<openvdb::Vec4I> quads;
        grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
            *xform, points, triangles, quads, whole ? 80.0f : float(v.band), whole ? 40.0f : float(v.band));
      },
      [&](std::size_t i, std::size_t j, std::size_t k) {
        return grid->tree().getValue(openvdb::Coord(int(i), int(j), int(k)));
      });
}
