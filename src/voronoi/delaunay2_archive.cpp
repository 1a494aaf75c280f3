// Delaunay2::save and load: the points, the segments, the closed triangulation
// and its public view as archive sections, viewed in place on load; every index
// is range-checked, the triangulation's combinatorics checked and the public
// view checked against it (nothing is rebuilt).
#include <string>

#include "archive_sections.hpp"
#include "geods/voronoi/delaunay2.hpp"

namespace geods::voronoi {
namespace {

constexpr const char* kKind = "voronoi.Delaunay2";
constexpr std::uint32_t kVersion = 2;  // 2: the public view saved too (version 1 files are refused)
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
  w.add_value("last_triangle", last_triangle_);
  const std::vector<std::uint64_t> counters = {flips_, walk_steps_, dag_nodes_};
  w.add("counters", counters);
  w.add("points", coordinates_of(points_));
  w.add("segments", flat(segments_));
  w.add("intersections", intersections_);
  w.add("representative", rep_);
  w.add("coords", coordinates_of(coords_));
  w.add("original_of", original_of_);
  w.add("internal_of", internal_of_);
  w.add("vert", vert_);
  w.add("twin", twin_);
  w.add("free_triangles", free_triangles_);
  w.add("vertex_edge", vertex_edge_);
  w.add("fixed", fixed_);
  w.add("triangles", triangles_);
  w.add("halfedges", halfedges_);
  w.add("hull", hull_);
  w.add("constrained", constrained_);
  w.add("public_triangle", public_triangle_);
  w.add("internal_triangle", internal_triangle_);
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
  dt.flips_ = counters[0], dt.walk_steps_ = counters[1], dt.dag_nodes_ = counters[2];

  dt.points_ = read_points(a, "points");
  dt.coords_ = read_points(a, "coords");
  const std::uint64_t n = dt.points_.size(), m = dt.coords_.size();
  const FlatArray<std::uint32_t> ends = read_indices(a, "segments", n);
  if (ends.size() % 2) throw a.error("segments: an odd number of end points");
  for (std::size_t k = 0; k < ends.size(); k += 2) dt.segments_.push_back({ends[k], ends[k + 1]});
  dt.intersections_ = read_indices(a, "intersections", n).to_vector();
  dt.rep_ = read_indices(a, "representative", n, {kNone}, n);
  dt.original_of_ = read_indices(a, "original_of", n, {}, m);
  dt.internal_of_ = read_indices(a, "internal_of", m, {kNone}, m == 0 ? 0 : n);  // a degenerate set has no internal vertices
  dt.vert_ = read_indices(a, "vert", m, {DelaunayCore::ghost, DelaunayCore::none});
  const std::uint64_t half_edges = dt.vert_.size(), internal = half_edges / 3;
  dt.twin_ = read_indices(a, "twin", half_edges, {}, half_edges);
  dt.free_triangles_ = read_indices(a, "free_triangles", internal);
  dt.last_triangle_ = read_indices(a, "last_triangle", std::max<std::uint64_t>(internal, 1), {}, 1)[0];
  dt.vertex_edge_ = read_indices(a, "vertex_edge", half_edges, {kNone}, m);
  dt.fixed_ = a.array<std::uint8_t>("fixed", dt.has_constraints_ ? half_edges : 0);
  dt.triangles_ = read_indices(a, "triangles", n);
  const std::uint64_t finite = dt.triangles_.size() / 3;
  if (dt.triangles_.size() % 3) throw a.error("triangles: not a multiple of 3 vertices");
  dt.halfedges_ = read_indices(a, "halfedges", 3 * finite, {kNone}, 3 * finite);
  dt.hull_ = read_indices(a, "hull", n);
  dt.constrained_ = a.array<std::uint8_t>("constrained", dt.has_constraints_ ? 3 * finite : 0);
  dt.public_triangle_ = read_indices(a, "public_triangle", finite, {kNone}, internal);
  dt.internal_triangle_ = read_indices(a, "internal_triangle", internal, {}, finite);
  for (std::uint32_t t : dt.free_triangles_)
    if (dt.vert_[3 * t] != kNone) throw a.error("free_triangles: triangle " + std::to_string(t) + " is in use");

  a.check([&] {
    const std::size_t representatives = dt.check_representatives();
    if (half_edges == 0) {
      dt.validate();  // cheap without triangles
    } else {
      const TriangleCounts counts = dt.check_triangles(representatives);
      dt.check_public_view(counts.live - counts.ghosts);
      if (Archive::checks_everything(verify)) dt.validate();
    }
  });
  return dt;
}

}  // namespace geods::voronoi
