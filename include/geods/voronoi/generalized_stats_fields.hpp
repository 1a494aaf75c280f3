#pragma once
// The fields of the generalized diagrams' stats structs (power, farthest-point,
// k-th order, constrained), named once (see voronoi/stats_fields.hpp).
#include "geods/voronoi/constrained_voronoi.hpp"
#include "geods/voronoi/farthest_voronoi.hpp"
#include "geods/voronoi/kth_order_voronoi.hpp"
#include "geods/voronoi/power_diagram.hpp"

namespace geods::voronoi {

template <typename F>
void for_each_field(const RegularTriangulationStats& s, F&& f) {
  f("points", s.points), f("vertices", s.vertices), f("redundant", s.redundant), f("duplicates", s.duplicates);
  f("triangles", s.triangles), f("hull", s.hull), f("flips", s.flips), f("removals", s.removals);
}

template <typename F>
void for_each_field(const PowerDiagramStats& s, F&& f) {
  f("sites", s.sites), f("cells", s.cells), f("redundant", s.redundant), f("edges", s.edges);
  f("cell_vertices", s.cell_vertices);
}

template <typename F>
void for_each_field(const FarthestVoronoiStats& s, F&& f) {
  f("sites", s.sites), f("distinct", s.distinct), f("corners", s.corners), f("edges", s.edges);
  f("cell_vertices", s.cell_vertices);
}

template <typename F>
void for_each_field(const KthOrderVoronoiStats& s, F&& f) {
  f("sites", s.sites), f("distinct", s.distinct), f("k", s.k), f("regions", s.regions), f("pieces", s.pieces);
  f("region_vertices", s.region_vertices);
}

template <typename F>
void for_each_field(const ConstrainedVoronoiStats& s, F&& f) {
  f("sites", s.sites), f("distinct", s.distinct), f("segments", s.segments), f("pieces", s.pieces);
  f("cells", s.cells), f("max_candidates", s.max_candidates);
}

}  // namespace geods::voronoi
