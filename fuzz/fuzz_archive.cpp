// libFuzzer target: the input loaded as each structure that saves to a geods
// archive (k-d tree, quadtree/octree, min/max octree, TriangleBvh, the ray
// accelerators, Delaunay2, Voronoi2, the dynamic k-d tree, the shape database), then queried.
// Where a load can skip the checksums (Archive::Verify::structure_only) it is
// also tried that way, so that mutated payloads reach the structures' own
// checks: whatever loads must answer queries without crashing.
#include <array>
#include <span>
#include <vector>

#include "fuzz_common.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/archive.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"
#include "geods/iso/min_max_octree.hpp"
#include "geods/ray/accelerator.hpp"
#include "geods/shape/shape_database.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/spatial/quadtree.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace {

using geods::Vec2d;
using geods::Vec3f;
using Path = std::filesystem::path;
constexpr auto kStructureOnly = geods::Archive::Verify::structure_only;

template <typename Tree>
void query_kd_tree(const Path& p) {
  const Tree tree = Tree::load(p, kStructureOnly);
  using T = typename Tree::Scalar;
  const std::vector<T> q(tree.dim(), T(0.5)), lo(tree.dim(), T(0)), hi(tree.dim(), T(1));
  tree.query(q, 3);
  tree.query(q, 2, 0.5);
  tree.query_radius(q, 0.75);
  tree.count_box(lo, hi);
  tree.query_box(lo, hi);
}

template <typename Tree>
void query_orthtree(const Path& p) {
  const Tree tree = Tree::load(p, kStructureOnly);
  const typename Tree::VecT q = Tree::VecT::Constant(0.5), lo = Tree::VecT::Zero(), hi = Tree::VecT::Ones();
  tree.query(q, 3);
  tree.query_radius(q, 0.75);
  tree.query_box(lo, hi);
  tree.locate(q);
  for (std::uint32_t v = 0; v < tree.nodes().size() && v < 64; ++v)
    for (int d = 0; d < 2 * Tree::kDim; ++d) tree.neighbor(v, geods::spatial::Direction(d));
  if (tree.nodes().size() < 4096) tree.balanced();
}

template <typename T>
void query_min_max_octree(const Path& p) {
  const geods::iso::MinMaxOctree<T> tree = geods::iso::MinMaxOctree<T>::load(p, kStructureOnly);
  for (double iso : {0.5, 13.0})
    for (auto sharing : {geods::iso::VertexSharing::block_masks, geods::iso::VertexSharing::hash_table})
      tree.isosurface(iso, {}, sharing);
  // The scan over the mapped samples in place.
  geods::iso::isosurface(tree.volume(), 0.5);
}

geods::Ray3f probe_ray() {
  geods::Ray3f ray;
  ray.origin = Vec3f(0.1f, 0.2f, -5.0f);
  ray.direction = Vec3f(0.01f, 0.02f, 1.0f);
  return ray;
}

void query(const geods::bvh::TriangleBvh& bvh) {
  bvh.intersect(probe_ray());
  bvh.occluded(probe_ray());
  bvh.closest_point(Vec3f(0.3f, 0.1f, 0.2f));
  bvh.contains(Vec3f(0.3f, 0.1f, 0.2f));
  bvh.cull_box(geods::AABB3f(Vec3f(-1, -1, -1), Vec3f(1, 1, 1)));
}

// Through the structure checks only (checksums skipped, so mutations reach validate()).
void query_bvh_structure(const Path& p) {
  using geods::bvh::TriangleBvh;
  query(TriangleBvh::from_sections(
      geods::Archive::open(p, TriangleBvh::kArchiveKind, TriangleBvh::kArchiveVersion, kStructureOnly)));
}

void query_bvh(const Path& p) { query(geods::bvh::TriangleBvh::load(p)); }

void query_accelerator(const Path& p) {
  const auto accel = geods::ray::load_accelerator(p);
  accel->intersect(probe_ray());
  accel->occluded(probe_ray());
}

void query_delaunay2(const Path& p) {
  const geods::voronoi::Delaunay2 dt = geods::voronoi::Delaunay2::load(p);
  dt.locate(Vec2d(0.25, 0.25));
  dt.nearest(Vec2d(0.25, 0.25));
}

void query_voronoi2(const Path& p) {
  const geods::voronoi::Voronoi2 diagram = geods::voronoi::Voronoi2::load(p);
  diagram.cell_polygons(geods::AABB2d(Vec2d(-1, -1), Vec2d(2, 2)));
}

template <typename Tree>
void query_dynamic_kd_tree(const Path& p) {
  const Tree tree = Tree::load(p);
  const std::array<double, 2> q{0.5, 0.5};
  tree.query(std::span<const double>(q), 3);
}

void query_shape_database(const Path& p) {
  const geods::shape::ShapeDatabase db = geods::shape::ShapeDatabase::load(p);
  const std::vector<float> q(db.dimension(), 0.5f);
  db.query_descriptor(q, 3);
  db.query_descriptor(q, 2, 0.5);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace geods::spatial;
  return geods::fuzz::read_as(data, size, "in.geods", [](const Path& p) {
    for (auto load : {query_kd_tree<KdTree<float, 2>>, query_kd_tree<KdTree<double, 2>>,
                      query_kd_tree<KdTree<double, Dynamic>>, query_orthtree<Quadtree<double>>,
                      query_orthtree<Octree<float>>, query_min_max_octree<std::uint8_t>, query_min_max_octree<float>,
                      query_bvh_structure, query_bvh, query_accelerator, query_delaunay2, query_voronoi2,
                      query_dynamic_kd_tree<geods::dynamic::DynamicKdTree<double, 2>>, query_shape_database}) {
      try {
        load(p);
      } catch (const geods::Error&) {
      }
    }
  });
}
