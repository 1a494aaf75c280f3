// geods::spatial::KdTree<float, 3> on the knn comparison inputs. compare_knn_geods opts in to
// store_points_in_tree_order() (a copy of the points in leaf order, made inside build_s);
// compare_knn_geods_zerocopy (GEODS_COMPARE_ZERO_COPY) is the default: zero-copy over the points.
#include "geods/spatial/kd_tree.hpp"
#include "knn_driver.hpp"

namespace {

struct Geods {
#ifdef GEODS_COMPARE_ZERO_COPY
  static constexpr const char* anchor = "geods-zero-copy";
#else
  static constexpr const char* anchor = "geods";
#endif
  using Index = geods::spatial::KdTree<float, 3>;
  static std::unique_ptr<Index> build(const float* points, std::size_t n, std::size_t leaf_size) {
    auto tree = std::make_unique<Index>(geods::spatial::PointView<float>(points, n, 3), leaf_size);
#ifndef GEODS_COMPARE_ZERO_COPY
    tree->store_points_in_tree_order();
#endif
    return tree;
  }
  static void knn(const Index& tree, const float* q, std::size_t k, std::uint32_t* indices, float* distances) {
    thread_local std::vector<geods::spatial::Neighbor<float>> out;  // allocated once per thread
    out.resize(k);
    tree.query_into(std::span<const float>(q, 3), geods::spatial::KnnRequest{k}, out.data());
    for (std::size_t i = 0; i < k; ++i) indices[i] = out[i].index, distances[i] = out[i].squared_distance;
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::knn::run<Geods>(argc, argv); }
