// geods::iso on the mc comparison: the exhaustive scan (iso::isosurface), or with
// GEODS_COMPARE_OCTREE the min/max octree (built once, build_s) queried per iso-value with its
// default vertex sharing (VertexSharing::block_masks).
#include <memory>

#include "geods/iso/marching_cubes.hpp"
#include "geods/iso/min_max_octree.hpp"
#include "mc_driver.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  geods::Grid3<float> volume;
  volume.dims = {compare::mc::kSide, compare::mc::kSide, compare::mc::kSide};
  volume.data = compare::mc::load_volume(args);
  geods::iso::IsoOptions options;
  options.normals = false;
#ifdef GEODS_COMPARE_OCTREE
  std::unique_ptr<geods::iso::MinMaxOctree<float>> tree;
  return compare::mc::run(
      argc, argv, "geods-octree",
      [&] {
        compare::ThreadLimit limit(args.threads);
        // The octree takes the samples (as the CLI, Python and the demo give them: moved, no copy).
        return compare::time_s([&] { tree = std::make_unique<geods::iso::MinMaxOctree<float>>(std::move(volume)); });
      },
      [&](double iso) {
        const geods::iso::OctreeIsoResult r = tree->isosurface(iso, options, geods::iso::VertexSharing::block_masks);
        return compare::mc::Extracted{r.mesh.num_vertices(), r.mesh.num_triangles(), r.cells_visited};
      });
#else
  return compare::mc::run(
      argc, argv, "geods", [] { return 0.0; },
      [&](double iso) {
        const geods::TriMesh mesh = geods::iso::isosurface(volume, iso, options);
        return compare::mc::Extracted{mesh.num_vertices(), mesh.num_triangles(), 0};
      });
#endif
}
