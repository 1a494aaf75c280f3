// geods::spatial::KdTree<float, 3> on the knn comparison inputs. compare_knn_geods is the
// default layout, PointLayout::tree_order (a copy of the points in leaf order, made inside
// build_s); compare_knn_geods_zerocopy (GEODS_COMPARE_ZERO_COPY) is PointLayout::zero_copy.
#include <cmath>

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
#ifdef GEODS_COMPARE_ZERO_COPY
    constexpr auto layout = geods::spatial::PointLayout::zero_copy;
#else
    constexpr auto layout = geods::spatial::PointLayout::tree_order;
#endif
    return std::make_unique<Index>(geods::spatial::PointView<float>(points, n, 3), leaf_size, layout);
  }
  static void knn(const Index& tree, const float* q, std::size_t k, std::uint32_t* indices, float* distances) {
    thread_local std::vector<geods::spatial::Neighbor<float>> out;  // allocated once per thread
    out.resize(k);
    tree.query_into(std::span<const float>(q, 3), geods::spatial::KnnRequest{k}, out.data());
    for (std::size_t i = 0; i < k; ++i) indices[i] = out[i].index, distances[i] = out[i].squared_distance;
  }
  static void knn_eps(const Index& tree, const float* q, std::size_t k, float eps, std::uint32_t* indices,
                      float* distances) {
    thread_local std::vector<geods::spatial::Neighbor<float>> out;
    out.resize(k);
    tree.query_into(std::span<const float>(q, 3), geods::spatial::KnnRequest{k, eps}, out.data());
    for (std::size_t i = 0; i < k; ++i) indices[i] = out[i].index, distances[i] = out[i].squared_distance;
  }
  // search_radius into a reused vector, sorted by distance (query_radius without its allocation).
  // geods' radius is inclusive (d <= r^2), nanoflann's and FLANN's strict (d < r^2): the next float
  // below r^2 makes the sets the same.
  static void radius(const Index& tree, const float* q, float squared_radius, std::vector<std::uint32_t>& out) {
    thread_local std::vector<geods::spatial::Neighbor<float>> found;
    found.clear();
    tree.search_radius(q, std::nextafter(squared_radius, 0.0f),
                       [&](std::uint32_t i, float d) { found.push_back({i, d}); });
    std::sort(found.begin(), found.end());
    for (const auto& f : found) out.push_back(f.index);
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::knn::run<Geods>(argc, argv); }
