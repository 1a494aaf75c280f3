// FLANN 1.9's KDTreeSingleIndex (L2_Simple<float>, leaf size 10, its default reorder = true: the
// points copied in leaf order, like geods' tree_order) on the knn comparison inputs, queried one
// point at a time through findNeighbors with FLANN's own result sets (its knnSearch and
// radiusSearch do the same per row). Header-only use; the bench program alone includes it.
#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/matrix.h>
#include <flann/util/result_set.h>

#include "knn_driver.hpp"

namespace {

struct Flann {
  static constexpr const char* anchor = "flann";
  using Tree = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;
  struct Index {
    Tree tree;
    Index(const float* points, std::size_t n, std::size_t leaf_size)
        : tree(flann::Matrix<float>(const_cast<float*>(points), n, 3), flann::KDTreeSingleIndexParams(int(leaf_size))) {
      tree.buildIndex();
    }
  };
  static std::unique_ptr<Index> build(const float* points, std::size_t n, std::size_t leaf_size) {
    return std::make_unique<Index>(points, n, leaf_size);
  }
  static void search(const Index& index, const float* q, std::size_t k, float eps, std::uint32_t* indices,
                     float* distances) {
    thread_local std::vector<std::size_t> ids;
    ids.resize(k);
    flann::KNNSimpleResultSet<float> result(k);
    index.tree.findNeighbors(result, q, flann::SearchParams(flann::FLANN_CHECKS_UNLIMITED, eps));
    result.copy(ids.data(), distances, k, true);
    for (std::size_t i = 0; i < k; ++i) indices[i] = std::uint32_t(ids[i]);
  }
  static void knn(const Index& index, const float* q, std::size_t k, std::uint32_t* indices, float* distances) {
    search(index, q, k, 0.0f, indices, distances);
  }
  static void knn_eps(const Index& index, const float* q, std::size_t k, float eps, std::uint32_t* indices,
                      float* distances) {
    search(index, q, k, eps, indices, distances);
  }
  // RadiusResultSet (L2_Simple: the squared radius), copied out sorted by distance.
  static void radius(const Index& index, const float* q, float squared_radius, std::vector<std::uint32_t>& out) {
    thread_local std::vector<std::size_t> ids;
    thread_local std::vector<float> dists;
    flann::RadiusResultSet<float> result(squared_radius);
    index.tree.findNeighbors(result, q, flann::SearchParams(flann::FLANN_CHECKS_UNLIMITED));
    const std::size_t count = result.size();
    ids.resize(count);
    dists.resize(count);
    result.copy(ids.data(), dists.data(), count, true);
    for (std::size_t i = 0; i < count; ++i) out.push_back(std::uint32_t(ids[i]));
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::knn::run<Flann>(argc, argv); }
