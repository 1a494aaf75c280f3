#include "geods/voronoi/motion_planning.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "even_odd.hpp"
#include "geods/core/error.hpp"
#include "geods/core/segment.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = SegmentVoronoi::kInfinity;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<std::array<Vec2d, 2>> polygon_segments(const std::vector<std::vector<Vec2d>>& polygons) {
  std::vector<std::array<Vec2d, 2>> out;
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    std::vector<Vec2d> ring;
    for (const Vec2d& p : polygons[i]) {
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
        throw Error("plan: obstacle " + std::to_string(i) + " has a coordinate that is not finite");
      if (ring.empty() || ring.back() != p) ring.push_back(p);
    }
    while (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
    if (ring.size() < 3) throw Error("plan: obstacle " + std::to_string(i) + " has fewer than 3 distinct points");
    for (std::size_t k = 0; k < ring.size(); ++k) out.push_back({ring[k], ring[(k + 1) % ring.size()]});
  }
  return out;
}

AABB2d make_frame(const std::vector<std::array<Vec2d, 2>>& segments, const PlanOptions& options,
                  const std::vector<Vec2d>& extra) {
  if (options.use_bounds) {
    if (options.bounds.empty() || !(options.bounds.hi - options.bounds.lo).allFinite())
      throw Error("plan: bounds must be a finite, non-empty box");
    return options.bounds;
  }
  if (!(options.margin > 0) || !std::isfinite(options.margin)) throw Error("plan: margin must be positive");
  AABB2d b;
  for (const auto& s : segments) b.extend(s[0]).extend(s[1]);
  for (const auto& p : extra) b.extend(p);
  if (b.empty()) throw Error("plan: no obstacles");
  const double side = std::max((b.hi - b.lo).maxCoeff(), 1e-300);
  const Vec2d m = Vec2d::Constant(options.margin * side);
  return AABB2d(b.lo - m, b.hi + m);
}

std::vector<double> flat_segments(const std::vector<std::array<Vec2d, 2>>& segments, const AABB2d& frame) {
  std::vector<double> out;
  out.reserve(4 * (segments.size() + 4));
  for (const auto& s : segments) out.insert(out.end(), {s[0][0], s[0][1], s[1][0], s[1][1]});
  const Vec2d c[4] = {frame.lo, Vec2d(frame.hi[0], frame.lo[1]), frame.hi, Vec2d(frame.lo[0], frame.hi[1])};
  for (int k = 0; k < 4; ++k) out.insert(out.end(), {c[k][0], c[k][1], c[(k + 1) % 4][0], c[(k + 1) % 4][1]});
  return out;
}

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

}  // namespace

MotionPlanner::MotionPlanner(const std::vector<std::vector<Vec2d>>& polygons, const PlanOptions& options,
                             const Vec2d& start, const Vec2d& goal)
    : options_(options),
      obstacle_segments_(polygon_segments(polygons)),
      frame_(make_frame(obstacle_segments_, options, {start, goal})),
      diagram_({}, flat_segments(obstacle_segments_, frame_)) {
  build(polygons);
}

MotionPlanner::MotionPlanner(const std::vector<std::vector<Vec2d>>& polygons, const PlanOptions& options)
    : options_(options),
      obstacle_segments_(polygon_segments(polygons)),
      frame_(make_frame(obstacle_segments_, options, {})),
      diagram_({}, flat_segments(obstacle_segments_, frame_)) {
  build(polygons);
}

MotionPlanner::~MotionPlanner() = default;
MotionPlanner::MotionPlanner(MotionPlanner&&) noexcept = default;

void MotionPlanner::build(const std::vector<std::vector<Vec2d>>&) {
  inside_ = std::make_unique<detail::EvenOddIndex>(obstacle_segments_);
  if (diagram_.split_count() > 0)
    throw Error("plan: obstacle edges cross (a self-intersecting polygon, overlapping polygons, or an obstacle "
                "crossing the frame)");
  if (options_.step == 0) options_.step = (frame_.hi - frame_.lo).maxCoeff() / 500;
  if (!(options_.step > 0)) throw Error("plan: step must be positive");
  const auto& edges = diagram_.edges();
  edge_length_.assign(edges.size(), 0);
  edge_clearance_.assign(edges.size(), 0);
  vertex_edges_.assign(diagram_.vertices().size(), {});
  in_graph_.assign(edges.size(), 0);
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    const auto& ed = edges[e];
    pair_edges_[pair_key(ed.site[0], ed.site[1])].push_back(e);
    if (!ed.primary || ed.vertex[0] == kNone || ed.vertex[1] == kNone) continue;
    const auto c = diagram_.edge_curve(e);
    const Vec2d mid = c.point(0.5 * (c.t0 + c.t1));
    if (!(mid[0] > frame_.lo[0] && mid[0] < frame_.hi[0] && mid[1] > frame_.lo[1] && mid[1] < frame_.hi[1])) continue;
    if (inside_obstacle(mid)) continue;
    graph_edges_.push_back(e);
    in_graph_[e] = 1;
    edge_length_[e] = diagram_.edge_length(e, c.t0, c.t1);
    edge_clearance_[e] = diagram_.edge_clearance(e, c.t0, c.t1);
    vertex_edges_[ed.vertex[0]].push_back(e);
    if (ed.vertex[1] != ed.vertex[0]) vertex_edges_[ed.vertex[1]].push_back(e);
  }
}

bool MotionPlanner::inside_obstacle(const Vec2d& x) const { return inside_->inside(x); }

double MotionPlanner::clearance(const Vec2d& x) const {
  double d = kInf;
  for (std::uint32_t s = 0; s < diagram_.num_sites(); ++s) d = std::min(d, diagram_.site_distance(s, x));
  return d;
}

double MotionPlanner::elementary_distance(std::uint32_t site, const Vec2d& x) const {
  if (!diagram_.is_segment(site)) return (x - diagram_.point(site)).norm();
  const auto s = diagram_.segment(static_cast<std::uint32_t>(site - diagram_.num_points()));
  const Vec2d a = diagram_.point(s[0]), d = diagram_.point(s[1]) - a;
  const double t = (x - a).dot(d) / d.squaredNorm();
  if (t < 0 || t > 1) return kInf;
  return std::abs(d[0] * (x - a)[1] - d[1] * (x - a)[0]) / d.norm();
}

void MotionPlanner::check_query(const Vec2d& p, const char* what) const {
  if (!p.allFinite()) throw Error(std::string("plan: the ") + what + " is not finite");
  if (!(p[0] > frame_.lo[0] && p[0] < frame_.hi[0] && p[1] > frame_.lo[1] && p[1] < frame_.hi[1]))
    throw Error(std::string("plan: the ") + what + " is outside the frame");
  if (inside_obstacle(p)) throw Error(std::string("plan: the ") + what + " is inside an obstacle");
}

// Moves p straight away from its nearest site until another site is as near:
// that point is on the diagram (on the edge between the two sites).
MotionPlanner::Retraction MotionPlanner::retract(const Vec2d& p) const {
  Retraction r;
  std::uint32_t s = 0;
  double d0 = kInf;
  for (std::uint32_t i = 0; i < diagram_.num_sites(); ++i) {
    const double d = elementary_distance(i, p);
    if (d < d0) d0 = d, s = i;
  }
  r.clearance = d0;
  if (!(d0 > 0)) return r;  // on an obstacle: not retractable (clearance 0)
  Vec2d c;
  if (!diagram_.is_segment(s)) {
    c = diagram_.point(s);
  } else {
    const auto sg = diagram_.segment(static_cast<std::uint32_t>(s - diagram_.num_points()));
    c = closest_point_on_segment(p, diagram_.point(sg[0]), diagram_.point(sg[1]));  // within it: elementary_distance chose s there
  }
  const Vec2d u = (p - c) / d0;
  double best = kInf;
  std::uint32_t first = kNone;
  for (std::uint32_t t = 0; t < diagram_.num_sites(); ++t) {
    if (t == s) continue;
    double l = kInf;
    if (!diagram_.is_segment(t)) {
      const Vec2d w = p - diagram_.point(t);
      const double den = 2 * (d0 - u.dot(w));
      if (den > 0) l = (w.squaredNorm() - d0 * d0) / den;
    } else {
      const auto sg = diagram_.segment(static_cast<std::uint32_t>(t - diagram_.num_points()));
      const Vec2d a = diagram_.point(sg[0]), b = diagram_.point(sg[1]);
      const Vec2d n = Vec2d(b[1] - a[1], a[0] - b[0]).normalized();
      const double h = n.dot(p - a), hu = n.dot(u);
      for (double sign : {1.0, -1.0}) {  // sign * (h + l hu) = d0 + l
        const double den = sign * hu - 1;
        if (den == 0) continue;
        const double cand = (d0 - sign * h) / den;
        if (cand >= 0 && cand < l && std::isfinite(elementary_distance(t, p + cand * u))) l = cand;
      }
    }
    if (l >= 0 && l < best) best = l, first = t;
  }
  if (first == kNone) return r;
  r.point = p + best * u;
  // The edge of (s, first) through that point.
  const auto it = pair_edges_.find(pair_key(s, first));
  if (it == pair_edges_.end()) return r;
  double best_gap = kInf;
  for (std::uint32_t e : it->second) {
    const auto c2 = diagram_.edge_curve(e);
    const double t = std::clamp((r.point - c2.origin).dot(c2.direction), c2.t0, c2.t1);
    if (!std::isfinite(t)) continue;
    const double gap = (c2.point(t) - r.point).norm();
    if (gap < best_gap) best_gap = gap, r.edge = e, r.t = t;
  }
  const double scale = (frame_.hi - frame_.lo).maxCoeff();
  if (best_gap > 1e-6 * scale) r.edge = kNone;
  return r;
}

struct MotionPlanner::Search {
  bool reached = false;
  double value = 0;  // length (shortest) or bottleneck clearance
  // The path as (edge, from parameter, to parameter) pieces, start to goal.
  std::vector<std::array<double, 3>> pieces;
};

// Dijkstra over the diagram's vertices plus the two retraction points (ids V
// and V + 1). Shortest mode: edges with clearance >= radius, by length.
// Bottleneck mode: maximizes the smallest clearance (radius unused).
MotionPlanner::Search MotionPlanner::search(const Retraction& s, const Retraction& g, double radius,
                                            bool bottleneck) const {
  Search out;
  const auto nv = static_cast<std::uint32_t>(diagram_.vertices().size());
  const std::uint32_t S = nv, G = nv + 1;
  const auto& edges = diagram_.edges();
  // Extra links: pieces of the retraction edges. (node, other node, edge, from t, to t)
  struct Link {
    std::uint32_t a, b, edge;
    double ta, tb;
  };
  std::vector<Link> links;
  auto add_parts = [&](const Retraction& r, std::uint32_t node) {
    if (r.edge == kNone) return;
    const auto c = diagram_.edge_curve(r.edge);
    const auto& ed = edges[r.edge];
    links.push_back({node, ed.vertex[1], r.edge, r.t, c.t0});
    links.push_back({node, ed.vertex[0], r.edge, r.t, c.t1});
  };
  if (s.edge == kNone || g.edge == kNone || !in_graph_[s.edge] || !in_graph_[g.edge]) return out;
  add_parts(s, S);
  add_parts(g, G);
  if (s.edge == g.edge) links.push_back({S, G, s.edge, s.t, g.t});
  std::vector<std::vector<std::uint32_t>> extra(nv + 2);
  for (std::uint32_t i = 0; i < links.size(); ++i) {
    extra[links[i].a].push_back(i);
    extra[links[i].b].push_back(i);
  }
  const std::size_t n = nv + 2;
  std::vector<double> best(n, bottleneck ? -kInf : kInf);
  std::vector<std::int64_t> via(n, -1);  // >= 0: diagram edge; < -1: link -(i + 2)
  std::vector<std::uint32_t> prev(n, kNone);
  using Item = std::pair<double, std::uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;  // keys: length, or -bottleneck
  best[S] = bottleneck ? kInf : 0;
  queue.push({bottleneck ? -kInf : 0, S});
  auto relax = [&](std::uint32_t from, std::uint32_t to, double weight, double clearance, std::int64_t how) {
    if (to == kNone) return;
    if (bottleneck) {
      const double v = std::min(best[from], clearance);
      if (v > best[to]) {
        best[to] = v, via[to] = how, prev[to] = from;
        queue.push({-v, to});
      }
    } else {
      if (clearance < radius) return;
      const double v = best[from] + weight;
      if (v < best[to]) {
        best[to] = v, via[to] = how, prev[to] = from;
        queue.push({v, to});
      }
    }
  };
  while (!queue.empty()) {
    const auto [key, u] = queue.top();
    queue.pop();
    if (key != (bottleneck ? -best[u] : best[u])) continue;
    if (u == G) break;
    if (u < nv) {
      for (std::uint32_t e : vertex_edges_[u]) {
        const auto& ed = edges[e];
        const std::uint32_t w = ed.vertex[0] == u ? ed.vertex[1] : ed.vertex[0];
        relax(u, w, edge_length_[e], edge_clearance_[e], e);
      }
    }
    for (std::uint32_t i : extra[u]) {
      const Link& l = links[i];
      const std::uint32_t w = l.a == u ? l.b : l.a;
      const double a = std::min(l.ta, l.tb), b = std::max(l.ta, l.tb);
      relax(u, w, diagram_.edge_length(l.edge, a, b), diagram_.edge_clearance(l.edge, a, b),
            -static_cast<std::int64_t>(i) - 2);
    }
  }
  if (bottleneck ? !(best[G] > -kInf) : !(best[G] < kInf)) return out;
  out.reached = true;
  out.value = best[G];
  // Walk back.
  for (std::uint32_t v = G; v != S; v = prev[v]) {
    const std::uint32_t u = prev[v];
    const std::int64_t how = via[v];
    if (how >= 0) {
      const auto e = static_cast<std::uint32_t>(how);
      const auto c = diagram_.edge_curve(e);
      const auto& ed = edges[e];
      // vertex[1] is at t0, vertex[0] at t1.
      const double from = ed.vertex[1] == u ? c.t0 : c.t1;
      const double to = from == c.t0 ? c.t1 : c.t0;
      out.pieces.push_back({static_cast<double>(e), from, to});
    } else {
      const Link& l = links[static_cast<std::size_t>(-how - 2)];
      const double from = l.a == u ? l.ta : l.tb;
      const double to = l.a == u ? l.tb : l.ta;
      out.pieces.push_back({static_cast<double>(l.edge), from, to});
    }
  }
  std::reverse(out.pieces.begin(), out.pieces.end());
  return out;
}

double MotionPlanner::max_radius(const Vec2d& start, const Vec2d& goal) const {
  check_query(start, "start");
  check_query(goal, "goal");
  const Retraction s = retract(start), g = retract(goal);
  const Search b = search(s, g, 0, true);
  if (!b.reached) return 0;
  return std::min({b.value, s.clearance, g.clearance});
}

PathPlan MotionPlanner::plan(const Vec2d& start, const Vec2d& goal, double radius) const {
  if (!(radius >= 0) || !std::isfinite(radius)) throw Error("plan: the radius must be finite and not negative");
  check_query(start, "start");
  check_query(goal, "goal");
  PathPlan out;
  const Retraction s = retract(start), g = retract(goal);
  const Search b = search(s, g, 0, true);
  out.max_radius = b.reached ? std::min({b.value, s.clearance, g.clearance}) : 0;
  if (s.clearance < radius) {
    out.reason = "start_too_close";
    return out;
  }
  if (g.clearance < radius) {
    out.reason = "goal_too_close";
    return out;
  }
  const Search p = search(s, g, radius, false);
  if (!p.reached) {
    out.reason = "disconnected";
    return out;
  }
  out.found = true;
  out.path.push_back(start);
  out.length = (s.point - start).norm() + p.value + (goal - g.point).norm();
  out.min_clearance = std::min(s.clearance, g.clearance);
  for (const auto& piece : p.pieces) {
    const auto e = static_cast<std::uint32_t>(piece[0]);
    out.min_clearance =
        std::min(out.min_clearance, diagram_.edge_clearance(e, std::min(piece[1], piece[2]), std::max(piece[1], piece[2])));
    for (const Vec2d& q : diagram_.sample_edge(e, piece[1], piece[2], options_.step))
      if ((q - out.path.back()).norm() > 0) out.path.push_back(q);
  }
  if ((goal - out.path.back()).norm() > 0) out.path.push_back(goal);
  return out;
}

PathPlan plan_path(const std::vector<std::vector<Vec2d>>& polygons, const Vec2d& start, const Vec2d& goal,
                   double radius, const PlanOptions& options) {
  if (!start.allFinite() || !goal.allFinite()) throw Error("plan: start and goal must be finite");
  return MotionPlanner(polygons, options, start, goal).plan(start, goal, radius);
}

}  // namespace geods::voronoi
