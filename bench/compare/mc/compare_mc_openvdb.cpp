// OpenVDB 10 on the mc comparison: tools::volumeToMesh (adaptivity 0) of a FloatGrid made from
// the dense volume before timing (tools::copyFromDense, tolerance 0: every voxel kept).
// Its quads count as two triangles. Threads: TBB (global_control).
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "mc_driver.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  openvdb::initialize();
  std::vector<float> volume = compare::mc::load_volume(args);
  const int n = int(compare::mc::kSide);
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
      openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)), volume.data());
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  openvdb::tools::copyFromDense(dense, *grid, 0.0f);
  return compare::mc::run(
      argc, argv, "openvdb", [] { return 0.0; },
      [&](double iso) {
        std::vector<openvdb::Vec3s> points;
        std::vector<openvdb::Vec3I> triangles;
        std::vector<openvdb::Vec4I> quads;
        openvdb::tools::volumeToMesh(*grid, points, triangles, quads, iso, 0.0);
        return compare::mc::Extracted{points.size(), triangles.size() + 2 * quads.size(), 0};
      });
}
