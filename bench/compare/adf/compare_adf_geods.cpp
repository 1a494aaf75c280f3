// geods::field::Adf on mesh_100k against the dense grid of the sdf workload (128^3, voxel
// 0.0172): the dense grid's trilinear interpolation error is measured at random points (half
// uniform in the grid's box, half within 8 voxels of the surface) against MeshDistance; the ADF
// is built with that error as E over a root cube of the same box and its own error measured the
// same way (measure_adf_error). Reported: bytes of both, their ratio, both max errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_set>

#include "../sdf/sdf_driver.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/adf.hpp"
#include "geods/field/sdf_grid.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  const compare::ThreadLimit limit(args.threads);
  if (!args.wants("mesh_100k")) return 0;
  const compare::sdf::Workload w = compare::sdf::load(args);
  geods::TriMesh mesh;
  for (std::size_t v = 0; v < w.mesh.vertices(); ++v)
    mesh.vertices.emplace_back(w.mesh.xyz[3 * v], w.mesh.xyz[3 * v + 1], w.mesh.xyz[3 * v + 2]);
  for (std::size_t t = 0; t < w.mesh.triangles(); ++t)
    mesh.triangles.push_back({std::uint32_t(w.mesh.tris[3 * t]), std::uint32_t(w.mesh.tris[3 * t + 1]),
                              std::uint32_t(w.mesh.tris[3 * t + 2])});
  const geods::field::MeshDistance md = geods::field::MeshDistance::build(mesh);
  geods::Grid3Geometry grid;
  grid.dims = {w.n, w.n, w.n};
  grid.origin = geods::Vec3f(float(w.origin[0]), float(w.origin[1]), float(w.origin[2]));
  grid.spacing = geods::Vec3f::Constant(float(w.voxel));
  const geods::field::SdfGrid dense = geods::field::sdf_grid(md, grid);

  // The dense grid's error at random points of its box.
  geods::Rng rng(1);
  const double side = w.voxel * double(w.n - 1);
  double dense_error = 0;
  for (int s = 0; s < 20000; ++s) {
    geods::Vec3d p;
    if (s % 2 == 0) {
      p = geods::Vec3d(rng.uniform(), rng.uniform(), rng.uniform()) * side;
    } else {
      const auto& t = mesh.triangles[rng.below(mesh.num_triangles())];
      double a = rng.uniform(), b = rng.uniform();
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const geods::Vec3d v0 = mesh.vertices[t[0]].cast<double>(), v1 = mesh.vertices[t[1]].cast<double>(),
                         v2 = mesh.vertices[t[2]].cast<double>();
      geods::Vec3d dir(rng.normal(), rng.normal(), rng.normal());
      dir.normalize();
      p = v0 + a * (v1 - v0) + b * (v2 - v0) + dir * rng.uniform(0, 8 * w.voxel) - grid.origin.cast<double>();
      p = p.cwiseMax(0.0).cwiseMin(side);
    }
    const geods::Vec3d u = p / w.voxel;
    std::size_t i[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      i[a] = std::min<std::size_t>(std::size_t(u[a]), w.n - 2);
      f[a] = u[a] - double(i[a]);
    }
    double interp = 0;
    for (int c = 0; c < 8; ++c)
      interp += dense.distance(i[0] + (c & 1), i[1] + (c >> 1 & 1), i[2] + (c >> 2 & 1)) * (c & 1 ? f[0] : 1 - f[0]) *
                (c & 2 ? f[1] : 1 - f[1]) * (c & 4 ? f[2] : 1 - f[2]);
    const geods::Vec3f q = (p + grid.origin.cast<double>()).cast<float>();
    dense_error = std::max(dense_error, std::abs(interp - double(md.query(q).distance)));
  }

  geods::field::AdfOptions options;
  options.error = dense_error;
  // The root cube: the grid's box (1.1 x the mesh's extent less a voxel).
  const double extent = mesh.bounds().extent().cast<double>().maxCoeff();
  options.padding = (side / extent - 1) / 2;
  geods::field::Adf adf;
  const double s = compare::median_time_s(1, [&] { adf = geods::field::Adf::build(mesh, md, options); });
  const geods::field::AdfError e = geods::field::measure_adf_error(adf, mesh, md, 20000);
  const geods::field::AdfStats st = adf.stats();
  const std::size_t dense_bytes = dense.distance.size() * sizeof(float);
  // How small can any octree of trilinear cells with exact corner samples be at this E? The
  // top-down tree is the smallest whose leaves all pass the test (a cell it splits fails the
  // test, so every such tree splits it too): at least st.leaves leaves. Stored as 8 floats a
  // leaf, that is 32 bytes a leaf whatever the tree encoding: float_corner_bound = dense bytes /
  // (32 leaves) bounds the ratio of that representation. Storing each distinct corner once
  // (leaves share corners) at 16 bits (the field's range in 65,535 steps, error quant16_error)
  // with one bit of tree structure a cell needs at least 2 bytes a distinct corner + cells / 8
  // bytes (without the means for a leaf to find its corners): shared16_ratio bounds that one.
  std::unordered_set<std::uint64_t> corners;
  std::size_t finest_leaves = 0;
  double lo_value = 0, hi_value = 0;
  const double finest = adf.size() / double(std::uint64_t(1) << st.depth);
  adf.for_each_leaf([&](int level, const geods::Vec3d& lo, double size, const float* c) {
    finest_leaves += std::size_t(level) == st.depth;
    const std::int64_t step = std::int64_t(std::llround(size / finest));
    std::int64_t base[3];
    for (int a = 0; a < 3; ++a) base[a] = std::llround((lo[a] - adf.origin()[a]) / finest);
    for (int k = 0; k < 8; ++k) {
      corners.insert(std::uint64_t(base[0] + (k & 1) * step) | std::uint64_t(base[1] + (k >> 1 & 1) * step) << 21 |
                     std::uint64_t(base[2] + (k >> 2 & 1) * step) << 42);
      lo_value = std::min(lo_value, double(c[k])), hi_value = std::max(hi_value, double(c[k]));
    }
  });
  const double float_corner_bytes = 32.0 * double(st.leaves);
  const double shared16_bytes = 2.0 * double(corners.size()) + double(st.cells) / 8;
  compare::Record("adf", "geods", "mesh_100k", args.threads)
      .timing(0, s, st.leaves, 1)
      .set("error", dense_error)
      .set("cells", st.cells)
      .set("bytes", st.bytes)
      .set("dense_bytes", dense_bytes)
      .set("ratio", double(dense_bytes) / double(st.bytes))
      .set("dense_max_error", dense_error)
      .set("max_error", e.max_error)
      .set("leaves", st.leaves)
      .set("depth", st.depth)
      .set("finest_leaves", finest_leaves)
      .set("distinct_corners", corners.size())
      .set("float_corner_bound", double(dense_bytes) / float_corner_bytes)
      .set("shared16_ratio", double(dense_bytes) / shared16_bytes)
      .set("quant16_error", (hi_value - lo_value) / 65535 / 2)
      .print(e.max_error <= 1.5 * dense_error);
  return 0;
}
