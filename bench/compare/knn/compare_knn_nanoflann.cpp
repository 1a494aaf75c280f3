// nanoflann's KDTreeSingleIndexAdaptor (L2, dimension 3 at compile time) on the knn comparison inputs.
#include <nanoflann.hpp>

#include "knn_driver.hpp"
#include "nanoflann_cloud.hpp"

namespace {

struct Nanoflann {
  static constexpr const char* anchor = "nanoflann";
  using Tree =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, std::uint32_t>;
  struct Index {
    Cloud cloud;
    Tree tree;
    Index(const float* points, std::size_t n, std::size_t leaf_size)
        : cloud{points, n}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(leaf_size)) {}
  };
  static std::unique_ptr<Index> build(const float* points, std::size_t n, std::size_t leaf_size) {
    return std::make_unique<Index>(points, n, leaf_size);  // the constructor builds the tree
  }
  static void knn(const Index& index, const float* q, std::size_t k, std::uint32_t* indices, float* distances) {
    nanoflann::KNNResultSet<float, std::uint32_t> result(k);
    result.init(indices, distances);
    index.tree.findNeighbors(result, q, nanoflann::SearchParams());
  }
  static void knn_eps(const Index& index, const float* q, std::size_t k, float eps, std::uint32_t* indices,
                      float* distances) {
    nanoflann::KNNResultSet<float, std::uint32_t> result(k);
    result.init(indices, distances);
    index.tree.findNeighbors(result, q, nanoflann::SearchParams(32, eps));
  }
  // radiusSearch (L2: the squared radius) into a reused vector, sorted by distance (SearchParams' default).
  static void radius(const Index& index, const float* q, float squared_radius, std::vector<std::uint32_t>& out) {
    thread_local std::vector<std::pair<std::uint32_t, float>> matches;
    matches.clear();
    index.tree.radiusSearch(q, squared_radius, matches, nanoflann::SearchParams());
    for (const auto& m : matches) out.push_back(m.first);
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::knn::run<Nanoflann>(argc, argv); }
