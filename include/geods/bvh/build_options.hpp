#pragma once
// How a bounding volume hierarchy is built: the builder (§4.1 of the seed),
// the bounding volume stored at the nodes, leaf size and node arity.
#include <cstdint>
#include <string>
#include <string_view>

#include "geods/core/progress.hpp"

namespace geods::bvh {

enum class Builder {
  sah,        // top-down, binned surface area heuristic (equation 7, the sweep of §4.1.4)
  median,     // top-down, object median along the longest axis of the centroids
  pca,        // top-down, plane through the barycenter orthogonal to the principal axis
  bottom_up,  // bottom-up, pairing nearest neighbours level by level (§4.1.1)
  tiling,     // bottom-up, grouping the nodes of a level into tiles (§4.1.1)
  insertion,  // one primitive at a time into the child of least area increase (§4.1.2)
  boxtree,    // top-down, Zachmann's restricted boxtree criterion (least total volume, §4.1.5)
};

/// obb: principal axes of the vertices below a node (ObbFit::pca); obb_hull:
/// the smallest of the hull-based candidates of ObbFit::hull (tighter, slower
/// to build; the same Obb3f volumes and queries). rss: rectangle swept
/// spheres (rss.hpp) in the principal axes of the vertices below a node.
enum class BoundingVolume { aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, obb_hull, rss };

struct BuildOptions {
  Builder builder = Builder::sah;
  BoundingVolume bv = BoundingVolume::aabb;
  /// Most primitives in a leaf (1..255); the SAH builder may stop earlier.
  /// 8: two groups of 4 triangles in the wide AABB layout (ray_triangle4.hpp).
  int leaf_size = 8;
  /// Children per inner node: 2, 4 or 8. Wider trees come from collapsing the binary one.
  int arity = 4;
  /// Bins per axis of the SAH builder (2..64).
  int sah_bins = 32;
  ProgressCallback progress;
};

/// The enum value's name: "sah", "median", "pca", "bottom_up", "tiling", "insertion", "boxtree" ("bottomup":
/// the deprecated spelling of bottom_up); throws geods::Error otherwise.
Builder parse_builder(std::string_view name);
/// "aabb", "sphere", "kdop6", "kdop14", "kdop18", "kdop26", "obb", "obb_hull", "rss"; throws geods::Error otherwise.
BoundingVolume parse_bounding_volume(std::string_view name);
std::string_view to_string(Builder builder);
std::string_view to_string(BoundingVolume bv);
/// Throws geods::Error naming the bad field.
void check_options(const BuildOptions& options);

}  // namespace geods::bvh
