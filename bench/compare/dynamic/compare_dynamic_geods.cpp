// geods::dynamic::DynamicKdTree<float, 3> on the dynamic comparison schedule (dynamic_driver.hpp).
// Built twice: compare_dynamic_geods (amortized variant) and compare_dynamic_geods_worstcase
// (GEODS_COMPARE_WORST_CASE: the worst-case variant, builds spread over later inserts).
#include <stdexcept>

#include "dynamic_driver.hpp"
#include "geods/dynamic/dynamic_kd_tree.hpp"

namespace {

struct Geods {
#ifdef GEODS_COMPARE_WORST_CASE
  static constexpr const char* anchor = "geods-worst-case";
  static constexpr geods::dynamic::Variant variant = geods::dynamic::Variant::worst_case;
#else
  static constexpr const char* anchor = "geods";
  static constexpr geods::dynamic::Variant variant = geods::dynamic::Variant::amortized;
#endif
  static constexpr bool single_insert = true;
  using Tree = geods::dynamic::DynamicKdTree<float, 3>;
  struct State {
    const float* points;
    Tree tree;
    std::vector<geods::dynamic::Id> remove_ids;
    State(const float* all_points, std::size_t) : points(all_points), tree(geods::dynamic::DynamizeOptions{variant}) {}
    void insert(std::size_t first, std::size_t count) {
      const auto ids = tree.insert(geods::spatial::PointView<float>(points + 3 * first, count, 3));
      if (ids.front() != first) throw std::runtime_error("DynamicKdTree handed out unexpected ids");
    }
    void remove(const std::uint32_t* ids, std::size_t count) {
      remove_ids.assign(ids, ids + count);
      tree.remove(remove_ids);
    }
    void prepare() {}
    void knn(const float* q, std::size_t k, std::uint32_t* ids, float* distances) const {
      thread_local std::vector<Tree::Neighbor> out;
      out.resize(k);
      tree.query_into(std::span<const float>(q, 3), geods::spatial::KnnRequest{k}, out.data());
      for (std::size_t i = 0; i < k; ++i) ids[i] = std::uint32_t(out[i].index), distances[i] = out[i].squared_distance;
    }
  };
};

}  // namespace

int main(int argc, char** argv) { return compare::dynamic::run<Geods>(argc, argv); }
