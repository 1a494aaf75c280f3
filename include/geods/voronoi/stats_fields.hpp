#pragma once
// The fields of the voronoi module's stats structs, named once (see
// spatial/stats_fields.hpp).
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/delaunay3.hpp"
#include "geods/voronoi/metric_voronoi.hpp"
#include "geods/voronoi/post_office.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "geods/voronoi/voronoi3.hpp"

namespace geods::voronoi {

/// Calls f(name, value) for each field, in declaration order.
template <typename F>
void for_each_field(const Delaunay2Stats& s, F&& f) {
  f("points", s.points), f("vertices", s.vertices), f("duplicates", s.duplicates), f("removed", s.removed);
  f("triangles", s.triangles), f("hull", s.hull), f("flips", s.flips), f("walk_steps", s.walk_steps);
  f("dag_nodes", s.dag_nodes), f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const Delaunay3Stats& s, F&& f) {
  f("points", s.points), f("vertices", s.vertices), f("duplicates", s.duplicates), f("removed", s.removed);
  f("rebuilds", s.rebuilds), f("tetrahedra", s.tetrahedra);
  f("hull_triangles", s.hull_triangles), f("dimension", s.dimension), f("walk_steps", s.walk_steps);
  f("conflicts", s.conflicts), f("seam_points", s.seam_points);
  f("flips_14", s.flips_14), f("flips_23", s.flips_23), f("flips_32", s.flips_32), f("flips_44", s.flips_44);
  f("splits", s.splits), f("hull_inserts", s.hull_inserts), f("unflippable", s.unflippable);
  f("flip_repairs", s.flip_repairs), f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const Voronoi2Stats& s, F&& f) {
  f("sites", s.sites), f("distinct", s.distinct), f("vertices", s.vertices), f("edges", s.edges);
  f("unbounded_cells", s.unbounded_cells), f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const Voronoi3Stats& s, F&& f) {
  f("sites", s.sites), f("faces", s.faces), f("vertices", s.vertices), f("empty", s.empty), f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const SlabLocatorStats& s, F&& f) {
  f("slabs", s.slabs), f("crossings", s.crossings), f("max_crossings", s.max_crossings), f("bytes", s.bytes);
}

template <typename F>
void for_each_field(const MetricVoronoiStats& s, F&& f) {
  f("sites", s.sites), f("distinct", s.distinct), f("edges", s.edges), f("cell_vertices", s.cell_vertices);
  f("max_candidates", s.max_candidates);
}

}  // namespace geods::voronoi
