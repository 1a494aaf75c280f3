#pragma once
// The one dispatch from a run-time dimension to KdTree<T, Dim>: the trees
// compiled for 2 and 3 dimensions (fixed-size points, unrolled distances),
// the run-time one for any other. The CLI and Python build and load trees
// through it.
#include <cstddef>
#include <filesystem>
#include <utility>
#include <variant>

#include "geods/spatial/kd_tree.hpp"

namespace geods::spatial {

/// A k-d tree of one of the dimensions dispatch_kd_dimension picks.
template <typename T>
using AnyKdTree = std::variant<KdTree<T, 2>, KdTree<T, 3>, KdTree<T, Dynamic>>;

/// fn.template operator()<Dim>() with Dim = dim for 2 and 3, Dynamic otherwise.
template <typename Fn>
decltype(auto) dispatch_kd_dimension(std::size_t dim, Fn&& fn) {
  if (dim == 2) return fn.template operator()<2>();
  if (dim == 3) return fn.template operator()<3>();
  return fn.template operator()<Dynamic>();
}

/// The tree over `points` (read in place: they must outlive it) for their dimension.
template <typename T>
AnyKdTree<T> make_kd_tree(PointView<T> points, std::size_t leaf_size = KdTree<T>::kDefaultLeafSize,
                          PointLayout layout = PointLayout::tree_order) {
  return dispatch_kd_dimension(points.dim, [&]<int Dim>() {
    return AnyKdTree<T>(std::in_place_type<KdTree<T, Dim>>, points, leaf_size, layout);
  });
}

/// A tree written by KdTree<T, *>::save of dimension `dim` (read_kd_tree_info gives the dimension).
template <typename T>
AnyKdTree<T> load_kd_tree(const std::filesystem::path& path, std::size_t dim,
                          PointLayout layout = PointLayout::zero_copy) {
  return dispatch_kd_dimension(
      dim, [&]<int Dim>() { return AnyKdTree<T>(KdTree<T, Dim>::load(path, Archive::Verify::checksums, layout)); });
}

}  // namespace geods::spatial
