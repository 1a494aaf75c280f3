#pragma once
// The core of Delaunay2 (seed §5.1.2, §5.2): a triangulation in flat half-edge
// arrays closed by a ghost vertex at infinity, grown one point at a time by the
// four steps of incremental insertion: walk to the point, split the triangle or
// edge it falls in, flip the edges that are no longer locally Delaunay
// (legalize), repeat. Delaunay2 publishes the finite triangles.
//
// Half-edge e of triangle e / 3 runs from vert[e] to vert[next(e)]; twin[e] is
// the opposite half-edge. Every hull edge has a ghost triangle (x, y, ghost) on
// its outer side, so insertion outside the hull, on it and inside are the same
// steps. Coordinates are indexed by internal vertex (Delaunay2 numbers them in
// insertion order).
//
// The parts kept beside the triangulation (the history DAG, constrained-edge
// marks) follow its changes through Hooks: after each split and flip the core
// calls them, and legalize() asks them which edges must not flip. NoHooks is
// the plain path; the calls compile away.
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "geods/core/predicates.hpp"
#include "geods/core/vec.hpp"

namespace geods::voronoi {

/// Hooks that ignore every change: plain Delaunay insertion.
struct NoHooks {
  void split_triangle(std::uint32_t /*t*/, std::uint32_t /*t1*/, std::uint32_t /*t2*/) {}
  void split_edge(std::uint32_t /*e*/, std::uint32_t /*twin*/, std::uint32_t /*t1*/, std::uint32_t /*t2*/) {}
  void flip(std::uint32_t /*e*/, std::uint32_t /*f*/) {}
  bool fixed(std::uint32_t /*e*/) const { return false; }
};

/// The vocabulary of the closed half-edge arrays, shared by the core that
/// builds them and the view that queries them.
struct DelaunayHalfEdges {
  static constexpr std::uint32_t none = std::uint32_t(-1);
  static constexpr std::uint32_t ghost = std::uint32_t(-2);    // the vertex at infinity
  static constexpr std::uint32_t ghost_bit = 1u << 31;         // set in ghost, never in a vertex

  static std::uint32_t next(std::uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }
  static std::uint32_t prev(std::uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }
  /// p strictly between a and b, for p on the line through a != b.
  static bool strictly_between(const Vec2d& a, const Vec2d& b, const Vec2d& p) {
    if (a[0] != b[0]) return (a[0] < p[0] && p[0] < b[0]) || (b[0] < p[0] && p[0] < a[0]);
    return (a[1] < p[1] && p[1] < b[1]) || (b[1] < p[1] && p[1] < a[1]);
  }
  /// p times 2^exponent, exactly (short of overflow or underflow): a frame in
  /// which products of coordinates near 1e300 or 1e-300 stay in range.
  static Vec2d scaled(const Vec2d& p, int exponent) {
    return {std::ldexp(p[0], exponent), std::ldexp(p[1], exponent)};
  }

  enum class Where { inside, on_edge, on_vertex, outside };
  struct Location {
    Where where;
    std::uint32_t edge;  // inside: any half-edge of the triangle; on_edge: the edge;
                         // on_vertex: a half-edge leaving the vertex; outside: the ghost triangle's hull half-edge
  };
};

/// The closed triangulation read only, as spans: what the walk and the circle
/// tests read. DelaunayCore views its vectors through it while building;
/// Delaunay2 views its arrays (its own, or a mapped file's) for the queries.
struct DelaunayView : DelaunayHalfEdges {
  std::span<const Vec2d> coords;              // per internal vertex
  std::span<const std::uint32_t> vert, twin;  // per half-edge

  const Vec2d& at(std::uint32_t v) const { return coords[v]; }
  bool is_ghost_triangle(std::uint32_t t) const { return ((vert[3 * t] | vert[3 * t + 1] | vert[3 * t + 2]) & ghost_bit) != 0; }
  /// The triangle, edge or vertex of p, by a stochastic visibility walk from
  /// triangle `start`; adds the triangles visited to *steps (when given).
  Location walk(const Vec2d& p, std::uint32_t start, std::size_t* steps) const;
  /// p inside the circle of the counter-clockwise triangle (a, b, c) (with a
  /// ghost vertex: the open half-plane beyond its finite edge, plus the open edge).
  bool circle_holds(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Vec2d& p) const;
  /// p inside the circle of triangle t: it conflicts with p.
  bool in_conflict(std::uint32_t t, const Vec2d& p) const { return circle_holds(vert[3 * t], vert[3 * t + 1], vert[3 * t + 2], p); }
};

class DelaunayCore : public DelaunayHalfEdges {
 public:
  std::vector<Vec2d> coords;                  // per internal vertex
  std::vector<std::uint32_t> vert, twin;      // per half-edge: origin vertex (or ghost; none in a freed slot), opposite
  std::vector<std::uint32_t> free_triangles;  // freed slots, reused by new_triangle()
  std::vector<std::uint32_t> vertex_edge;     // per vertex: a half-edge leaving it (kept by publish and the hooks that need it)
  std::uint32_t last_triangle = 0;            // where the next walk starts: the triangle of the last change
  std::size_t flips = 0, walk_steps = 0;

  /// The arrays as they are now (until they grow).
  DelaunayView view() const { return {{}, coords, vert, twin}; }
  const Vec2d& at(std::uint32_t v) const { return coords[v]; }
  bool is_ghost_triangle(std::uint32_t t) const { return view().is_ghost_triangle(t); }
  Location walk(const Vec2d& p, std::uint32_t start, std::size_t* steps) const { return view().walk(p, start, steps); }
  bool circle_holds(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Vec2d& p) const {
    return view().circle_holds(a, b, c, p);
  }
  bool in_conflict(std::uint32_t t, const Vec2d& p) const { return view().in_conflict(t, p); }
  void link(std::uint32_t a, std::uint32_t b) {
    twin[a] = b;
    twin[b] = a;
  }

  /// Clears the triangulation (coords stay); then the first triangle of three
  /// vertices that are not collinear, the earliest in coords, with its three
  /// ghost triangles. False if there is none (the set is degenerate).
  bool make_first_triangle();
  /// A triangle slot (a freed one or three new half-edges) holding the
  /// vertices (a, b, c); its twins are for the caller to link.
  std::uint32_t new_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);
  /// Frees triangle t's slot (its vertices become none).
  void free_triangle(std::uint32_t t);
  /// Inserts vertex i (coords[i] set): walk from `start`, split, legalize.
  /// Returns none, or the vertex at the same place (then nothing changes).
  template <class Hooks>
  std::uint32_t insert_vertex(std::uint32_t i, std::uint32_t start, Hooks& hooks);
  /// Splits triangle t into three around vertex p.
  template <class Hooks>
  void split_triangle(std::uint32_t t, std::uint32_t p, Hooks& hooks);
  /// Splits the edge of half-edge e and its two triangles into four at vertex p.
  template <class Hooks>
  void split_edge(std::uint32_t e, std::uint32_t p, Hooks& hooks);
  /// Replaces the diagonal of the two triangles of half-edge e by the other one.
  template <class Hooks>
  void flip(std::uint32_t e, Hooks& hooks);
  /// Flips the edges opposite p on the flip stack until every one is locally Delaunay (Lawson).
  template <class Hooks>
  void legalize(std::uint32_t p, Hooks& hooks);
  /// Flips edge e if it is not fixed and not locally Delaunay, then the edges
  /// around each flip the same way, until none is left (Lawson): for an edge
  /// that was held fixed and is freed. Hull edges stay (no point is added).
  template <class Hooks>
  void restore_delaunay(std::uint32_t e, Hooks& hooks);

 private:
  std::vector<std::uint32_t> flip_stack_;  // half-edges opposite the new vertex, still to check
};

// ------------------------------------------------------------------ the steps

inline bool DelaunayView::circle_holds(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Vec2d& p) const {
  if (((a | b | c) & ghost_bit) == 0) [[likely]]
    return incircle(at(a), at(b), at(c), p) > 0;
  // The circle of a ghost triangle (x, y, ghost) is the open half-plane left of
  // x -> y plus the open segment between them.
  const std::uint32_t x = a == ghost ? b : b == ghost ? c : a;
  const std::uint32_t y = a == ghost ? c : b == ghost ? a : b;
  const double side = orient2d(at(x), at(y), p);
  return side > 0 || (side == 0 && strictly_between(at(x), at(y), p));
}

template <class Hooks>
std::uint32_t DelaunayCore::insert_vertex(std::uint32_t i, std::uint32_t start, Hooks& hooks) {
  const Location loc = walk(at(i), start, &walk_steps);
  switch (loc.where) {
    case Where::on_vertex:
      last_triangle = loc.edge / 3;
      return vert[loc.edge];
    case Where::on_edge:
      split_edge(loc.edge, i, hooks);
      break;
    case Where::inside:
    case Where::outside:
      split_triangle(loc.edge / 3, i, hooks);
      break;
  }
  legalize(i, hooks);
  return none;
}

template <class Hooks>
void DelaunayCore::split_triangle(std::uint32_t t, std::uint32_t p, Hooks& hooks) {
  const std::uint32_t s0 = 3 * t, s1 = s0 + 1, s2 = s0 + 2;
  const std::uint32_t a = vert[s0], b = vert[s1], c = vert[s2];
  const std::uint32_t o1 = twin[s1], o2 = twin[s2];
  // t = (a, b, p), t1 = (b, c, p), t2 = (c, a, p)
  const std::uint32_t t1 = new_triangle(b, c, p), t2 = new_triangle(c, a, p), u0 = 3 * t1, w0 = 3 * t2;
  vert[s2] = p;
  link(u0, o1);
  link(w0, o2);
  link(s1, u0 + 2);
  link(u0 + 1, w0 + 2);
  link(w0 + 1, s2);
  hooks.split_triangle(t, t1, t2);
  flip_stack_.push_back(s0);
  flip_stack_.push_back(u0);
  flip_stack_.push_back(w0);
  last_triangle = t;
}

template <class Hooks>
void DelaunayCore::split_edge(std::uint32_t e, std::uint32_t p, Hooks& hooks) {
  const std::uint32_t e1 = next(e), e2 = prev(e);
  const std::uint32_t t = twin[e], t1 = next(t), t2 = prev(t);
  const std::uint32_t a = vert[e], b = vert[e1], c = vert[e2], d = vert[t2];
  const std::uint32_t o_e1 = twin[e1], o_t1 = twin[t1];
  // (a, b, c) -> (a, p, c) + (p, b, c); (b, a, d) -> (b, p, d) + (p, a, d)
  const std::uint32_t n1t = new_triangle(p, b, c), n2t = new_triangle(p, a, d), n0 = 3 * n1t, m0 = 3 * n2t;
  vert[e1] = p;
  vert[t1] = p;
  link(e, m0);
  link(n0, t);
  link(e1, n0 + 2);
  link(t1, m0 + 2);
  link(n0 + 1, o_e1);
  link(m0 + 1, o_t1);
  hooks.split_edge(e, t, n1t, n2t);
  flip_stack_.push_back(e2);
  flip_stack_.push_back(n0 + 1);
  flip_stack_.push_back(t2);
  flip_stack_.push_back(m0 + 1);
  last_triangle = e / 3;
}

template <class Hooks>
void DelaunayCore::flip(std::uint32_t e, Hooks& hooks) {
  // e = u -> w in (u, w, p), f = w -> u in (w, u, x)  ==>  (u, x, p) and (w, p, x)
  const std::uint32_t e1 = next(e), f = twin[e], f1 = next(f), f2 = prev(f);
  const std::uint32_t outer_e1 = twin[e1], outer_f1 = twin[f1];
  const std::uint32_t p = vert[prev(e)], x = vert[f2];
  vert[e1] = x;
  vert[f1] = p;
  link(e, outer_f1);
  link(f, outer_e1);
  link(e1, f1);
  hooks.flip(e, f);
  ++flips;
}

template <class Hooks>
void DelaunayCore::legalize(std::uint32_t p, Hooks& hooks) {
  const Vec2d point = at(p);
  // The triangles across the new edges and their far vertices lie anywhere in
  // memory: ask for all of them at once rather than one miss after another.
  for (const std::uint32_t e : flip_stack_) __builtin_prefetch(&vert[prev(twin[e])]);
  for (const std::uint32_t e : flip_stack_)
    if (const std::uint32_t v = vert[prev(twin[e])]; v < coords.size()) __builtin_prefetch(&coords[v]);
  while (!flip_stack_.empty()) {
    const std::uint32_t e = flip_stack_.back();  // opposite p in its triangle
    flip_stack_.pop_back();
    const std::uint32_t f = twin[e];
    if (hooks.fixed(e) || !in_conflict(f / 3, point)) continue;
    const std::uint32_t f2 = prev(f);
    flip(e, hooks);
    flip_stack_.push_back(e);
    flip_stack_.push_back(f2);
  }
}

template <class Hooks>
void DelaunayCore::restore_delaunay(std::uint32_t e, Hooks& hooks) {
  flip_stack_.push_back(e);
  while (!flip_stack_.empty()) {
    const std::uint32_t h = flip_stack_.back();
    flip_stack_.pop_back();
    const std::uint32_t f = twin[h];
    if (hooks.fixed(h) || is_ghost_triangle(h / 3) || is_ghost_triangle(f / 3) ||
        !in_conflict(f / 3, at(vert[prev(h)])))
      continue;
    // (u, w, p) and (w, u, x) become (u, x, p) and (w, p, x): their outer edges next.
    const std::uint32_t f2 = prev(f);
    flip(h, hooks);
    for (std::uint32_t outer : {h, prev(h), f, f2}) flip_stack_.push_back(outer);
  }
}

}  // namespace geods::voronoi
