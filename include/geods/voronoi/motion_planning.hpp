#pragma once
// Motion planning for a disc robot (seed §5.4.2, Theorem 9) on the Voronoi
// diagram of the obstacles' edges: the start and the goal are retracted onto
// the diagram (moved straight away from their nearest obstacle feature until
// they reach it), the edges whose clearance is below the robot's radius r are
// removed, and the shortest path by arc length (Dijkstra) in what is left is
// the answer. A path exists on the diagram exactly when a disc of radius r
// can move from start to goal among the obstacles (the retraction argument).
//
// The workspace is a frame (axis-aligned box) around the obstacles, the start
// and the goal: by default their bounding box grown by `margin` times its
// larger side on every side; the robot must keep r from the frame too.
//
// Input rules: obstacles are simple polygons (closed rings of at least 3
// points; a repeated closing point is dropped) that do not overlap; crossing
// edges (a self-intersecting polygon or overlapping polygons), a start or
// goal inside an obstacle or outside the frame, NaN, or a negative radius
// raise geods::Error. Polygons may touch at shared vertices.
#include <array>
#include <memory>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/vec.hpp"
#include "geods/voronoi/segment_voronoi.hpp"

namespace geods::voronoi {
namespace detail {
class EvenOddIndex;
}

struct PlanOptions {
  double margin = 0.25;  // frame: bounding box grown by margin * its larger side
  bool use_bounds = false;
  AABB2d bounds;  // the frame when use_bounds is set (must contain the obstacles, start and goal)
  double step = 0;  // sample spacing of the output path along arcs; 0: 1/500 of the frame's larger side
};

/// Result of a query. `reason` is "" when a path was found, else
/// "start_too_close" (start nearer than r to an obstacle or the frame),
/// "goal_too_close", or "disconnected" (no way through for radius r).
struct PathPlan {
  bool found = false;
  std::string reason;
  std::vector<Vec2d> path;  // start, its retraction, points along the diagram's arcs, the goal's retraction, goal
  double length = 0;        // arc length of the path (exact for lines and parabolas)
  double min_clearance = 0; // smallest distance from the path to an obstacle or the frame
  double max_radius = 0;    // the largest radius for which a path from start to goal exists
};

class MotionPlanner {
 public:
  /// `polygons`: each a ring of points (closing point optional).
  MotionPlanner(const std::vector<std::vector<Vec2d>>& polygons, const PlanOptions& options, const Vec2d& start,
                const Vec2d& goal);
  /// Build for a given frame (options.use_bounds must be set), to plan many queries in it.
  MotionPlanner(const std::vector<std::vector<Vec2d>>& polygons, const PlanOptions& options);
  ~MotionPlanner();
  MotionPlanner(MotionPlanner&&) noexcept;

  /// The shortest path on the diagram for a disc of radius r.
  PathPlan plan(const Vec2d& start, const Vec2d& goal, double radius) const;
  /// The largest radius for which a path exists between start and goal.
  double max_radius(const Vec2d& start, const Vec2d& goal) const;

  const SegmentVoronoi& diagram() const { return diagram_; }
  const AABB2d& frame() const { return frame_; }
  /// Distance from x to the nearest obstacle edge or frame side.
  double clearance(const Vec2d& x) const;
  /// Even-odd inside test against the obstacles.
  bool inside_obstacle(const Vec2d& x) const;
  /// The usable edges of the diagram (primary, finite, in free space).
  const std::vector<std::uint32_t>& graph_edges() const { return graph_edges_; }

 private:
  struct Retraction {
    Vec2d point;
    std::uint32_t edge = SegmentVoronoi::kInfinity;
    double t = 0;          // parameter on the edge's curve
    double clearance = 0;  // of the start/goal itself
  };
  void build(const std::vector<std::vector<Vec2d>>& polygons);
  void check_query(const Vec2d& p, const char* what) const;
  Retraction retract(const Vec2d& p) const;
  double elementary_distance(std::uint32_t site, const Vec2d& x) const;
  // Length and clearance of edge e between parameters a <= b.
  double arc_length(std::uint32_t e, double a, double b) const;
  double clearance_between(std::uint32_t e, double a, double b) const;
  struct Search;
  Search search(const Retraction& s, const Retraction& g, double radius, bool bottleneck) const;

  PlanOptions options_;
  std::vector<std::array<Vec2d, 2>> obstacle_segments_;
  AABB2d frame_;
  SegmentVoronoi diagram_;
  std::vector<std::uint32_t> graph_edges_;
  std::vector<char> in_graph_;
  std::vector<double> edge_length_, edge_clearance_;  // per diagram edge (graph edges only)
  std::vector<std::vector<std::uint32_t>> vertex_edges_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> pair_edges_;
  std::unique_ptr<detail::EvenOddIndex> inside_;
};

/// One-shot planning: builds the planner for these obstacles, start and goal.
PathPlan plan_path(const std::vector<std::vector<Vec2d>>& polygons, const Vec2d& start, const Vec2d& goal,
                   double radius, const PlanOptions& options = {});

}  // namespace geods::voronoi
