// libFuzzer target: the input loaded as each structure that saves to a geods
// archive (k-d tree, quadtree/octree, min/max octree), then queried. The
// checksums are skipped (Archive::Verify::structure_only) so that mutated
// payloads reach the structures' own checks: whatever loads must answer
// queries without crashing.
#include <array>
#include <vector>

#include "fuzz_common.hpp"
#include "geods/iso/min_max_octree.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/spatial/quadtree.hpp"

namespace {

constexpr auto kStructureOnly = geods::Archive::Verify::structure_only;

template <typename Tree>
void query_kd_tree(const std::filesystem::path& p) {
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
void query_orthtree(const std::filesystem::path& p) {
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
void query_min_max_octree(const std::filesystem::path& p) {
  const geods::iso::MinMaxOctree<T> tree = geods::iso::MinMaxOctree<T>::load(p, kStructureOnly);
  for (double iso : {0.5, 13.0})
    for (auto sharing : {geods::iso::VertexSharing::block_masks, geods::iso::VertexSharing::hash_table})
      tree.isosurface(iso, {}, sharing);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace geods::spatial;
  return geods::fuzz::read_as(data, size, "in.geods", [](const auto& p) {
    for (auto load : {query_kd_tree<KdTree<float, 2>>, query_kd_tree<KdTree<double, 2>>,
                      query_kd_tree<KdTree<double, Dynamic>>, query_orthtree<Quadtree<double>>,
                      query_orthtree<Octree<float>>, query_min_max_octree<std::uint8_t>, query_min_max_octree<float>}) {
      try {
        load(p);
      } catch (const geods::Error&) {
      }
    }
  });
}
