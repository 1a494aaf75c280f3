// Delaunay2: the points' bookkeeping (duplicates, removal, insertion order) and
// the public finite view around DelaunayCore, with its parts (see delaunay2.hpp).
// A Delaunay2 holds its arrays read only (FlatArray: its own, or views of a
// mapped file); construction, insert() and remove() change them as vectors in
// an Editor.
#include "geods/voronoi/delaunay2.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <type_traits>

#include "../core/prefault.hpp"
#include "brio_order.hpp"
#include "constrained_delaunay.hpp"
#include "exact_compare.hpp"
#include "geods/core/error.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/parallel.hpp"
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

// The hull vertices counter-clockwise (internal numbers), from the first ghost
// triangle in the arrays: the ghost triangles (x, y, ghost) around the hull,
// whose hull edge is y -> x, each sharing x with the next. `visit` ends a walk
// around a corrupt hull by throwing.
template <class Visit>
void walk_hull(const DelaunayView& mesh, Visit visit) {
  std::uint32_t start = kNone;
  for (std::uint32_t h = 0; h < mesh.vert.size() && start == kNone; ++h)
    if (mesh.vert[h] == kGhost) start = h;
  if (start == kNone) return;
  std::uint32_t g = start;
  do {
    visit(mesh.vert[DelaunayView::prev(g)]);
    g = DelaunayView::next(mesh.twin[g]);  // x -> ghost, then ghost -> z in the next ghost triangle
  } while (g != start);
}

// Runs check(first, last), which returns two counts, over the blocks of [0,
// count) in parallel and returns the counts summed. The geods::Error of the
// first block that fails is thrown again: the first violation in index order,
// however the threads ran.
template <class Check>
std::array<std::size_t, 2> check_in_blocks(std::size_t count, const Check& check) {
  constexpr std::size_t kBlock = std::size_t(1) << 15;
  const std::size_t blocks = (count + kBlock - 1) / kBlock;
  std::vector<std::array<std::size_t, 2>> counts(blocks, {0, 0});
  std::vector<std::optional<Error>> errors(blocks);
  parallel_for_each_index(
      0, blocks,
      [&](std::size_t b) {
        try {
          counts[b] = check(b * kBlock, std::min(count, (b + 1) * kBlock));
        } catch (const Error& e) {
          errors[b] = e;
        }
      },
      1);
  std::array<std::size_t, 2> total = {0, 0};
  for (std::size_t b = 0; b < blocks; ++b) {
    if (errors[b]) throw *errors[b];
    total[0] += counts[b][0], total[1] += counts[b][1];
  }
  return total;
}

}  // namespace

// The arrays as vectors while the triangulation changes: an Editor takes them
// from its Delaunay2 (moves them, or copies the views of a mapped file: the
// first change after load()) and gives them back when it goes, also when a
// change throws.
struct Delaunay2::Editor {
  explicit Editor(Delaunay2& dt);
  ~Editor();
  Editor(const Editor&) = delete;
  Editor& operator=(const Editor&) = delete;

  void init(std::span<const Vec2d> given, std::span<const Segment> given_segments, Options chosen);
  // With `touched`, the triangles the insertion touched are appended to it and
  // the public arrays are left as they were (the Inserter publishes once).
  std::uint32_t insert(const Vec2d& p, std::uint32_t start = kNone, std::vector<std::uint32_t>* touched = nullptr);
  void remove(std::uint32_t v);

  void build();
  template <class Location>
  void insert_all(Location& location);
  void build_degenerate();
  std::uint32_t add_vertex(std::uint32_t i);  // appends an internal vertex for point i
  template <class Hooks>
  void insert_vertex(std::uint32_t k, std::uint32_t start, Hooks& hooks);
  void insert_constraints();
  void publish();

  Delaunay2& dt;
  Options& options;
  std::vector<Segment>& segments;
  std::vector<std::uint32_t>& intersections;
  bool& has_constraints;
  std::size_t& dag_nodes;
  std::vector<Vec2d> points;
  std::vector<std::uint32_t> rep, original_of, internal_of;
  std::vector<std::uint8_t> fixed;
  DelaunayCore core;
  std::vector<std::uint32_t> triangles, halfedges, hull, public_triangle, internal_triangle;
  std::vector<std::uint8_t> constrained;
};

Delaunay2::Editor::Editor(Delaunay2& d)
    : dt(d),
      options(d.options_),
      segments(d.segments_),
      intersections(d.intersections_),
      has_constraints(d.has_constraints_),
      dag_nodes(d.dag_nodes_),
      points(std::move(d.points_).take_vector()),
      rep(std::move(d.rep_).take_vector()),
      original_of(std::move(d.original_of_).take_vector()),
      internal_of(std::move(d.internal_of_).take_vector()),
      fixed(std::move(d.fixed_).take_vector()),
      triangles(std::move(d.triangles_).take_vector()),
      halfedges(std::move(d.halfedges_).take_vector()),
      hull(std::move(d.hull_).take_vector()),
      public_triangle(std::move(d.public_triangle_).take_vector()),
      internal_triangle(std::move(d.internal_triangle_).take_vector()),
      constrained(std::move(d.constrained_).take_vector()) {
  core.coords = std::move(d.coords_).take_vector();
  core.vert = std::move(d.vert_).take_vector();
  core.twin = std::move(d.twin_).take_vector();
  core.free_triangles = std::move(d.free_triangles_).take_vector();
  core.vertex_edge = std::move(d.vertex_edge_).take_vector();
  core.last_triangle = d.last_triangle_;
  core.flips = d.flips_;
  core.walk_steps = d.walk_steps_;
}

Delaunay2::Editor::~Editor() {
  dt.points_ = std::move(points);
  dt.rep_ = std::move(rep);
  dt.original_of_ = std::move(original_of);
  dt.internal_of_ = std::move(internal_of);
  dt.fixed_ = std::move(fixed);
  dt.triangles_ = std::move(triangles);
  dt.halfedges_ = std::move(halfedges);
  dt.hull_ = std::move(hull);
  dt.public_triangle_ = std::move(public_triangle);
  dt.internal_triangle_ = std::move(internal_triangle);
  dt.constrained_ = std::move(constrained);
  dt.coords_ = std::move(core.coords);
  dt.vert_ = std::move(core.vert);
  dt.twin_ = std::move(core.twin);
  dt.free_triangles_ = std::move(core.free_triangles);
  dt.vertex_edge_ = std::move(core.vertex_edge);
  dt.last_triangle_ = core.last_triangle;
  dt.flips_ = core.flips;
  dt.walk_steps_ = core.walk_steps;
}

Delaunay2::Delaunay2(std::span<const Vec2d> points, Options options) { Editor(*this).init(points, {}, options); }

Delaunay2::Delaunay2(std::span<const Vec2d> points, std::span<const Segment> segments, Options options) {
  Editor(*this).init(points, segments, options);
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

void Delaunay2::Editor::init(std::span<const Vec2d> given, std::span<const Segment> given_segments, Options chosen) {
  if (given.size() >= (std::size_t(1) << 30))
    throw Error("Delaunay2: " + std::to_string(given.size()) + " points, at most 2^30 - 1 are supported");
  for (std::size_t i = 0; i < given.size(); ++i) require_finite(given[i], i, "Delaunay2");
  for (std::size_t k = 0; k < given_segments.size(); ++k) {
    const Segment& s = given_segments[k];
    if (s[0] >= given.size() || s[1] >= given.size())
      throw Error("Delaunay2: segment " + std::to_string(k) + " refers to point " +
                  std::to_string(std::max(s[0], s[1])) + ", but there are " + std::to_string(given.size()) + " points");
    if (s[0] == s[1])
      throw Error("Delaunay2: segment " + std::to_string(k) + " joins point " + std::to_string(s[0]) + " to itself");
  }
  points.assign(given.begin(), given.end());
  segments.assign(given_segments.begin(), given_segments.end());
  rep.resize(points.size());
  std::iota(rep.begin(), rep.end(), 0u);
  options = chosen;
  build();
}

// ------------------------------------------------------------------ building

void Delaunay2::Editor::build() {
  has_constraints = false;
  fixed.clear();
  std::vector<std::uint32_t> active;
  active.reserve(points.size());
  for (std::uint32_t i = 0; i < points.size(); ++i)
    if (rep[i] != kNone) active.push_back(rep[i] = i);
  original_of = brio_order(points, active, options.seed);
  if (options.location == Delaunay2Location::history_dag) {  // a random order instead: the DAG needs no locality
    Rng rng(options.seed);
    for (std::size_t k = original_of.size(); k > 1; --k) std::swap(original_of[k - 1], original_of[rng.below(k)]);
  }
  const std::uint32_t m = std::uint32_t(original_of.size());
  core.coords.resize(m);
  internal_of.assign(points.size(), kNone);
  for (std::uint32_t k = 0; k < m; ++k) {
    core.coords[k] = points[original_of[k]];
    internal_of[original_of[k]] = k;
  }
  if (!core.make_first_triangle()) {
    build_degenerate();
    return;
  }
  // The DAG serves construction only (updates may shrink the hull, which its cones assume never happens).
  std::optional<HistoryDag> dag;
  if (options.location == Delaunay2Location::history_dag) dag.emplace(core, m);
  if (dag && dag->usable()) {
    insert_all(*dag);
    dag_nodes = dag->nodes();
  } else {
    WalkFromLast walk{{}, &core};
    insert_all(walk);
    dag_nodes = 0;
  }
  // A point renamed to an earlier duplicate leaves a chain of representatives.
  for (std::uint32_t i = 0; i < rep.size(); ++i) {
    std::uint32_t r = rep[i];
    if (r == kNone) continue;
    while (rep[r] != r) r = rep[r];
    rep[i] = r;
  }
  publish();
  if (!segments.empty()) insert_constraints();
}

template <class Location>
void Delaunay2::Editor::insert_all(Location& location) {
  static_assert(InsertionLocation<Location>);
  const std::uint32_t a = core.vert[0], b = core.vert[1], c = core.vert[2];
  for (std::uint32_t k = 0; k < core.coords.size(); ++k)
    if (k != a && k != b && k != c) insert_vertex(k, location.start(core.at(k)), location);
}

template <class Hooks>
void Delaunay2::Editor::insert_vertex(std::uint32_t k, std::uint32_t start, Hooks& hooks) {
  const std::uint32_t j = core.insert_vertex(k, start, hooks);
  if (j == DelaunayCore::none) return;
  // k lies on vertex j: the first occurrence stands for all equal points.
  const std::uint32_t point = original_of[k], existing = original_of[j];
  if (point < existing) {
    original_of[j] = point;
    rep[existing] = point;
    rep[point] = point;
  } else {
    rep[point] = existing;
  }
  internal_of[point] = j;
}

std::uint32_t Delaunay2::Editor::add_vertex(std::uint32_t i) {
  const std::uint32_t k = std::uint32_t(core.coords.size());
  core.coords.push_back(points[i]);
  original_of.push_back(i);
  internal_of.push_back(k);
  core.vertex_edge.push_back(kNone);
  return k;
}

void Delaunay2::Editor::insert_constraints() {
  has_constraints = true;
  fixed.assign(core.vert.size(), 0);
  ConstrainedDelaunay constraints(core, fixed);
  ConstrainedDelaunay::Pending pending;
  for (auto it = segments.rbegin(); it != segments.rend(); ++it)
    pending.push_back({internal_of[rep[(*it)[0]]], internal_of[rep[(*it)[1]]]});
  while (!pending.empty()) {
    const auto [a, b] = pending.back();
    pending.pop_back();
    if (a == b) continue;
    const auto crossing = constraints.insert_segment(a, b, pending);
    if (!crossing) continue;
    // Both are split at the crossing, a new point; the four pieces are then segments of their own.
    const std::uint32_t i = std::uint32_t(points.size());
    if (i + 1 >= (std::uint32_t(1) << 30)) throw Error("Delaunay2: too many points");
    points.push_back(crossing->point);
    rep.push_back(i);
    insert_vertex(add_vertex(i), crossing->edge / 3, constraints);
    intersections.push_back(i);
    const std::uint32_t x = internal_of[i], u = crossing->u, w = crossing->w;
    for (auto piece : {std::pair{u, x}, std::pair{x, w}, std::pair{x, b}, std::pair{a, x}}) pending.push_back(piece);
  }
  publish();
}

void Delaunay2::Editor::build_degenerate() {
  core.vert.clear();
  core.twin.clear();
  core.free_triangles.clear();
  std::vector<std::uint32_t> active;
  for (std::uint32_t i = 0; i < points.size(); ++i)
    if (rep[i] != kNone) active.push_back(i);
  const auto& p = points;
  std::sort(active.begin(), active.end(), [&](std::uint32_t i, std::uint32_t j) {
    if (p[i][0] != p[j][0]) return p[i][0] < p[j][0];
    if (p[i][1] != p[j][1]) return p[i][1] < p[j][1];
    return i < j;
  });
  hull.clear();
  for (std::uint32_t i : active) {
    if (!hull.empty() && p[hull.back()] == p[i]) {
      rep[i] = hull.back();
    } else {
      rep[i] = i;
      hull.push_back(i);
    }
  }
  triangles.clear();
  halfedges.clear();
  public_triangle.clear();
  internal_triangle.clear();
  core.coords.clear();
  original_of.clear();
  internal_of.clear();
  core.vertex_edge.clear();
}

// ------------------------------------------------------------------ public view

void Delaunay2::Editor::publish() {
  const std::uint32_t internal = std::uint32_t(core.vert.size() / 3);
  // Fresh storage is mapped in one call, not a page fault per 4 KiB page as it is first written
  // (grown geometrically: insert() publishes after every point).
  const auto room = [](auto& v, std::size_t size) {
    if (v.capacity() < size) geods::detail::reserve_prefaulted(v, std::max(size, 2 * v.capacity()));
  };
  room(public_triangle, internal);
  public_triangle.assign(internal, kNone);
  internal_triangle.clear();
  room(internal_triangle, internal);
  for (std::uint32_t t = 0; t < internal; ++t) {
    if (core.vert[3 * t] == kNone || core.is_ghost_triangle(t)) continue;
    public_triangle[t] = std::uint32_t(internal_triangle.size());
    internal_triangle.push_back(t);
  }
  const std::size_t m = internal_triangle.size();
  room(triangles, 3 * m);
  room(halfedges, 3 * m);
  triangles.resize(3 * m);
  halfedges.resize(3 * m);
  constexpr std::size_t kAhead = 16;  // the neighbours' numbers and the points are read at random: ask ahead
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t t = internal_triangle[k];
    if (k + kAhead < m)
      for (std::uint32_t s = 0, u = internal_triangle[k + kAhead]; s < 3; ++s) {
        __builtin_prefetch(&public_triangle[core.twin[3 * u + s] / 3]);
        __builtin_prefetch(&original_of[core.vert[3 * u + s]]);
      }
    for (std::uint32_t s = 0; s < 3; ++s) {
      triangles[3 * k + s] = original_of[core.vert[3 * t + s]];
      const std::uint32_t f = core.twin[3 * t + s], other = public_triangle[f / 3];
      halfedges[3 * k + s] = other == kNone ? kNone : 3 * other + f % 3;
    }
  }
  constrained.assign(has_constraints ? 3 * m : 0, 0);
  if (has_constraints)
    for (std::size_t k = 0; k < m; ++k)
      for (std::uint32_t s = 0; s < 3; ++s) constrained[3 * k + s] = fixed[3 * internal_triangle[k] + s];
  room(core.vertex_edge, core.coords.size());
  core.vertex_edge.assign(core.coords.size(), kNone);
  for (std::uint32_t h = 0; h < core.vert.size(); ++h)
    if (core.vert[h] != kGhost && core.vert[h] != kNone) core.vertex_edge[core.vert[h]] = h;
  hull.clear();
  if (m == 0) return;
  walk_hull(core.view(), [&](std::uint32_t v) {
    hull.push_back(original_of[v]);
    if (hull.size() > points.size()) throw Error("Delaunay2: corrupt hull");
  });
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
  const DelaunayCore::Location loc = view().walk(q, start, nullptr);
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
  const std::uint32_t e = vertex_edge_[internal_of_[v]];
  std::uint32_t h = e;
  std::size_t after_ghost = 0;
  do {
    if (vert_[next(h)] != kGhost)
      result.push_back(original_of_[vert_[next(h)]]);
    else
      after_ghost = result.size();
    h = twin_[prev(h)];
  } while (h != e);
  std::rotate(result.begin(), result.begin() + std::ptrdiff_t(after_ghost), result.end());
  return result;
}

std::uint32_t Delaunay2::nearest(const Vec2d& q) const {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) throw Error("Delaunay2::nearest: query is not finite");
  if (internal_triangle_.empty()) {
    std::uint32_t best = kNone;
    for (std::uint32_t v : hull_)
      if (best == kNone || detail::WideSquaredNorm(points_[v] - q) < detail::WideSquaredNorm(points_[best] - q))
        best = v;
    return best;
  }
  // Distances that neither overflow nor underflow: the triangulation takes
  // any finite coordinates, so its nearest vertex must too.
  const auto distance = [&](std::uint32_t v) { return detail::WideSquaredNorm(coords_[v] - q); };
  const DelaunayCore::Location loc = view().walk(q, internal_triangle_[internal_triangle_.size() / 2], nullptr);
  std::uint32_t best = kNone;
  for (std::uint32_t h = loc.edge / 3 * 3; h < loc.edge / 3 * 3 + 3; ++h)
    if (vert_[h] != kGhost && (best == kNone || distance(vert_[h]) < distance(best))) best = vert_[h];
  // Greedy: a vertex with no closer Delaunay neighbour is a nearest one (q
  // lies in its Voronoi cell).
  detail::WideSquaredNorm best_distance = distance(best);
  for (bool improved = true; improved;) {
    improved = false;
    const std::uint32_t e = vertex_edge_[best];
    std::uint32_t h = e;
    do {
      const std::uint32_t w = vert_[next(h)];
      if (w != kGhost) {
        const detail::WideSquaredNorm d = distance(w);
        if (d < best_distance) {
          best = w, best_distance = d, improved = true;
          break;
        }
      }
      h = twin_[prev(h)];
    } while (h != e);
  }
  return original_of_[best];
}

// ------------------------------------------------------------------ updates

namespace {

// Hooks that note the triangles each step touches, then pass it on.
template <class Inner>
struct ChangeLog {
  Inner& inner;
  std::vector<std::uint32_t>& touched;
  void split_triangle(std::uint32_t t, std::uint32_t t1, std::uint32_t t2) {
    touched.insert(touched.end(), {t, t1, t2});
    inner.split_triangle(t, t1, t2);
  }
  void split_edge(std::uint32_t e, std::uint32_t twin, std::uint32_t t1, std::uint32_t t2) {
    touched.insert(touched.end(), {e / 3, twin / 3, t1, t2});
    inner.split_edge(e, twin, t1, t2);
  }
  void flip(std::uint32_t e, std::uint32_t f) {
    touched.insert(touched.end(), {e / 3, f / 3});
    inner.flip(e, f);
  }
  bool fixed(std::uint32_t e) const { return inner.fixed(e); }
};

}  // namespace

std::uint32_t Delaunay2::Editor::insert(const Vec2d& p, std::uint32_t start, std::vector<std::uint32_t>* touched) {
  require_finite(p, points.size(), "Delaunay2::insert");
  if (points.size() + 1 >= (std::size_t(1) << 30)) throw Error("Delaunay2::insert: too many points");
  const std::uint32_t i = std::uint32_t(points.size());
  points.push_back(p);
  rep.push_back(i);
  if (internal_triangle.empty()) {
    build();  // publishes
    if (touched)
      for (std::uint32_t t = 0; t < core.vert.size() / 3; ++t) touched->push_back(t);
    return i;
  }
  const std::uint32_t k = add_vertex(i);
  if (start == kNone) start = core.last_triangle;
  const auto insert_with = [&](auto& hooks) {
    if (touched) {
      ChangeLog<std::remove_reference_t<decltype(hooks)>> log{hooks, *touched};
      insert_vertex(k, start, log);
    } else {
      insert_vertex(k, start, hooks);
    }
  };
  if (has_constraints) {
    ConstrainedDelaunay constraints(core, fixed);
    insert_with(constraints);
  } else {
    NoHooks plain;
    insert_with(plain);
  }
  if (!touched) publish();
  return i;
}

void Delaunay2::Editor::remove(std::uint32_t v) {
  if (v >= points.size() || rep[v] == kNone)
    throw Error("Delaunay2::remove: point " + std::to_string(v) + " is not in the triangulation");
  if (!segments.empty()) throw Error("Delaunay2::remove: not supported on a constrained triangulation");
  if (rep[v] != v) {  // an alias: the triangulation does not change
    rep[v] = kNone;
    return;
  }
  std::uint32_t alias = kNone;
  for (std::uint32_t i = v + 1; i < rep.size() && alias == kNone; ++i)
    if (rep[i] == v) alias = i;
  if (alias != kNone) {  // the next equal point takes v's place
    for (std::uint32_t i = v + 1; i < rep.size(); ++i)
      if (rep[i] == v) rep[i] = alias;
    rep[v] = kNone;
    if (internal_triangle.empty()) {
      build_degenerate();
    } else {
      original_of[internal_of[v]] = alias;
      internal_of[v] = kNone;
      publish();
    }
    return;
  }
  rep[v] = kNone;
  const std::uint32_t internal = internal_of[v];
  internal_of[v] = kNone;
  if (internal_triangle.empty() || !remove_vertex(core, internal)) {
    build();
    return;
  }
  publish();
  if (internal_triangle.empty()) build();  // what is left is collinear
}

std::uint32_t Delaunay2::insert(const Vec2d& p) { return Editor(*this).insert(p); }

void Delaunay2::remove(std::uint32_t v) { Editor(*this).remove(v); }

// ------------------------------------------------------------------ Inserter

Delaunay2::Inserter::Inserter(Delaunay2& dt) : editor_(std::make_unique<Editor>(dt)) {}

Delaunay2::Inserter::~Inserter() {
  // The arrays changed without publish() unless the set is still degenerate.
  if (!editor_->internal_triangle.empty()) editor_->publish();
}

std::uint32_t Delaunay2::Inserter::insert(const Vec2d& p, std::uint32_t near) {
  const DelaunayCore& core = editor_->core;
  if (near != kNone && (near >= core.vert.size() / 3 || core.vert[3 * near] == DelaunayCore::none))
    throw Error("Delaunay2::Inserter::insert: " + std::to_string(near) + " is not a triangle handle");
  touched_.clear();
  const std::uint32_t i = editor_->insert(p, near, &touched_);
  std::sort(touched_.begin(), touched_.end());
  changed_.clear();
  for (std::size_t k = 0; k < touched_.size(); ++k) {
    const std::uint32_t t = touched_[k];
    if ((k > 0 && touched_[k - 1] == t) || core.vert[3 * t] == DelaunayCore::none || core.is_ghost_triangle(t)) continue;
    changed_.push_back({t, {core.at(core.vert[3 * t]), core.at(core.vert[3 * t + 1]), core.at(core.vert[3 * t + 2])}});
  }
  return i;
}

void Delaunay2::Inserter::reserve(std::size_t more) {
  Editor& e = *editor_;
  const std::size_t n = e.points.size() + more, half_edges = 6 * n + 12;  // a closed triangulation: 2n - 2 triangles
  const auto grow = [](auto& v, std::size_t size) { geods::detail::reserve_growing(v, size); };
  grow(e.points, n), grow(e.rep, n), grow(e.original_of, n), grow(e.internal_of, n);
  grow(e.core.coords, n), grow(e.core.vertex_edge, n), grow(e.core.vert, half_edges), grow(e.core.twin, half_edges);
}

void Delaunay2::Inserter::prefetch(std::uint32_t h) const {
  const DelaunayCore& core = editor_->core;
  if (h >= core.vert.size() / 3) return;
  // No reads: h's entries are not in cache yet (a triangle's three may straddle two lines).
  __builtin_prefetch(&core.vert[3 * h]), __builtin_prefetch(&core.vert[3 * h + 2]);
  __builtin_prefetch(&core.twin[3 * h], 1), __builtin_prefetch(&core.twin[3 * h + 2], 1);
}

void Delaunay2::Inserter::prefetch_neighbors(std::uint32_t h) const {
  const DelaunayCore& core = editor_->core;
  if (h >= core.vert.size() / 3) return;
  for (std::uint32_t e = 3 * h; e < 3 * h + 3; ++e)
    if (core.vert[e] < core.coords.size()) __builtin_prefetch(&core.coords[core.vert[e]]);
  for (std::uint32_t e = 3 * h; e < 3 * h + 3; ++e) {
    const std::uint32_t t = core.twin[e] / 3;
    if (3 * std::size_t(t) + 2 >= core.vert.size()) continue;
    // A triangle's three entries may straddle two lines.
    __builtin_prefetch(&core.vert[3 * t]), __builtin_prefetch(&core.vert[3 * t + 2]);
    __builtin_prefetch(&core.twin[3 * t], 1), __builtin_prefetch(&core.twin[3 * t + 2], 1);
  }
}

std::uint32_t Delaunay2::Inserter::handle_count() const { return std::uint32_t(editor_->core.vert.size() / 3); }

bool Delaunay2::Inserter::is_triangle(std::uint32_t h) const {
  const DelaunayCore& core = editor_->core;
  return h < core.vert.size() / 3 && core.vert[3 * h] != DelaunayCore::none && !core.is_ghost_triangle(h);
}

std::array<std::uint32_t, 3> Delaunay2::Inserter::triangle(std::uint32_t h) const {
  if (!is_triangle(h)) throw Error("Delaunay2::Inserter::triangle: " + std::to_string(h) + " is not a triangle handle");
  const auto& v = editor_->core.vert;
  const auto& o = editor_->original_of;
  return {o[v[3 * h]], o[v[3 * h + 1]], o[v[3 * h + 2]]};
}

std::span<const Vec2d> Delaunay2::Inserter::points() const { return editor_->points; }

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
  s.flips = flips_;
  s.walk_steps = walk_steps_;
  s.dag_nodes = dag_nodes_;
  s.bytes = (points_.size() + coords_.size()) * sizeof(Vec2d) +
            sizeof(std::uint32_t) * (rep_.size() + original_of_.size() + internal_of_.size() + vert_.size() + twin_.size() +
                                     free_triangles_.size() + vertex_edge_.size() + triangles_.size() + halfedges_.size() +
                                     hull_.size() + public_triangle_.size() + internal_triangle_.size());
  return s;
}

// The closed triangulation's combinatorics: twins, vertices, orientation, and
// vertex_edge (the last half-edge leaving each vertex, none for a vertex in no
// triangle: publish() keeps it so), which also tells which vertices are used.
// The vertices' links to their points are checked once per vertex, not per
// half-edge (the points are in input order, the vertices in insertion order, so
// those reads miss the cache); that each representative has a vertex follows
// by counting, since a vertex maps back to one representative of its own.
Delaunay2::TriangleCounts Delaunay2::check_triangles(std::size_t representatives) const {
  const auto fail = [](const std::string& what) { throw Error("Delaunay2::validate: " + what); };
  const std::size_t n = points_.size(), vertices = coords_.size();
  const std::uint32_t half_edges = std::uint32_t(vert_.size());
  if (twin_.size() != half_edges || half_edges % 3) fail("array sizes");
  if (has_constraints_ && fixed_.size() != half_edges) fail("constraint flags have the wrong size");
  if (original_of_.size() != vertices) fail("one point per vertex expected");
  if (vertex_edge_.size() != vertices) fail("one half-edge per vertex expected");
  // The twins and the vertices' half-edges are read at random (the checks are
  // bound by those misses): ask for them a few triangles ahead.
  const auto prefetch_twins = [&](std::uint32_t t) {
    if (t >= half_edges / 3) return;
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t f = twin_[e], v = vert_[e];
      if (f < half_edges) __builtin_prefetch(&twin_[f]), __builtin_prefetch(&vert_[f]);
      if (v < vertices) __builtin_prefetch(&vertex_edge_[v]);
    }
  };
  const auto [live, ghosts] = check_in_blocks(half_edges / 3, [&](std::uint32_t first, std::uint32_t last) {
    std::array<std::size_t, 2> counts = {0, 0};  // live, ghosts
    for (std::uint32_t t = first; t < last; ++t) {
      prefetch_twins(t + 8);
      if (vert_[3 * t] == kNone) {
        if (vert_[3 * t + 1] != kNone || vert_[3 * t + 2] != kNone) fail("triangle " + std::to_string(t) + " is partly free");
        continue;
      }
      ++counts[0];
      const bool ghost = view().is_ghost_triangle(t);
      counts[1] += ghost;
      if ((vert_[3 * t] == kGhost) + (vert_[3 * t + 1] == kGhost) + (vert_[3 * t + 2] == kGhost) > 1)
        fail("triangle " + std::to_string(t) + " has two ghost vertices");
      for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
        const std::uint32_t v = vert_[e], f = twin_[e];
        if (v != kGhost) {
          if (v >= vertices) fail("triangle " + std::to_string(t) + " uses a vertex that is not a representative");
          if (vertex_edge_[v] == kNone || vertex_edge_[v] < e) fail("vertex " + std::to_string(v) + " has the wrong half-edge");
        }
        if (f >= half_edges || twin_[f] != e || vert_[f] == kNone) fail("twin of half-edge " + std::to_string(e));
        if (vert_[f] != vert_[next(e)] || vert_[next(f)] != v) fail("twins of half-edge " + std::to_string(e) + " do not share their end points");
      }
      if (!ghost && !(orient2d(coords_[vert_[3 * t]], coords_[vert_[3 * t + 1]], coords_[vert_[3 * t + 2]]) > 0))
        fail("triangle " + std::to_string(t) + " is not counter-clockwise");
    }
    return counts;
  });
  // Each vertex in a triangle (its half-edge leaves it) stands for a
  // representative point at its place, which maps back to it.
  const std::size_t used = check_in_blocks(vertices, [&](std::uint32_t first, std::uint32_t last) {
    std::array<std::size_t, 2> counts = {0, 0};  // used vertices
    for (std::uint32_t v = first; v < last; ++v) {
      if (const std::uint32_t ahead = v + 16; ahead < last && original_of_[ahead] < n) {  // the points are read at random
        __builtin_prefetch(&rep_[original_of_[ahead]]), __builtin_prefetch(&internal_of_[original_of_[ahead]]);
        __builtin_prefetch(&points_[original_of_[ahead]]);
      }
      const std::uint32_t h = vertex_edge_[v];
      if (h == kNone) continue;
      if (h >= half_edges || vert_[h] != v) fail("vertex " + std::to_string(v) + " has a half-edge that does not leave it");
      const std::uint32_t o = original_of_[v];
      if (o >= n || rep_[o] != o || internal_of_[o] != v || points_[o] != coords_[v])
        fail("vertex " + std::to_string(v) + " is not a representative");
      ++counts[0];
    }
    return counts;
  })[0];
  if (used != representatives)
    fail(std::to_string(representatives - std::min(used, representatives)) + " points are in no triangle");
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
  const auto [live, ghosts] = check_triangles(vertices);
  check_public_view(live - ghosts);
  const std::uint32_t half_edges = std::uint32_t(vert_.size());
  // Locally Delaunay: the vertex opposite each edge is not inside the circle
  // (half-plane for a ghost triangle) of the triangle on the other side. With
  // ghost triangles this also says that the hull is convex.
  for (std::uint32_t e = 0; e < half_edges; ++e) {
    if (vert_[e] == kNone) continue;
    const std::uint32_t opposite = vert_[prev(twin_[e])];
    if (opposite == kGhost || (has_constraints_ && fixed_[e])) continue;
    if (view().in_conflict(e / 3, coords_[opposite]))
      fail("edge " + std::to_string(vert_[e]) + "-" + std::to_string(vert_[next(e)]) + " is not locally Delaunay");
  }
  if (has_constraints_) {
    for (std::uint32_t e = 0; e < half_edges; ++e)
      if (vert_[e] != kNone && fixed_[e] != fixed_[twin_[e]]) fail("constraint flags of twins differ");
    // Every input segment is a path of constrained edges through intersection
    // points (rounded, so slightly off it, and possibly onto another point,
    // whose vertex then stands for both) and through vertices on it or on its
    // pieces between them (so within that rounding of it).
    std::vector<char> crossing(coords_.size(), 0);
    for (std::uint32_t c : intersections_)
      if (c < rep_.size() && rep_[c] < internal_of_.size() && internal_of_[rep_[c]] != kNone)
        crossing[internal_of_[rep_[c]]] = 1;
    for (const Segment& seg : segments_) {
      const std::uint32_t a = internal_of_[rep_[seg[0]]], b = internal_of_[rep_[seg[1]]];
      if (a == kNone || b == kNone) fail("a segment end point is not a vertex");
      // Within the rounding of an intersection point (a few units in the last
      // place of the segment's coordinates) of the segment, and along it. In a
      // frame scaled by a power of two to the segment's length: products of
      // coordinates near 1e300 or 1e-300 would overflow or underflow.
      const Vec2d &pa = coords_[a], &pb = coords_[b];
      int exponent = 0;
      std::frexp((pb - pa).cwiseAbs().maxCoeff(), &exponent);
      const Vec2d d = DelaunayCore::scaled(pb - pa, -exponent);
      const double off = std::ldexp(16 * std::numeric_limits<double>::epsilon() *
                                        std::max(pa.cwiseAbs().maxCoeff(), pb.cwiseAbs().maxCoeff()),
                                    -exponent) *
                         d.norm();
      const auto on_segment = [&](const Vec2d& p) {
        const Vec2d q = DelaunayCore::scaled(p - pa, -exponent);
        const double along = d.dot(q);
        return std::abs(d[0] * q[1] - d[1] * q[0]) <= off && along > 0 && along < d.squaredNorm();
      };
      std::vector<std::uint32_t> queue{a};
      std::vector<char> seen(coords_.size(), 0);
      seen[a] = 1;
      for (std::size_t k = 0; k < queue.size() && !seen[b]; ++k) {
        const std::uint32_t start = vertex_edge_[queue[k]];
        std::uint32_t h = start;
        do {
          const std::uint32_t w = vert_[next(h)];
          if (fixed_[h] && w != kGhost && !seen[w] &&
              (w == b || crossing[w] || on_segment(coords_[w]))) {
            seen[w] = 1;
            queue.push_back(w);
          }
          h = twin_[prev(h)];
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
}

// The public view against the closed triangulation: each array is what
// publish() computes from it (finite triangles numbered in internal order).
void Delaunay2::check_public_view(std::size_t finite) const {
  const auto fail = [](const std::string& what) { throw Error("Delaunay2::validate: " + what); };
  const std::uint32_t half_edges = std::uint32_t(vert_.size());
  if (public_triangle_.size() != half_edges / 3 || internal_triangle_.size() != finite) fail("triangle maps have the wrong size");
  if (triangles_.size() != 3 * finite || halfedges_.size() != triangles_.size()) fail("public arrays have the wrong size");
  if (constrained_.size() != (has_constraints_ ? triangles_.size() : 0)) fail("public constraint flags have the wrong size");
  // Each finite triangle has a public number that maps back to it, and the
  // numbers follow the internal order: the numbering publish() makes.
  check_in_blocks(half_edges / 3, [&](std::uint32_t first, std::uint32_t last) {
    for (std::uint32_t t = first; t < last; ++t) {
      const std::uint32_t k = public_triangle_[t];
      if (vert_[3 * t] == kNone || view().is_ghost_triangle(t)) {
        if (k != kNone) fail("triangle " + std::to_string(t) + " is public but not finite");
      } else if (k >= finite || internal_triangle_[k] != t) {
        fail("internal triangle " + std::to_string(t) + " has no public number of its own");
      }
    }
    return std::array<std::size_t, 2>{0, 0};
  });
  check_in_blocks(finite, [&](std::uint32_t first, std::uint32_t last) {
    for (std::uint32_t k = first; k < last; ++k) {
      const std::uint32_t t = internal_triangle_[k];
      if (k > 0 && internal_triangle_[k - 1] >= t) fail("public triangle " + std::to_string(k) + " is out of order");
      for (std::uint32_t s = 0; s < 3; ++s) {
        const std::uint32_t e = 3 * k + s, f = twin_[3 * t + s], other = public_triangle_[f / 3];
        if (triangles_[e] != original_of_[vert_[3 * t + s]]) fail("public triangle " + std::to_string(k) + " differs");
        if (halfedges_[e] != (other == kNone ? kNone : 3 * other + f % 3)) fail("public half-edge " + std::to_string(e) + " differs");
        if (has_constraints_ && constrained_[e] != fixed_[3 * t + s]) fail("public constraint flag " + std::to_string(e) + " differs");
      }
    }
    return std::array<std::size_t, 2>{0, 0};
  });
  std::size_t h = 0;
  if (finite > 0)
    walk_hull(view(), [&](std::uint32_t v) {
      if (h >= hull_.size() || hull_[h] != original_of_[v]) fail("hull vertex " + std::to_string(h) + " differs");
      ++h;
    });
  if (h != hull_.size()) fail("the hull has " + std::to_string(hull_.size()) + " vertices, expected " + std::to_string(h));
}

}  // namespace geods::voronoi
