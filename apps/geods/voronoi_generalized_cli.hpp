#pragma once
// The generalized diagrams of `geods voronoi` (--weights, --farthest, --order):
// built here as cells, edges and stats for the command to draw and write.
#include <fmt/format.h>

#include <optional>
#include <string>
#include <vector>

#include <filesystem>

#include "geods/io/npy.hpp"
#include "geods/io/table_io.hpp"
#include "geods/voronoi/constrained_voronoi.hpp"
#include "geods/voronoi/farthest_voronoi.hpp"
#include "geods/voronoi/generalized_stats_fields.hpp"
#include "geods/voronoi/kth_order_voronoi.hpp"
#include "geods/voronoi/power_diagram.hpp"
#include "stats_json.hpp"

namespace geods::cli {

struct GeneralizedDiagram {
  std::string kind;  // "power", "farthest" or "order"
  std::vector<std::vector<Vec2d>> cells;  // per point (power, farthest) or per region (order)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edge_sites;
  std::vector<std::pair<Vec2d, Vec2d>> edges;
  Json stats = Json::object();
  Json extra = Json::object();  // for the JSON output: redundant points, region sets
  std::string title;
};

/// One value per point (`option` names it in messages): a 1-D .npy of n values, or an n x 1 table (.npy, .csv, .txt).
inline std::vector<double> read_per_point(const std::string& path, std::size_t points, const std::string& option) {
  std::vector<double> w;
  if (std::filesystem::path(path).extension() == ".npy" && path != "-") {
    const io::NpyArray a = io::read_npy(path);
    if (a.shape.size() == 1) w = a.to_vector<double>();
  }
  if (w.empty()) w = io::read_table(path, "value", 1).values;
  if (w.size() != points)
    throw Error(option + ": " + path + " has " + std::to_string(w.size()) + " values for " + std::to_string(points) + " points");
  return w;
}

/// Segments as an m x 2 table of point indices.
inline std::vector<voronoi::ConstrainedVoronoi::Segment> read_index_pairs(const std::string& path, std::size_t points) {
  const io::Table t = io::read_table(path, "segment", 2);
  std::vector<voronoi::ConstrainedVoronoi::Segment> out(t.rows);
  for (std::size_t i = 0; i < 2 * t.rows; ++i) {
    const double v = t.values[i];
    if (!(v >= 0 && v == std::floor(v) && v < double(points)))
      throw Error("--constraints: " + path + " holds " + format_number(v) + ", not a point index below " + std::to_string(points));
    out[i / 2][i % 2] = std::uint32_t(v);
  }
  return out;
}

inline GeneralizedDiagram build_generalized(const std::vector<Vec2d>& points, const AABB2d& box,
                                            const std::string& weights, bool farthest, std::size_t order,
                                            const std::string& constraints = "") {
  GeneralizedDiagram g;
  const auto take_edges = [&](const auto& list) {
    for (const auto& e : list) {
      g.edges.push_back({e.p0, e.p1});
      g.edge_sites.push_back({e.a, e.b});
    }
  };
  if (!weights.empty()) {
    const voronoi::PowerDiagram d(points, read_per_point(weights, points.size(), "--weights"), box);
    g.kind = "power";
    g.cells = d.cells();
    take_edges(d.edges());
    const auto t = d.triangulation().stats();
    put_stats(g.stats, t);
    g.stats["distinct"] = t.points - t.duplicates;
    g.extra["redundant"] = d.triangulation().redundant();
    g.title = fmt::format("Power diagram of {} weighted points ({} redundant)", points.size(), t.redundant);
  } else if (!constraints.empty()) {
    const voronoi::ConstrainedVoronoi d(points, read_index_pairs(constraints, points.size()), box);
    g.kind = "constrained";
    Json sites = Json::array();
    for (const auto& piece : d.pieces()) {
      g.cells.push_back(piece.polygon);
      sites.push_back(piece.site);
    }
    put_stats(g.stats, d.stats());
    g.extra["piece_sites"] = std::move(sites);
    Json segs = Json::array();
    for (const auto& s : d.constraints()) segs.push_back({s[0], s[1]});
    g.extra["constraints"] = std::move(segs);
    g.title = fmt::format("Constrained Voronoi diagram of {} points and {} segments", points.size(), d.constraints().size());
  } else if (farthest) {
    const voronoi::FarthestVoronoi d(points, box);
    g.kind = "farthest";
    g.cells = d.cells();
    take_edges(d.edges());
    put_stats(g.stats, d.stats());
    g.extra["corners"] = d.corners();
    g.title = fmt::format("Farthest-point Voronoi diagram of {} points", points.size());
  } else {
    const voronoi::KthOrderVoronoi d(points, order, box);
    g.kind = "order";
    Json sets = Json::array();
    for (const auto& r : d.regions()) {
      g.cells.push_back(r.polygon);
      sets.push_back(r.sites);
    }
    put_stats(g.stats, d.stats());
    g.extra["regions"] = std::move(sets);
    g.title = fmt::format("Order-{} Voronoi diagram of {} points", order, points.size());
  }
  return g;
}

}  // namespace geods::cli
