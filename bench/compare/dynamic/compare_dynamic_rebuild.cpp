// Baseline: a static geods::spatial::KdTree<float, 3> rebuilt from scratch whenever the point
// set has changed and a query round comes (dynamic_driver.hpp: prepare()). Inserts only append
// (the points are a prefix of the input, read in place); deletes mark points dead, then the live
// points are compacted and the tree is rebuilt over them. The rebuilds are timed as insert /
// delete time. This is the cheapest "rebuild" policy (one rebuild per query round, 11 in all).
#include <numeric>

#include "dynamic_driver.hpp"
#include "geods/spatial/kd_tree.hpp"

namespace {

struct Rebuild {
  static constexpr const char* anchor = "rebuild";
  static constexpr bool single_insert = false;  // one insert = one rebuild: not measured
  using Tree = geods::spatial::KdTree<float, 3>;
  struct State {
    const float* points;
    std::size_t n = 0;  // points [0, n) inserted
    std::vector<char> live;
    bool deleted = false, dirty = false;
    std::vector<float> compact;           // live points after deletions
    std::vector<std::uint32_t> original;  // compact index -> id
    std::unique_ptr<Tree> tree;
    State(const float* all_points, std::size_t total) : points(all_points), live(total, 0) {}
    void insert(std::size_t first, std::size_t count) {
      std::fill_n(live.begin() + first, count, 1);
      n = std::max(n, first + count);
      dirty = true;
    }
    void remove(const std::uint32_t* ids, std::size_t count) {
      for (std::size_t i = 0; i < count; ++i) live[ids[i]] = 0;
      deleted = dirty = true;
    }
    void prepare() {
      if (!dirty) return;
      dirty = false;
      tree.reset();
      if (!deleted) {
        tree = std::make_unique<Tree>(geods::spatial::PointView<float>(points, n, 3), 10);
        return;
      }
      compact.clear();
      original.clear();
      for (std::size_t i = 0; i < n; ++i)
        if (live[i]) {
          compact.insert(compact.end(), points + 3 * i, points + 3 * i + 3);
          original.push_back(static_cast<std::uint32_t>(i));
        }
      tree = std::make_unique<Tree>(geods::spatial::PointView<float>(compact.data(), original.size(), 3), 10);
    }
    void knn(const float* q, std::size_t k, std::uint32_t* ids, float* distances) const {
      thread_local std::vector<geods::spatial::Neighbor<float>> out;
      out.resize(k);
      tree->query_into(std::span<const float>(q, 3), geods::spatial::KnnRequest{k}, out.data());
      for (std::size_t i = 0; i < k; ++i) {
        const std::uint32_t j = out[i].index;
        ids[i] = deleted && j < original.size() ? original[j] : j;
        distances[i] = out[i].squared_distance;
      }
    }
  };
};

}  // namespace

int main(int argc, char** argv) { return compare::dynamic::run<Rebuild>(argc, argv); }
