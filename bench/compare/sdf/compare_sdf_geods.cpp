// geods::field::sdf_grid on the sdf workload (see sdf_driver.hpp): MeshDistance built once
// (build_s: the hierarchy, pseudonormals, winding-number moments), then the grid, exact on
// every sample ("whole") or in a band of 3 voxels, signed by winding numbers.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "geods/field/sdf_grid.hpp"
#include "sdf_driver.hpp"

int main(int argc, char** argv) {
  std::optional<geods::field::MeshDistance> md;
  geods::TriMesh mesh;
  geods::Grid3Geometry grid;
  geods::field::SdfGrid field;
  return compare::sdf::run(
      argc, argv, "geods",
      [&](const compare::sdf::Workload& w, const compare::Args& args) {
        for (std::size_t v = 0; v < w.mesh.vertices(); ++v)
          mesh.vertices.emplace_back(w.mesh.xyz[3 * v], w.mesh.xyz[3 * v + 1], w.mesh.xyz[3 * v + 2]);
        for (std::size_t t = 0; t < w.mesh.triangles(); ++t)
          mesh.triangles.push_back({std::uint32_t(w.mesh.tris[3 * t]), std::uint32_t(w.mesh.tris[3 * t + 1]),
                                    std::uint32_t(w.mesh.tris[3 * t + 2])});
        grid.dims = {w.n, w.n, w.n};
        grid.origin = geods::Vec3f(float(w.origin[0]), float(w.origin[1]), float(w.origin[2]));
        grid.spacing = geods::Vec3f::Constant(float(w.voxel));
        return compare::median_time_s(args.reps, [&] { md = geods::field::MeshDistance::build(mesh); });
      },
      [&](const compare::sdf::Variant& v) {
        geods::field::SdfGridOptions options;
        options.band = v.band;
        field = geods::field::sdf_grid(*md, grid, options);
        if (std::getenv("GEODS_SDF_HASH")) {  // the grid's bits (FNV-1a), to check that a change keeps them
          std::uint64_t h = 1469598103934665603ull;
          for (const float d : field.distance.data) {
            std::uint32_t b;
            std::memcpy(&b, &d, 4);
            h = (h ^ b) * 1099511628211ull;
          }
          std::fprintf(stderr, "%s grid hash %016llx\n", v.name.c_str(), (unsigned long long)h);
        }
      },
      [&](std::size_t i, std::size_t j, std::size_t k) { return field.distance(i, j, k); });
}
