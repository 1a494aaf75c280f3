// Delaunay2::save and load: the points, the segments and the closed triangulation
// as archive sections; on load every index is range-checked, the triangulation's
// combinatorics checked and the public view rebuilt.
#include <string>

#include "archive_sections.hpp"
#include "geods/voronoi/delaunay2.hpp"

namespace geods::voronoi {
namespace {

constexpr const char* kKind = "voronoi.Delaunay2";
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kNone = Delaunay2::no_edge;

std::span<const std::uint32_t> flat(const std::vector<Delaunay2::Segment>& segments) {
  return {segments.empty() ? nullptr : segments.data()->data(), 2 * segments.size()};
}

}  // namespace

void Delaunay2::save(const std::filesystem::path& path) const {
  ArchiveWriter w(kKind, kVersion);
  w.add_value("seed", options_.seed);
  w.add_value("location", std::uint32_t(options_.location));
  w.add_value("has_constraints", std::uint8_t(has_constraints_));
  w.add_value("last_triangle", core_.last_triangle);
  const std::vector<std::uint64_t> counters = {core_.flips, core_.walk_steps, dag_nodes_};
  w.add("counters", counters);
  w.add("points", coordinates_of(points_));
  w.add("segments", flat(segments_));
  w.add("intersections", intersections_);
  w.add("representative", rep_);
  w.add("coords", coordinates_of(core_.coords));
  w.add("original_of", original_of_);
  w.add("internal_of", internal_of_);
  w.add("vert", core_.vert);
  w.add("twin", core_.twin);
  w.add("free_triangles", core_.free_triangles);
  w.add("fixed", fixed_);
  w.write(path);
}

Delaunay2 Delaunay2::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kKind, kVersion, verify);
  Delaunay2 dt;
  dt.options_.seed = a.value<std::uint64_t>("seed");
  const std::uint32_t location = a.value<std::uint32_t>("location");
  if (location > std::uint32_t(Delaunay2Location::history_dag)) throw a.error("unknown location " + std::to_string(location));
  dt.options_.location = Delaunay2Location(location);
  dt.has_constraints_ = a.value<std::uint8_t>("has_constraints") != 0;
  const FlatArray<std::uint64_t> counters = a.array<std::uint64_t>("counters", 3);
  dt.core_.flips = counters[0], dt.core_.walk_steps = counters[1], dt.dag_nodes_ = counters[2];

  dt.points_ = read_points(a, "points").to_vector();
  dt.core_.coords = read_points(a, "coords").to_vector();
  const std::uint64_t n = dt.points_.size(), m = dt.core_.coords.size();
  const FlatArray<std::uint32_t> ends = read_indices(a, "segments", n);
  if (ends.size() % 2) throw a.error("segments: an odd number of end points");
  for (std::size_t k = 0; k < ends.size(); k += 2) dt.segments_.push_back({ends[k], ends[k + 1]});
  dt.intersections_ = read_indices(a, "intersections", n).to_vector();
  dt.rep_ = read_indices(a, "representative", n, {kNone}, n).to_vector();
  dt.original_of_ = read_indices(a, "original_of", n, {}, m).to_vector();
  dt.internal_of_ = read_indices(a, "internal_of", m, {kNone}, m == 0 ? 0 : n).to_vector();  // a degenerate set has no internal vertices
  dt.core_.vert = read_indices(a, "vert", m, {DelaunayCore::ghost, DelaunayCore::none}).to_vector();
  const std::uint64_t half_edges = dt.core_.vert.size();
  dt.core_.twin = read_indices(a, "twin", half_edges, {}, half_edges).to_vector();
  dt.core_.free_triangles = read_indices(a, "free_triangles", half_edges / 3).to_vector();
  dt.core_.last_triangle = read_indices(a, "last_triangle", std::max<std::uint64_t>(half_edges / 3, 1), {}, 1)[0];
  dt.fixed_ = a.array<std::uint8_t>("fixed", dt.has_constraints_ ? half_edges : 0).to_vector();
  for (std::uint32_t t : dt.core_.free_triangles)
    if (dt.core_.vert[3 * t] != kNone) throw a.error("free_triangles: triangle " + std::to_string(t) + " is in use");

  try {
    dt.check_representatives();
    if (half_edges == 0) {
      dt.build_degenerate();
      dt.validate();
    } else {
      dt.check_triangles();
      dt.publish();
      if (Archive::checks_everything(verify)) dt.validate();
    }
  } catch (const Error& e) {
    throw a.error(e.what());
  }
  return dt;
}

}  // namespace geods::voronoi
