// Delaunay2: the points' bookkeeping (duplicates, removal, insertion order) and
// the public finite view around DelaunayCore, with its parts (see delaunay2.hpp).
#include "geods/voronoi/delaunay2.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "brio_order.hpp"
#include "constrained_delaunay.hpp"
#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"
#include "history_dag.hpp"
#include "point_location.hpp"
#include "vertex_removal.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = Delaunay2::no_edge;
constexpr std::uint32_t kGhost = DelaunayCore::ghost;

void require_finite(const Vec2d& p, std::size_t i, const char* who) {
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
    throw Error(std::string(who) + ": point " + std::to_string(i) + " has a NaN or infinite coordinate");
}

}  // namespace

Delaunay2::Delaunay2(std::span<const Vec2d> points, Options options) { init(points, {}, options); }

Delaunay2::Delaunay2(std::span<const Vec2d> points, std::span<const Segment> segments, Options options) {
  init(points, segments, options);
}

Delaunay2 Delaunay2::from_segment_ends(std::span<const Vec2d> points, std::span<const std::array<Vec2d, 2>> segments,
                                       Options options) {
  std::vector<Vec2d> all(points.begin(), points.end());
  std::vector<Segment> indices;
  for (const auto& [a, b] : segments) {
    indices.push_back({std::uint32_t(all.size()), std::uint32_t(all.size() + 1)});
    all.push_back(a);
    all.push_back(b);
  }
  return Delaunay2(all, indices, options);
}

void Delaunay2::init(std::span<const Vec2d> points, std::span<const Segment> segments, Options options) {
  if (points.size() >= (std::size_t(1) << 30))
    throw Error("Delaunay2: " + std::to_string(points.size()) + " points, at most 2^30 - 1 are supported");
  for (std::size_t i = 0; i < points.size(); ++i) require_finite(points[i], i, "Delaunay2");
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const Segment& s = segments[k];
    if (s[0] >= points.size() || s[1] >= points.size())
      throw Error("Delaunay2: segment " + std::to_string(k) + " refers to point " +
                  std::to_string(std::max(s[0], s[1])) + ", but there are " + std::to_string(points.size()) + " points");
    if (s[0] == s[1])
      throw Error("Delaunay2: segment " + std::to_string(k) + " joins point " + std::to_string(s[0]) + " to itself");
  }
  points_.assign(points.begin(), points.end());
  segments_.assign(segments.begin(), segments.end());
  rep_.resize(points_.size());
  std::iota(rep_.begin(), rep_.end(), 0u);
  options_ = options;
  build(options);
}

// ------------------------------------------------------------------ building

void Delaunay2::build(Options options) {
  has_constraints_ = false;
  fixed_.clear();
  std::vector<std::uint32_t> active;
  active.reserve(points_.size());
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (rep_[i] != kNone) active.push_back(rep_[i] = i);
  original_of_ = brio_order(points_, active, options.seed);
  if (options.location == Delaunay2Location::history_dag) {  // a random order instead: the DAG needs no locality
    Rng rng(options.seed);
    for (std::size_t k = original_of_.size(); k > 1; --k) std::swap(original_of_[k - 1], original_of_[rng.below(k)]);
  }
  const std::uint32_t m = std::uint32_t(original_of_.size());
  core_.coords.resize(m);
  internal_of_.assign(points_.size(), kNone);
  for (std::uint32_t k = 0; k < m; ++k) {
    core_.coords[k] = points_[original_of_[k]];
    internal_of_[original_of_[k]] = k;
  }
  if (!core_.make_first_triangle()) {
    build_degenerate();
    return;
  }
  // The DAG serves construction only (updates may shrink the hull, which its cones assume never happens).
  std::optional<HistoryDag> dag;
  if (options.location == Delaunay2Location::history_dag) dag.emplace(core_, m);
  if (dag && dag->usable()) {
    insert_all(*dag);
    dag_nodes_ = dag->nodes();
  } else {
    WalkFromLast walk{{}, &core_};
    insert_all(walk);
    dag_nodes_ = 0;
  }
  // A point renamed to an earlier duplicate leaves a chain of representatives.
  for (std::uint32_t i = 0; i < rep_.size(); ++i) {
    std::uint32_t r = rep_[i];
    if (r == kNone) continue;
    while (rep_[r] != r) r = rep_[r];
    rep_[i] = r;
  }
  publish();
  if (!segments_.empty()) insert_constraints();
}

template <class Location>
void Delaunay2::insert_all(Location& location) {
  static_assert(InsertionLocation<Location>);
  const std::uint32_t a = core_.vert[0], b = core_.vert[1], c = core_.vert[2];
  for (std::uint32_t k = 0; k < core_.coords.size(); ++k)
    if (k != a && k != b && k != c) insert_vertex(k, location.start(core_.at(k)), location);
}

template <class Hooks>
void Delaunay2::insert_vertex(std::uint32_t k, std::uint32_t start, Hooks& hooks) {
  const std::uint32_t j = core_.insert_vertex(k, start, hooks);
  if (j == DelaunayCore::none) return;
  // k lies on vertex j: the first occurrence stands for all equal points.
  const std::uint32_t point = original_of_[k], existing = original_of_[j];
  if (point < existing) {
    original_of_[j] = point;
    rep_[existing] = point;
    rep_[point] = point;
  } else {
    rep_[point] = existing;
  }
  internal_of_[point] = j;
}

std::uint32_t Delaunay2::add_vertex(std::uint32_t i) {
  const std::uint32_t k = std::uint32_t(core_.coords.size());
  core_.coords.push_back(points_[i]);
  original_of_.push_back(i);
  internal_of_.push_back(k);
  core_.vertex_edge.push_back(kNone);
  return k;
}

void Delaunay2::insert_constraints() {
  has_constraints_ = true;
  fixed_.assign(core_.vert.size(), 0);
  ConstrainedDelaunay constraints(core_, fixed_);
  ConstrainedDelaunay::Pending pending;
  for (auto it = segments_.rbegin(); it != segments_.rend(); ++it)
    pending.push_back({internal_of_[rep_[(*it)[0]]], internal_of_[rep_[(*it)[1]]]});
  while (!pending.empty()) {
    const auto [a, b] = pending.back();
    pending.pop_back();
    if (a == b) continue;
    const auto crossing = constraints.insert_segment(a, b, pending);
    if (!crossing) continue;
    // Both are split at the crossing, a new point; the four pieces are then segments of their own.
    const std::uint32_t i = std::uint32_t(points_.size());
    if (i + 1 >= (std::uint32_t(1) << 30)) throw Error("Delaunay2: too many points");
    points_.push_back(crossing->point);
    rep_.push_back(i);
    insert_vertex(add_vertex(i), crossing->edge / 3, constraints);
    intersections_.push_back(i);
    const std::uint32_t x = internal_of_[i], u = crossing->u, w = crossing->w;
    for (auto piece : {std::pair{u, x}, std::pair{x, w}, std::pair{x, b}, std::pair{a, x}}) pending.push_back(piece);
  }
  publish();
}

void Delaunay2::build_degenerate() {
  core_.vert.clear();
  core_.twin.clear();
  core_.free_triangles.clear();
  std::vector<std::uint32_t> active;
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (rep_[i] != kNone) active.push_back(i);
  const auto& p = points_;
  std::sort(active.begin(), active.end(), [&](std::uint32_t i, std::uint32_t j) {
    if (p[i][0] != p[j][0]) return p[i][0] < p[j][0];
    if (p[i][1] != p[j][1]) return p[i][1] < p[j][1];
    return i < j;
  });
  hull_.clear();
  for (std::uint32_t i : active) {
    if (!hull_.empty() && p[hull_.back()] == p[i]) {
      rep_[i] = hull_.back();
    } else {
      rep_[i] = i;
      hull_.push_back(i);
    }
  }
  triangles_.clear();
  halfedges_.clear();
  public_triangle_.clear();
  internal_triangle_.clear();
  core_.coords.clear();
  original_of_.clear();
  internal_of_.clear();
  core_.vertex_edge.clear();
}

// ------------------------------------------------------------------ public view

void Delaunay2::publish() {
  const std::uint32_t internal = std::uint32_t(core_.vert.size() / 3);
  public_triangle_.assign(internal, kNone);
  internal_triangle_.clear();
  for (std::uint32_t t = 0; t < internal; ++t) {
    if (core_.vert[3 * t] == kNone || core_.is_ghost_triangle(t)) continue;
    public_triangle_[t] = std::uint32_t(internal_triangle_.size());
    internal_triangle_.push_back(t);
  }
  const std::size_t m = internal_triangle_.size();
  triangles_.resize(3 * m);
  halfedges_.resize(3 * m);
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t t = internal_triangle_[k];
    for (std::uint32_t s = 0; s < 3; ++s) {
      triangles_[3 * k + s] = original_of_[core_.vert[3 * t + s]];
      const std::uint32_t f = core_.twin[3 * t + s], other = public_triangle_[f / 3];
      halfedges_[3 * k + s] = other == kNone ? kNone : 3 * other + f % 3;
    }
  }
  constrained_.assign(has_constraints_ ? 3 * m : 0, 0);
  if (has_constraints_)
    for (std::size_t k = 0; k < m; ++k)
      for (std::uint32_t s = 0; s < 3; ++s) constrained_[3 * k + s] = fixed_[3 * internal_triangle_[k] + s];
  core_.vertex_edge.assign(core_.coords.size(), kNone);
  for (std::uint32_t h = 0; h < core_.vert.size(); ++h)
    if (core_.vert[h] != kGhost && core_.vert[h] != kNone) core_.vertex_edge[core_.vert[h]] = h;
  hull_.clear();
  if (m == 0) return;
  // Walk the ghost triangles (x, y, ghost) around the hull: the hull edge of
  // each is y -> x, and the next one shares x.
  std::uint32_t start = kNone;
  for (std::uint32_t h = 0; h < core_.vert.size() && start == kNone; ++h)
    if (core_.vert[h] == kGhost) start = h;
  std::uint32_t g = start;
  do {
    hull_.push_back(original_of_[core_.vert[prev(g)]]);
    g = next(core_.twin[g]);  // x -> ghost, then ghost -> z in the next ghost triangle
    if (hull_.size() > points_.size()) throw Error("Delaunay2: corrupt hull");
  } while (g != start);
}

// ------------------------------------------------------------------ queries

std::uint32_t Delaunay2::representative(std::uint32_t i) const {
  if (i >= rep_.size()) throw Error("Delaunay2::representative: point " + std::to_string(i) + " does not exist");
  return rep_[i];
}

std::size_t Delaunay2::duplicate_count() const {
  std::size_t count = 0;
  for (std::uint32_t i = 0; i < rep_.size(); ++i) count += rep_[i] != kNone && rep_[i] != i;
  return count;
}

std::uint32_t Delaunay2::locate(const Vec2d& q, std::uint32_t hint) const {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) throw Error("Delaunay2::locate: query is not finite");
  if (internal_triangle_.empty()) return kNone;
  if (hint != kNone && hint >= internal_triangle_.size())
    throw Error("Delaunay2::locate: hint " + std::to_string(hint) + " is not a triangle");
  const std::uint32_t start = internal_triangle_[hint != kNone ? hint : internal_triangle_.size() / 2];
  const DelaunayCore::Location loc = core_.walk(q, start, nullptr);
  return loc.where == DelaunayCore::Where::outside ? kNone : public_triangle_[loc.edge / 3];
}

std::vector<std::uint32_t> Delaunay2::neighbors(std::uint32_t v) const {
  if (v >= points_.size()) throw Error("Delaunay2::neighbors: point " + std::to_string(v) + " does not exist");
  std::vector<std::uint32_t> result;
  if (internal_triangle_.empty()) {  // the sorted points of a degenerate set form a path
    const auto it = std::find(hull_.begin(), hull_.end(), v);
    if (it != hull_.end()) {
      if (it != hull_.begin()) result.push_back(*(it - 1));
      if (it + 1 != hull_.end()) result.push_back(*(it + 1));
    }
    return result;
  }
  if (rep_[v] != v) return result;
  const std::uint32_t e = core_.vertex_edge[internal_of_[v]];
  std::uint32_t h = e;
  std::size_t after_ghost = 0;
  do {
    if (core_.vert[next(h)] != kGhost)
      result.push_back(original_of_[core_.vert[next(h)]]);
    else
      after_ghost = result.size();
    h = core_.twin[prev(h)];
  } while (h != e);
  std::rotate(result.begin(), result.begin() + std::ptrdiff_t(after_ghost), result.end());
  return result;
}

std::uint32_t Delaunay2::nearest(const Vec2d& q) const {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) throw Error("Delaunay2::nearest: query is not finite");
  if (internal_triangle_.empty()) {
    std::uint32_t best = kNone;
    for (std::uint32_t v : hull_)
      if (best == kNone || (points_[v] - q).squaredNorm() < (points_[best] - q).squaredNorm()) best = v;
    return best;
  }
  const auto distance = [&](std::uint32_t v) { return (core_.at(v) - q).squaredNorm(); };
  const DelaunayCore::Location loc = core_.walk(q, internal_triangle_[internal_triangle_.size() / 2], nullptr);
  std::uint32_t best = kNone;
  for (std::uint32_t h = loc.edge / 3 * 3; h < loc.edge / 3 * 3 + 3; ++h)
    if (core_.vert[h] != kGhost && (best == kNone || distance(core_.vert[h]) < distance(best))) best = core_.vert[h];
  // Greedy: a vertex with no closer Delaunay neighbour is a nearest one (q
  // lies in its Voronoi cell).
  double best_distance = distance(best);
  for (bool improved = true; improved;) {
    improved = false;
    const std::uint32_t e = core_.vertex_edge[best];
    std::uint32_t h = e;
    do {
      const std::uint32_t w = core_.vert[next(h)];
      if (w != kGhost) {
        const double d = distance(w);
        if (d < best_distance) {
          best = w, best_distance = d, improved = true;
          break;
        }
      }
      h = core_.twin[prev(h)];
    } while (h != e);
  }
  return original_of_[best];
}

// ------------------------------------------------------------------ updates

std::uint32_t Delaunay2::insert(const Vec2d& p) {
  require_finite(p, points_.size(), "Delaunay2::insert");
  if (points_.size() + 1 >= (std::size_t(1) << 30)) throw Error("Delaunay2::insert: too many points");
  const std::uint32_t i = std::uint32_t(points_.size());
  points_.push_back(p);
  rep_.push_back(i);
  if (internal_triangle_.empty()) {
    build(options_);
  } else {
    const std::uint32_t k = add_vertex(i);
    if (has_constraints_) {
      ConstrainedDelaunay constraints(core_, fixed_);
      insert_vertex(k, core_.last_triangle, constraints);
    } else {
      NoHooks plain;
      insert_vertex(k, core_.last_triangle, plain);
    }
    publish();
  }
  return i;
}

void Delaunay2::remove(std::uint32_t v) {
  if (v >= points_.size() || rep_[v] == kNone)
    throw Error("Delaunay2::remove: point " + std::to_string(v) + " is not in the triangulation");
  if (!segments_.empty()) throw Error("Delaunay2::remove: not supported on a constrained triangulation");
  if (rep_[v] != v) {  // an alias: the triangulation does not change
    rep_[v] = kNone;
    return;
  }
  std::uint32_t alias = kNone;
  for (std::uint32_t i = v + 1; i < rep_.size() && alias == kNone; ++i)
    if (rep_[i] == v) alias = i;
  if (alias != kNone) {  // the next equal point takes v's place
    for (std::uint32_t i = v + 1; i < rep_.size(); ++i)
      if (rep_[i] == v) rep_[i] = alias;
    rep_[v] = kNone;
    if (internal_triangle_.empty()) {
      build_degenerate();
    } else {
      original_of_[internal_of_[v]] = alias;
      internal_of_[v] = kNone;
      publish();
    }
    return;
  }
  rep_[v] = kNone;
  const std::uint32_t internal = internal_of_[v];
  internal_of_[v] = kNone;
  if (internal_triangle_.empty() || !remove_vertex(core_, internal)) {
    build(options_);
    return;
  }
  publish();
  if (internal_triangle_.empty()) build(options_);  // what is left is collinear
}

std::vector<std::uint8_t> Delaunay2::inside() const {
  // Even-odd: a breadth-first search from the hull, the parity flipping across
  // each constrained edge.
  const std::size_t m = triangle_count();
  std::vector<std::uint8_t> parity(m, 2);
  std::vector<std::uint32_t> queue;
  for (std::uint32_t e = 0; e < 3 * m; ++e)
    if (halfedges_[e] == kNone && parity[e / 3] == 2) {
      parity[e / 3] = constrained_.empty() ? 0 : constrained_[e];
      queue.push_back(e / 3);
    }
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const std::uint32_t t = queue[k];
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t f = halfedges_[e];
      if (f == kNone || parity[f / 3] != 2) continue;
      parity[f / 3] = std::uint8_t(parity[t] ^ (constrained_.empty() ? 0 : constrained_[e]));
      queue.push_back(f / 3);
    }
  }
  return parity;
}

std::vector<Delaunay2::Segment> Delaunay2::constrained_edges() const {
  std::vector<Segment> edges;
  for (std::uint32_t e = 0; e < constrained_.size(); ++e)
    if (constrained_[e] && (halfedges_[e] == kNone || e < halfedges_[e]))
      edges.push_back({triangles_[e], triangles_[next(e)]});
  return edges;
}

// ------------------------------------------------------------------ inspection

Delaunay2Stats Delaunay2::stats() const {
  Delaunay2Stats s;
  s.points = points_.size();
  for (std::uint32_t i = 0; i < rep_.size(); ++i) {
    s.vertices += rep_[i] == i;
    s.duplicates += rep_[i] != kNone && rep_[i] != i;
    s.removed += rep_[i] == kNone;
  }
  s.triangles = triangle_count();
  s.hull = hull_.size();
  s.flips = core_.flips;
  s.walk_steps = core_.walk_steps;
  s.dag_nodes = dag_nodes_;
  s.bytes = (points_.capacity() + core_.coords.capacity()) * sizeof(Vec2d) +
            sizeof(std::uint32_t) * (rep_.capacity() + original_of_.capacity() + internal_of_.capacity() + core_.vert.capacity() + core_.twin.capacity() +
                                     core_.free_triangles.capacity() + core_.vertex_edge.capacity() + triangles_.capacity() +
                                     halfedges_.capacity() + hull_.capacity() + public_triangle_.capacity() +
                                     internal_triangle_.capacity());
  return s;
}

// The closed triangulation's combinatorics: twins, vertices, orientation. The
// vertices' links to their points are checked once per vertex, not per
// half-edge: the points are in input order, the vertices in insertion order, so
// those reads miss the cache (they were most of load()'s time).
Delaunay2::TriangleCounts Delaunay2::check_triangles() const {
  const auto fail = [](const std::string& what) { throw Error("Delaunay2::validate: " + what); };
  const std::size_t n = points_.size(), vertices = core_.coords.size();
  const std::uint32_t half_edges = std::uint32_t(core_.vert.size());
  if (core_.twin.size() != half_edges || half_edges % 3) fail("array sizes");
  if (has_constraints_ && fixed_.size() != half_edges) fail("constraint flags have the wrong size");
  if (original_of_.size() != vertices) fail("one point per vertex expected");
  std::size_t live = 0, ghosts = 0;
  std::vector<char> used(vertices, 0);
  for (std::uint32_t t = 0; t < half_edges / 3; ++t) {
    if (core_.vert[3 * t] == kNone) continue;
    ++live;
    const bool ghost = core_.is_ghost_triangle(t);
    ghosts += ghost;
    if ((core_.vert[3 * t] == kGhost) + (core_.vert[3 * t + 1] == kGhost) + (core_.vert[3 * t + 2] == kGhost) > 1)
      fail("triangle " + std::to_string(t) + " has two ghost vertices");
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t v = core_.vert[e], f = core_.twin[e];
      if (v != kGhost) {
        if (v >= vertices) fail("triangle " + std::to_string(t) + " uses a vertex that is not a representative");
        used[v] = 1;
      }
      if (f >= half_edges || core_.twin[f] != e || core_.vert[f] == kNone) fail("twin of half-edge " + std::to_string(e));
      if (core_.vert[f] != core_.vert[next(e)] || core_.vert[next(f)] != v) fail("twins of half-edge " + std::to_string(e) + " do not share their end points");
    }
    if (!ghost && !(orient2d(core_.at(core_.vert[3 * t]), core_.at(core_.vert[3 * t + 1]), core_.at(core_.vert[3 * t + 2])) > 0))
      fail("triangle " + std::to_string(t) + " is not counter-clockwise");
  }
  // Each vertex in a triangle stands for a representative point at its place,
  // which maps back to it; each representative has such a vertex.
  for (std::uint32_t v = 0; v < vertices; ++v) {
    if (!used[v]) continue;
    const std::uint32_t o = original_of_[v];
    if (o >= n || rep_[o] != o || internal_of_[o] != v || points_[o] != core_.coords[v])
      fail("vertex " + std::to_string(v) + " is not a representative");
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (rep_[i] != i) continue;
    const std::uint32_t v = i < internal_of_.size() ? internal_of_[i] : kNone;
    if (v >= vertices || !used[v] || original_of_[v] != i) fail("point " + std::to_string(i) + " is in no triangle");
  }
  return {live, ghosts};
}

std::size_t Delaunay2::check_representatives() const {
  const auto fail = [](const std::string& what) { throw Error("Delaunay2::validate: " + what); };
  const std::size_t n = points_.size();
  if (rep_.size() != n) fail("one representative per point expected");
  std::size_t vertices = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = rep_[i];
    if (r == kNone) continue;
    if (r > i || rep_[r] != r) fail("point " + std::to_string(i) + " has a bad representative");
    if (points_[r] != points_[i]) fail("point " + std::to_string(i) + " differs from its representative");
    vertices += r == i;
  }
  return vertices;
}

void Delaunay2::validate() const {
  const auto fail = [](const std::string& what) { throw Error("Delaunay2::validate: " + what); };
  const std::size_t vertices = check_representatives();
  if (internal_triangle_.empty()) {
    const auto at = [&](std::uint32_t i) { return points_[i]; };
    if (!triangles_.empty() || !halfedges_.empty()) fail("degenerate set with triangles");
    if (hull_.size() != vertices) fail("degenerate hull does not list every distinct point");
    for (std::size_t k = 0; k < hull_.size(); ++k) {
      if (rep_[hull_[k]] != hull_[k]) fail("degenerate hull lists a non-representative");
      if (k > 0 && !(at(hull_[k - 1])[0] < at(hull_[k])[0] ||
                     (at(hull_[k - 1])[0] == at(hull_[k])[0] && at(hull_[k - 1])[1] < at(hull_[k])[1])))
        fail("degenerate hull is not sorted");
      if (k > 1 && orient2d(at(hull_[0]), at(hull_[1]), at(hull_[k])) != 0)
        fail("degenerate set is not collinear");
    }
    return;
  }
  const auto [live, ghosts] = check_triangles();
  const std::uint32_t half_edges = std::uint32_t(core_.vert.size());
  // Locally Delaunay: the vertex opposite each edge is not inside the circle
  // (half-plane for a ghost triangle) of the triangle on the other side. With
  // ghost triangles this also says that the hull is convex.
  for (std::uint32_t e = 0; e < half_edges; ++e) {
    if (core_.vert[e] == kNone) continue;
    const std::uint32_t opposite = core_.vert[prev(core_.twin[e])];
    if (opposite == kGhost || (has_constraints_ && fixed_[e])) continue;
    if (core_.in_conflict(e / 3, core_.at(opposite)))
      fail("edge " + std::to_string(core_.vert[e]) + "-" + std::to_string(core_.vert[next(e)]) + " is not locally Delaunay");
  }
  if (has_constraints_) {
    for (std::uint32_t e = 0; e < half_edges; ++e)
      if (core_.vert[e] != kNone && fixed_[e] != fixed_[core_.twin[e]]) fail("constraint flags of twins differ");
    // Every input segment is a path of constrained edges through vertices on
    // it or through intersection points (rounded, so slightly off it).
    std::vector<std::uint32_t> crossings = intersections_;
    std::sort(crossings.begin(), crossings.end());
    for (const Segment& seg : segments_) {
      const std::uint32_t a = internal_of_[rep_[seg[0]]], b = internal_of_[rep_[seg[1]]];
      if (a == kNone || b == kNone) fail("a segment end point is not a vertex");
      std::vector<std::uint32_t> queue{a};
      std::vector<char> seen(core_.coords.size(), 0);
      seen[a] = 1;
      for (std::size_t k = 0; k < queue.size() && !seen[b]; ++k) {
        const std::uint32_t start = core_.vertex_edge[queue[k]];
        std::uint32_t h = start;
        do {
          const std::uint32_t w = core_.vert[next(h)];
          if (fixed_[h] && w != kGhost && !seen[w] &&
              (w == b || std::binary_search(crossings.begin(), crossings.end(), original_of_[w]) ||
               (orient2d(core_.at(a), core_.at(b), core_.at(w)) == 0 && DelaunayCore::strictly_between(core_.at(a), core_.at(b), core_.at(w))))) {
            seen[w] = 1;
            queue.push_back(w);
          }
          h = core_.twin[prev(h)];
        } while (h != start);
      }
      if (!seen[b]) fail("segment " + std::to_string(seg[0]) + "-" + std::to_string(seg[1]) + " is not present");
    }
  }
  // Euler on the sphere (ghost vertex included): t = 2 (n + 1) - 4; hull size = ghost triangles.
  const std::size_t finite = live - ghosts;
  if (live != 2 * (vertices + 1) - 4) fail("Euler's formula fails for the closed triangulation");
  if (finite != 2 * vertices - hull_.size() - 2) fail("t = 2n - h - 2 fails");
  if (hull_.size() != ghosts) fail("hull size differs from the number of hull edges");
  // The public arrays.
  if (triangles_.size() != 3 * finite || halfedges_.size() != triangles_.size()) fail("public arrays have the wrong size");
  for (std::size_t k = 0; k < finite; ++k) {
    const std::uint32_t t = internal_triangle_[k];
    for (std::uint32_t s = 0; s < 3; ++s) {
      const std::uint32_t e = std::uint32_t(3 * k + s);
      if (triangles_[e] != original_of_[core_.vert[3 * t + s]]) fail("public triangle " + std::to_string(k) + " differs");
      const std::uint32_t h = halfedges_[e];
      if (h == kNone) {
        if (!core_.is_ghost_triangle(core_.twin[3 * t + s] / 3)) fail("public hull edge inside the triangulation");
      } else if (h >= halfedges_.size() || halfedges_[h] != e) {
        fail("public halfedges are not symmetric");
      }
    }
  }
}

}  // namespace geods::voronoi
