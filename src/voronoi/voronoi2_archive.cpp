// Voronoi2::save and load: the sites, vertices, half-edges and neighbour lists as
// archive sections, viewed in place on load, range-checked and their cells
// checked (all of validate() unless the checksums were verified alone).
#include <string>

#include "archive_sections.hpp"
#include "geods/voronoi/voronoi2.hpp"

namespace geods::voronoi {
namespace {
constexpr const char* kKind = "voronoi.Voronoi2";
constexpr std::uint32_t kVersion = 1;
}  // namespace

void Voronoi2::save(const std::filesystem::path& path) const {
  ArchiveWriter w(kKind, kVersion);
  w.add("points", coordinates_of(points_));
  w.add("representative", representative_);
  w.add("vertices", coordinates_of(vertices_));
  w.add("edges", edges_);
  w.add("cell_edge", cell_edge_);
  w.add("neighbor_offsets", neighbor_offsets_);
  w.add("neighbors", neighbors_);
  w.write(path);
}

Voronoi2 Voronoi2::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kKind, kVersion, verify);
  Voronoi2 v;
  v.points_ = read_points(a, "points");
  v.vertices_ = read_points(a, "vertices");
  const std::uint64_t n = v.points_.size();
  v.representative_ = read_indices(a, "representative", n, {}, n);
  for (std::uint32_t i = 0; i < n; ++i)
    if (v.representative_[v.representative_[i]] != v.representative_[i])
      throw a.error("representative: point " + std::to_string(i) + " has a representative that is not its own");
  v.edges_ = a.array<Edge>("edges");
  const std::uint64_t m = v.edges_.size();
  v.cell_edge_ = read_indices(a, "cell_edge", m, {kNoEdge}, n);
  v.neighbors_ = read_indices(a, "neighbors", n);
  v.neighbor_offsets_ = read_indices(a, "neighbor_offsets", v.neighbors_.size() + 1, {}, n + 1);
  for (std::size_t i = 0; i < n; ++i)
    if (v.neighbor_offsets_[i] > v.neighbor_offsets_[i + 1]) throw a.error("neighbor_offsets: not increasing");
  if (v.neighbor_offsets_.back() != v.neighbors_.size()) throw a.error("neighbor_offsets: do not end at the neighbours' count");
  a.check([&] { Archive::checks_everything(verify) ? v.validate() : v.check_cells(); });
  return v;
}

}  // namespace geods::voronoi
