#include "geods/bvh/build_options.hpp"

#include <array>
#include <utility>

#include "geods/core/error.hpp"

namespace geods::bvh {
namespace {

// Each name is the enum value's; a later entry for the same value is a deprecated spelling.
constexpr std::array<std::pair<std::string_view, Builder>, 8> kBuilders = {{{"sah", Builder::sah},
                                                                            {"median", Builder::median},
                                                                            {"pca", Builder::pca},
                                                                            {"bottom_up", Builder::bottom_up},
                                                                            {"tiling", Builder::tiling},
                                                                            {"insertion", Builder::insertion},
                                                                            {"boxtree", Builder::boxtree},
                                                                            {"bottomup", Builder::bottom_up}}};
constexpr std::array<std::pair<std::string_view, BoundingVolume>, 9> kVolumes = {{{"aabb", BoundingVolume::aabb},
                                                                                 {"sphere", BoundingVolume::sphere},
                                                                                 {"kdop6", BoundingVolume::kdop6},
                                                                                 {"kdop14", BoundingVolume::kdop14},
                                                                                 {"kdop18", BoundingVolume::kdop18},
                                                                                 {"kdop26", BoundingVolume::kdop26},
                                                                                 {"obb", BoundingVolume::obb},
                                                                                 {"obb_hull", BoundingVolume::obb_hull},
                                                                                 {"rss", BoundingVolume::rss}}};

// The current names (deprecated spellings left out).
template <typename Table>
std::string names_of(const Table& table) {
  std::string out;
  for (std::size_t i = 0; i < table.size(); ++i) {
    bool alias = false;
    for (std::size_t j = 0; j < i; ++j) alias = alias || table[j].second == table[i].second;
    if (!alias) out += (out.empty() ? "" : ", ") + std::string(table[i].first);
  }
  return out;
}

}  // namespace

Builder parse_builder(std::string_view name) {
  for (const auto& [n, b] : kBuilders)
    if (n == name) return b;
  throw Error("bvh: unknown builder '" + std::string(name) + "' (one of " + names_of(kBuilders) + ")");
}

BoundingVolume parse_bounding_volume(std::string_view name) {
  for (const auto& [n, v] : kVolumes)
    if (n == name) return v;
  throw Error("bvh: unknown bounding volume '" + std::string(name) + "' (one of " + names_of(kVolumes) + ")");
}

std::string_view to_string(Builder builder) {
  for (const auto& [n, b] : kBuilders)
    if (b == builder) return n;
  return "?";
}

std::string_view to_string(BoundingVolume bv) {
  for (const auto& [n, v] : kVolumes)
    if (v == bv) return n;
  return "?";
}

void check_options(const BuildOptions& options) {
  if (options.leaf_size < 1 || options.leaf_size > 255)
    throw Error("bvh: leaf_size must be in 1..255, got " + std::to_string(options.leaf_size));
  if (options.arity != 2 && options.arity != 4 && options.arity != 8)
    throw Error("bvh: arity must be 2, 4 or 8, got " + std::to_string(options.arity));
  if (options.sah_bins < 2 || options.sah_bins > 64)
    throw Error("bvh: sah_bins must be in 2..64, got " + std::to_string(options.sah_bins));
  bool known_builder = false, known_bv = false;
  for (const auto& entry : kBuilders) known_builder |= entry.second == options.builder;
  for (const auto& entry : kVolumes) known_bv |= entry.second == options.bv;
  if (!known_builder) throw Error("bvh: unknown builder value");
  if (!known_bv) throw Error("bvh: unknown bounding volume value");
}

}  // namespace geods::bvh
