// Delaunay3::save and load: the points, removal flags, representatives and the
// closed tetrahedralization's slots as archive sections. Load copies them into
// the structure's own arrays (insert() changes them in place), checks every
// index before anything reads through it, rebuilds the public arrays and runs
// validate() (exact: a file that loads is a Delaunay tetrahedralization).
#include <string>

#include "archive_sections.hpp"
#include "delaunay3_mesh.hpp"
#include "geods/core/error.hpp"
#include "geods/voronoi/delaunay3.hpp"

namespace geods::voronoi {
namespace {
constexpr const char* kKind = "voronoi.Delaunay3";
constexpr std::uint32_t kVersion = 1;
}  // namespace

void Delaunay3::save(const std::filesystem::path& path) const {
  ArchiveWriter w(kKind, kVersion);
  w.add("points", coordinates_of(std::span<const Vec3d>(points_)));
  w.add("removed", removed_);
  w.add("representative", rep_);
  w.add("tetrahedra_slots", tets_);
  w.add("free_slots", free_slots_);
  w.add_value("dimension", std::int32_t(dimension_));
  w.add_value("seed", options_.seed);
  w.add_value("insertion", std::int32_t(options_.insertion));  // (absent from older files: cavity)
  w.add_value("last", last_);
  w.write(path);
}

Delaunay3 Delaunay3::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kKind, kVersion, verify);
  Delaunay3 dt;
  dt.points_ = read_points<Vec3d>(a, "points").to_vector();
  const std::uint64_t n = dt.points_.size();
  dt.removed_ = a.array<std::uint8_t>("removed", n).to_vector();
  dt.rep_ = read_indices(a, "representative", n, {no_index}, n).to_vector();
  for (std::uint64_t i = 0; i < n; ++i)
    if ((dt.rep_[i] == no_index) != (dt.removed_[i] != 0) || (dt.rep_[i] != no_index && dt.rep_[dt.rep_[i]] != dt.rep_[i]))
      throw a.error("representative: point " + std::to_string(i) + " has a bad representative");
  dt.tets_ = a.array<std::uint32_t>("tetrahedra_slots").to_vector();
  if (dt.tets_.size() % 8) throw a.error("tetrahedra_slots: not 8 entries per slot");
  const std::uint64_t slots = dt.tets_.size() / 8;
  dt.free_slots_ = read_indices(a, "free_slots", slots).to_vector();
  dt.dimension_ = a.value<std::int32_t>("dimension");
  if (dt.dimension_ < -1 || dt.dimension_ > 3) throw a.error("dimension: " + std::to_string(dt.dimension_));
  dt.options_.seed = a.value<std::uint64_t>("seed");
  if (a.has("insertion")) {
    const std::int32_t insertion = a.value<std::int32_t>("insertion");
    if (insertion != std::int32_t(Delaunay3Insertion::cavity) && insertion != std::int32_t(Delaunay3Insertion::flips))
      throw a.error("insertion: " + std::to_string(insertion) + " is neither cavity (0) nor flips (1)");
    dt.options_.insertion = Delaunay3Insertion(insertion);
  }
  dt.last_ = a.value<std::uint32_t>("last");
  if (dt.dimension_ < 3 ? slots != 0 : (slots == 0 || dt.last_ >= slots))
    throw a.error("tetrahedra_slots: do not fit dimension " + std::to_string(dt.dimension_));
  // Every index in range before anything follows one: vertices are representatives or the
  // ghost, a free slot is all no_index, adjacencies name slots.
  for (std::uint64_t s = 0; s < slots; ++s) {
    const std::uint32_t* t = &dt.tets_[8 * s];
    if (t[0] == no_index) {
      if (t[1] != no_index || t[2] != no_index || t[3] != no_index)
        throw a.error("tetrahedra_slots: slot " + std::to_string(s) + " is half free");
      continue;
    }
    for (int k = 0; k < 4; ++k) {
      if (t[k] != Tet3Mesh::kGhost && (t[k] >= n || dt.rep_[t[k]] != t[k]))
        throw a.error("tetrahedra_slots: slot " + std::to_string(s) + " has a vertex that is not a point");
      if ((t[4 + k] >> 2) >= slots || dt.tets_[8 * std::size_t(t[4 + k] >> 2)] == no_index)
        throw a.error("tetrahedra_slots: slot " + std::to_string(s) + " has a neighbour out of range");
    }
  }
  if (dt.last_ < slots && dt.tets_[8 * std::size_t(dt.last_)] == no_index) throw a.error("last: a free slot");
  dt.publish();
  a.check([&] { dt.validate(); });
  return dt;
}

}  // namespace geods::voronoi
