// nanoflann 1.4's KDTreeSingleIndexDynamicAdaptor (a logarithmic method over static
// KDTreeSingleIndexAdaptor_ indices, leaf size 10) on the dynamic comparison schedule.
// Its deletion is lazy: removePoint only flags the index (queries skip it); the point stays in
// its tree and memory is never reclaimed, so delete_s is not comparable with a real deletion.
#include <nanoflann.hpp>

#include "dynamic_driver.hpp"
#include "nanoflann_cloud.hpp"

namespace {

struct Nanoflann {
  static constexpr const char* anchor = "nanoflann";
  static constexpr bool single_insert = true;
  using Tree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3,
                                                          std::uint32_t>;
  struct State {
    Cloud cloud;
    Tree tree;
    State(const float* all_points, std::size_t total)
        : cloud{all_points, 0}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10), total) {}
    void insert(std::size_t first, std::size_t count) {
      tree.addPoints(static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(first + count - 1));
    }
    void remove(const std::uint32_t* ids, std::size_t count) {
      for (std::size_t i = 0; i < count; ++i) tree.removePoint(ids[i]);
    }
    void prepare() {}
    void knn(const float* q, std::size_t k, std::uint32_t* ids, float* distances) const {
      nanoflann::KNNResultSet<float, std::uint32_t> result(k);
      result.init(ids, distances);
      tree.findNeighbors(result, q, nanoflann::SearchParams());
    }
  };
};

}  // namespace

int main(int argc, char** argv) { return compare::dynamic::run<Nanoflann>(argc, argv); }
