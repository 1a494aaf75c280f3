// CGAL 5.5's Kd_tree + Orthogonal_k_neighbor_search (Search_traits_3 over Simple_cartesian<float>,
// sliding-midpoint splitter with bucket size 10) on the knn comparison inputs.
// The points are stored in the tree as (Point_3, index) tuples (CGAL's documented "point with
// info" pattern, Search_traits_adapter + Nth_of_tuple_property_map), so the neighbour indices come
// back without an extra lookup; the copy of the float array into those tuples is part of build_s.
// threads > 1: build<Parallel_tag>() (CGAL's TBB build), queries split by the driver like the others.
#include <CGAL/Kd_tree.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>
#include <boost/iterator/counting_iterator.hpp>
#include <boost/tuple/tuple.hpp>

#include <tbb/global_control.h>

#include "knn_driver.hpp"

namespace {

using Kernel = CGAL::Simple_cartesian<float>;
using Point = Kernel::Point_3;
using Item = boost::tuple<Point, std::uint32_t>;
using PointMap = CGAL::Nth_of_tuple_property_map<0, Item>;
using BaseTraits = CGAL::Search_traits_3<Kernel>;
using Traits = CGAL::Search_traits_adapter<Item, PointMap, BaseTraits>;
using Splitter = CGAL::Sliding_midpoint<Traits>;
using Tree = CGAL::Kd_tree<Traits, Splitter>;
using Distance = CGAL::Distance_adapter<Item, PointMap, CGAL::Euclidean_distance<BaseTraits>>;
using Search = CGAL::Orthogonal_k_neighbor_search<Traits, Distance, Splitter, Tree>;

struct Cgal {
  static constexpr const char* anchor = "cgal";
  struct Index {
    Tree tree;
    explicit Index(std::size_t leaf_size) : tree(Splitter(static_cast<unsigned>(leaf_size))) {}
  };
  static std::unique_ptr<Index> build(const float* points, std::size_t n, std::size_t leaf_size) {
    auto index = std::make_unique<Index>(leaf_size);
    std::vector<Item> items;
    items.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
      items.emplace_back(Point(points[3 * i], points[3 * i + 1], points[3 * i + 2]), static_cast<std::uint32_t>(i));
    index->tree.insert(items.begin(), items.end());
    if (tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1)
      index->tree.template build<CGAL::Parallel_tag>();
    else
      index->tree.template build<CGAL::Sequential_tag>();
    return index;
  }
  static void knn(const Index& index, const float* q, std::size_t k, std::uint32_t* indices, float* distances) {
    const Search search(index.tree, Point(q[0], q[1], q[2]), static_cast<unsigned>(k), 0.0f, true, Distance(), true);
    std::size_t i = 0;
    for (auto it = search.begin(); it != search.end() && i < k; ++it, ++i) {
      indices[i] = boost::get<1>(it->first);
      distances[i] = it->second;  // squared (transformed) distance
    }
    for (; i < k; ++i) indices[i] = ~0u, distances[i] = 0;
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::knn::run<Cgal>(argc, argv); }
