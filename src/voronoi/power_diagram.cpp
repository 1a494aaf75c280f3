// RegularTriangulation: incremental insertion with 2-2, 3-1 and 4-2 flips on
// DelaunayCore's arrays; PowerDiagram: cells cut out of a box by power bisectors.
#include "geods/voronoi/power_diagram.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "brio_order.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/predicates.hpp"
#include "geods/voronoi/delaunay_core.hpp"
#include "generalized_common.hpp"
#include "halfplane_clip.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = DelaunayCore::none;
constexpr std::uint32_t kGhost = DelaunayCore::ghost;
constexpr auto next = DelaunayCore::next;
constexpr auto prev = DelaunayCore::prev;

// Hooks that record nothing and fix every edge: core.legalize() with them only
// empties the core's own flip stack (the regular flips are ours).
struct AllFixed : NoHooks {
  bool fixed(std::uint32_t) const { return true; }
};

void check_input(std::span<const Vec2d> points, std::span<const double> weights, const char* what) {
  if (points.empty()) throw Error(std::string(what) + ": no points");
  if (weights.size() != points.size())
    throw Error(std::string(what) + ": " + std::to_string(weights.size()) + " weights for " +
                std::to_string(points.size()) + " points");
  if (points.size() >= (std::size_t(1) << 30)) throw Error(std::string(what) + ": 2^30 points or more");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]))
      throw Error(std::string(what) + ": non-finite coordinates at point " + std::to_string(i));
    if (!std::isfinite(weights[i])) throw Error(std::string(what) + ": non-finite weight at point " + std::to_string(i));
  }
  check_coordinate_range(points.front().data(), points.size(), 2, 2, 3, what);
  const double limit = coordinate_limit<double>(3);
  for (std::size_t i = 0; i < weights.size(); ++i)
    if (std::abs(weights[i]) > limit * limit)
      throw Error(std::string(what) + ": weight " + format_number(weights[i]) + " of point " + std::to_string(i) +
                  " is beyond +-" + format_number(limit * limit) + ", where powers would overflow; scale the input");
}

// The insertion: the triangulation of internal vertices (coords and weights in
// insertion order), the point each one stands for, and the status of points.
struct Builder {
  DelaunayCore core;
  std::vector<double> weight;               // per internal vertex
  std::vector<std::uint32_t> original_of;   // internal vertex -> point
  std::vector<std::uint32_t>& rep;          // per point
  std::vector<std::uint8_t>& redundant;     // per point
  std::vector<std::uint32_t> stack;
  std::size_t flips = 0, removals = 0;

  Builder(std::vector<std::uint32_t>& r, std::vector<std::uint8_t>& red) : rep(r), redundant(red) {}

  const Vec2d& at(std::uint32_t v) const { return core.coords[v]; }
  int power(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) const {
    return power_test(at(a), weight[a], at(b), weight[b], at(c), weight[c], at(d), weight[d]);
  }
  // Whether m, collinear with and strictly between a and b, keeps a cell.
  bool below(std::uint32_t a, std::uint32_t m, std::uint32_t b) const {
    return collinear_power_test(at(a), weight[a], at(m), weight[m], at(b), weight[b]) > 0;
  }

  void drain() {
    AllFixed fixed;
    core.legalize(0, fixed);
  }

  std::size_t degree(std::uint32_t h) const {  // h leaves the vertex
    std::size_t d = 0;
    std::uint32_t e = h;
    do {
      ++d;
      e = core.twin[prev(e)];
    } while (e != h);
    return d;
  }

  void push_opposite(std::uint32_t t, std::uint32_t p) {
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e)
      if (core.vert[prev(e)] == p) stack.push_back(e);
  }

  // Removes vertex r (a half-edge h leaves it) of degree 3, or of degree 4 on
  // the segment between two of its opposite neighbours; retriangulates its ring.
  void remove_vertex(std::uint32_t h, std::uint32_t p) {
    const std::uint32_t r = core.vert[h];
    std::vector<std::uint32_t> ring, outer, triangles;
    std::uint32_t e = h;
    do {
      ring.push_back(core.vert[next(e)]);
      outer.push_back(core.twin[next(e)]);
      triangles.push_back(e / 3);
      e = core.twin[prev(e)];
    } while (e != h);
    if (ring.size() == 3 && std::find(ring.begin(), ring.end(), kGhost) != ring.end()) return;  // a hull corner stays
    for (std::uint32_t t : triangles) core.free_triangle(t);
    std::vector<std::uint32_t> made;
    if (ring.size() == 3) {
      const std::uint32_t t = core.new_triangle(ring[0], ring[1], ring[2]);
      for (std::uint32_t k = 0; k < 3; ++k) core.link(3 * t + k, outer[k]);
      made.push_back(t);
    } else {
      // The diagonal through r: between ring[s] and ring[s + 2].
      std::uint32_t s = 0;
      if (ring[0] == kGhost || ring[2] == kGhost || orient2d(at(ring[0]), at(ring[2]), at(r)) != 0) s = 1;
      const std::uint32_t a = ring[s], b = ring[s + 1], c = ring[(s + 2) % 4], d = ring[(s + 3) % 4];
      const std::uint32_t t1 = core.new_triangle(a, b, c), t2 = core.new_triangle(c, d, a);
      core.link(3 * t1, outer[s]);
      core.link(3 * t1 + 1, outer[s + 1]);
      core.link(3 * t2, outer[(s + 2) % 4]);
      core.link(3 * t2 + 1, outer[(s + 3) % 4]);
      core.link(3 * t1 + 2, 3 * t2 + 2);
      made = {t1, t2};
    }
    redundant[original_of[r]] = 1;
    ++removals;
    core.last_triangle = made.front();
    for (std::uint32_t t : made) push_opposite(t, p);
  }

  // Flips until every edge opposite p is locally regular.
  void legalize(std::uint32_t p) {
    while (!stack.empty()) {
      const std::uint32_t e = stack.back();
      stack.pop_back();
      if (core.vert[e] == kNone || core.vert[prev(e)] != p) continue;  // a stale entry
      const std::uint32_t f = core.twin[e];
      const std::uint32_t u = core.vert[e], w = core.vert[next(e)], x = core.vert[prev(f)];
      if (x == kGhost) continue;  // a hull edge with p inside
      bool flat = false;          // the vertex to remove lies on the segment p-x
      std::uint32_t reflex_edge = kNone;  // leaves the vertex to remove
      if (u != kGhost && w != kGhost) {
        if (power(w, u, x, p) <= 0) continue;
        const double su = orient2d(at(u), at(x), at(p)), sw = orient2d(at(w), at(p), at(x));
        if (su > 0 && sw > 0) {
          flip(e, f);
          continue;
        }
        reflex_edge = su <= 0 ? e : next(e);
        flat = (su <= 0 ? su : sw) == 0;
      } else {
        // Two ghost triangles: s is the hull vertex between x and p.
        const std::uint32_t s = u == kGhost ? w : u;
        const double side = u == kGhost ? orient2d(at(x), at(w), at(p)) : orient2d(at(u), at(x), at(p));
        if (side > 0) {
          flip(e, f);
          continue;
        }
        if (side < 0 || !DelaunayCore::strictly_between(at(x), at(p), at(s)) || below(x, s, p)) continue;
        reflex_edge = u == kGhost ? next(e) : e;
        flat = true;
      }
      const std::size_t d = degree(reflex_edge);
      if ((!flat && d == 3) || (flat && d == 4)) remove_vertex(reflex_edge, p);
    }
  }

  void flip(std::uint32_t e, std::uint32_t f) {
    const std::uint32_t f2 = prev(f);
    NoHooks none;
    core.flip(e, none);
    ++flips;
    stack.push_back(e);
    stack.push_back(f2);
  }

  void split_triangle(std::uint32_t t, std::uint32_t k) {
    NoHooks none;
    core.split_triangle(t, k, none);
    drain();
    // The three triangles around k: t and the two that hold k's other edges.
    const std::uint32_t h = 3 * t + 2;  // k -> a in (a, b, k)
    std::uint32_t e = h;
    do {
      push_opposite(e / 3, k);
      e = core.twin[prev(e)];
    } while (e != h);
  }

  void split_edge(std::uint32_t e, std::uint32_t k) {
    NoHooks none;
    core.split_edge(e, k, none);
    drain();
    const std::uint32_t h = next(e);  // k -> c in (a, k, c)
    std::uint32_t g = h;
    do {
      push_opposite(g / 3, k);
      g = core.twin[prev(g)];
    } while (g != h);
  }

  void insert(std::uint32_t k) {
    const std::uint32_t point = original_of[k];
    const auto loc = core.walk(at(k), core.last_triangle, &core.walk_steps);
    const std::uint32_t t = loc.edge / 3;
    using Where = DelaunayCore::Where;
    switch (loc.where) {
      case Where::on_vertex: {
        const std::uint32_t v = core.vert[loc.edge];
        const std::uint32_t existing = original_of[v];
        core.last_triangle = t;
        if (weight[k] < weight[v]) {
          redundant[point] = 1;
        } else if (weight[k] == weight[v]) {
          if (point < existing) {
            original_of[v] = point;
            rep[existing] = point;
          } else {
            rep[point] = existing;
          }
        } else {
          // The heavier point takes the vertex; its lower lift may make neighbours redundant.
          redundant[existing] = 1;
          original_of[v] = point;
          weight[v] = weight[k];
          std::uint32_t g = loc.edge;
          do {
            push_opposite(g / 3, v);
            g = core.twin[prev(g)];
          } while (g != loc.edge);
          legalize(v);
        }
        return;
      }
      case Where::inside:
        if (power(core.vert[3 * t], core.vert[3 * t + 1], core.vert[3 * t + 2], k) <= 0) {
          redundant[point] = 1;
          return;
        }
        split_triangle(t, k);
        break;
      case Where::on_edge: {
        const std::uint32_t finite = core.is_ghost_triangle(t) ? core.twin[loc.edge] / 3 : t;
        if (power(core.vert[3 * finite], core.vert[3 * finite + 1], core.vert[3 * finite + 2], k) <= 0) {
          redundant[point] = 1;
          return;
        }
        split_edge(loc.edge, k);
        break;
      }
      case Where::outside:
        split_triangle(t, k);
        break;
    }
    legalize(k);
  }
};

}  // namespace

RegularTriangulation::RegularTriangulation(std::span<const Vec2d> points, std::span<const double> weights,
                                           std::uint64_t seed) {
  check_input(points, weights, "RegularTriangulation");
  points_.assign(points.begin(), points.end());
  weights_.assign(weights.begin(), weights.end());
  build(seed);
}

void RegularTriangulation::build(std::uint64_t seed) {
  const std::uint32_t n = std::uint32_t(points_.size());
  representative_.resize(n);
  std::iota(representative_.begin(), representative_.end(), 0u);
  redundant_flag_.assign(n, 0);
  std::vector<std::uint32_t> all(n);
  std::iota(all.begin(), all.end(), 0u);
  Builder b(representative_, redundant_flag_);
  b.original_of = brio_order(points_, all, seed);
  b.core.coords.resize(n);
  b.weight.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    b.core.coords[k] = points_[b.original_of[k]];
    b.weight[k] = weights_[b.original_of[k]];
  }
  if (!b.core.make_first_triangle()) {
    build_collinear();
    return;
  }
  const std::uint32_t a = b.core.vert[0], c1 = b.core.vert[1], c2 = b.core.vert[2];
  for (std::uint32_t k = 0; k < n; ++k)
    if (k != a && k != c1 && k != c2) b.insert(k);
  flips_ = b.flips;
  removals_ = b.removals;
  // Chains of representatives (a point renamed to an earlier equal one).
  for (std::uint32_t i = 0; i < n; ++i) {
    std::uint32_t r = representative_[i];
    while (representative_[r] != r) r = representative_[r];
    representative_[i] = r;
  }

  // Publish the finite triangles over point indices.
  const DelaunayCore& core = b.core;
  const std::uint32_t slots = std::uint32_t(core.vert.size() / 3);
  std::vector<std::uint32_t> public_of(slots, kNone);
  std::uint32_t count = 0;
  for (std::uint32_t t = 0; t < slots; ++t)
    if (core.vert[3 * t] != kNone && !core.is_ghost_triangle(t)) public_of[t] = count++;
  triangles_.resize(3 * std::size_t(count));
  halfedges_.assign(3 * std::size_t(count), no_edge);
  for (std::uint32_t t = 0; t < slots; ++t) {
    if (public_of[t] == kNone) continue;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t e = 3 * t + k, g = core.twin[e];
      triangles_[3 * public_of[t] + k] = b.original_of[core.vert[e]];
      if (public_of[g / 3] != kNone) halfedges_[3 * public_of[t] + k] = 3 * public_of[g / 3] + g % 3;
    }
  }
  // The hull: follow the ghost triangles (x, y, ghost) counter-clockwise.
  std::uint32_t start = kNone;
  for (std::uint32_t t = 0; t < slots && start == kNone; ++t)
    if (core.vert[3 * t] != kNone && core.is_ghost_triangle(t))
      for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e)
        if (core.vert[e] != kGhost && core.vert[next(e)] != kGhost) start = e;
  // Ghost half-edge x -> y runs clockwise along the hull; the ghost triangle
  // across its edge ghost -> x holds the hull edge z -> x, z the next hull vertex.
  std::uint32_t e = start;
  do {
    hull_.push_back(b.original_of[core.vert[e]]);
    e = prev(core.twin[prev(e)]);
  } while (e != start && hull_.size() <= n);
  build_neighbors();
}

void RegularTriangulation::build_collinear() {
  const std::uint32_t n = std::uint32_t(points_.size());
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return std::tie(points_[a][0], points_[a][1], a) < std::tie(points_[b][0], points_[b][1], b);
  });
  // Equal points: the heaviest stands, the first of equal weight among them; lighter ones are redundant.
  std::vector<std::uint32_t> sites;
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    std::uint32_t best = order[i];
    while (j < n && points_[order[j]] == points_[order[i]]) {
      if (weights_[order[j]] > weights_[best]) best = order[j];
      ++j;
    }
    for (std::size_t k = i; k < j; ++k) {
      const std::uint32_t q = order[k];
      if (q == best) continue;
      if (weights_[q] == weights_[best])
        representative_[q] = best;
      else
        redundant_flag_[q] = 1;
    }
    sites.push_back(best);
    i = j;
  }
  // The lower hull of the lifted line (monotone chain).
  const auto below = [&](std::uint32_t a, std::uint32_t m, std::uint32_t c) {
    return collinear_power_test(points_[a], weights_[a], points_[m], weights_[m], points_[c], weights_[c]) > 0;
  };
  for (std::uint32_t s : sites) {
    while (chain_.size() >= 2 && !below(chain_[chain_.size() - 2], chain_.back(), s)) {
      redundant_flag_[chain_.back()] = 1;
      ++removals_;
      chain_.pop_back();
    }
    chain_.push_back(s);
  }
  hull_ = chain_;
  build_neighbors();
}

void RegularTriangulation::build_neighbors() {
  // Each undirected edge once per end: a half-edge a -> c gives c to a, and to c
  // also a when it has no twin (a hull edge); interior edges come back through their twin.
  const std::size_t n = points_.size();
  const auto each_pair = [&](const auto& f) {
    if (triangles_.empty()) {
      for (std::size_t k = 0; k + 1 < chain_.size(); ++k) f(chain_[k], chain_[k + 1]), f(chain_[k + 1], chain_[k]);
      return;
    }
    for (std::uint32_t e = 0; e < triangles_.size(); ++e) {
      const std::uint32_t a = triangles_[e], c = triangles_[e % 3 == 2 ? e - 2 : e + 1];
      f(a, c);
      if (halfedges_[e] == no_edge) f(c, a);
    }
  };
  neighbor_offsets_.assign(n + 1, 0);
  each_pair([&](std::uint32_t a, std::uint32_t) { ++neighbor_offsets_[a + 1]; });
  std::partial_sum(neighbor_offsets_.begin(), neighbor_offsets_.end(), neighbor_offsets_.begin());
  neighbors_.resize(neighbor_offsets_[n]);
  std::vector<std::uint32_t> fill(neighbor_offsets_.begin(), neighbor_offsets_.end() - 1);
  each_pair([&](std::uint32_t a, std::uint32_t c) { neighbors_[fill[a]++] = c; });
  for (std::size_t i = 0; i < n; ++i)
    std::sort(neighbors_.begin() + neighbor_offsets_[i], neighbors_.begin() + neighbor_offsets_[i + 1]);
}

std::vector<std::uint32_t> RegularTriangulation::redundant() const {
  std::vector<std::uint32_t> out;
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (is_redundant(i)) out.push_back(i);
  return out;
}

RegularTriangulationStats RegularTriangulation::stats() const {
  RegularTriangulationStats s;
  s.points = points_.size();
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    if (is_redundant(i))
      ++s.redundant;
    else if (representative_[i] != i)
      ++s.duplicates;
    else
      ++s.vertices;
  }
  s.triangles = triangle_count();
  s.hull = hull_.size();
  s.flips = flips_;
  s.removals = removals_;
  return s;
}

void RegularTriangulation::validate() const {
  const auto fail = [](const std::string& what) { throw Error("RegularTriangulation::validate: " + what); };
  const auto p = [&](std::uint32_t i) -> const Vec2d& { return points_[i]; };
  const auto w = [&](std::uint32_t i) { return weights_[i]; };
  for (std::uint32_t e = 0; e < triangles_.size(); ++e) {
    const std::uint32_t v = triangles_[e];
    if (v >= points_.size() || representative_[v] != v || is_redundant(v))
      fail("triangle corner " + std::to_string(e) + " is not a site");
    const std::uint32_t g = halfedges_[e];
    if (g == no_edge) continue;
    if (g >= halfedges_.size() || halfedges_[g] != e) fail("half-edge " + std::to_string(e) + " has a bad twin");
    if (g < e) continue;
    const std::uint32_t t = e / 3, u = g / 3;
    const std::uint32_t a = triangles_[3 * t], b = triangles_[3 * t + 1], c = triangles_[3 * t + 2];
    const std::uint32_t d = triangles_[3 * u + (g % 3 + 2) % 3];
    if (power_test(p(a), w(a), p(b), w(b), p(c), w(c), p(d), w(d)) > 0)
      fail("edge " + std::to_string(e) + " is not locally regular");
  }
  for (std::uint32_t t = 0; t < triangle_count(); ++t)
    if (orient2d(p(triangles_[3 * t]), p(triangles_[3 * t + 1]), p(triangles_[3 * t + 2])) <= 0)
      fail("triangle " + std::to_string(t) + " is not counter-clockwise");
  std::size_t sites = 0;
  for (std::uint32_t i = 0; i < points_.size(); ++i) sites += representative_[i] == i && !is_redundant(i);
  if (!degenerate() && triangle_count() != 2 * sites - hull_.size() - 2)
    fail("Euler's formula fails: " + std::to_string(triangle_count()) + " triangles for " + std::to_string(sites) +
         " sites and " + std::to_string(hull_.size()) + " on the hull");
}

// ------------------------------------------------------------------ the diagram

PowerDiagram::PowerDiagram(std::span<const Vec2d> points, std::span<const double> weights, const AABB2d& box)
    : PowerDiagram(RegularTriangulation(points, weights), box) {}

PowerDiagram::PowerDiagram(RegularTriangulation triangulation, const AABB2d& box)
    : triangulation_(std::move(triangulation)), box_(box) {
  detail::check_sites_and_box(triangulation_.points(), box, "PowerDiagram");
  const RegularTriangulation& rt = triangulation_;
  const std::size_t n = rt.points().size();
  cells_.resize(n);
  std::vector<std::vector<Edge>> pieces(n);
  parallel_for_each_index(0, n, [&](std::size_t i) {
    const auto site = std::uint32_t(i);
    if (rt.representative(site) != site || rt.is_redundant(site)) return;
    const Vec2d& p = rt.points()[site];
    detail::LabeledPolygon poly = detail::box_polygon(box_);
    for (std::uint32_t j : rt.neighbors(site)) {
      // |y|^2 - wi <= |y - d|^2 - wj for y = x - p, d = pj - p:  2 d.y <= |d|^2 + wi - wj.
      const Vec2d d = rt.points()[j] - p;
      detail::clip_halfplane(poly, p, 2 * d, d.squaredNorm() + rt.weights()[site] - rt.weights()[j], j);
      if (poly.points.empty()) break;
    }
    detail::append_bisector_edges(poly, site, pieces[i]);
    cells_[i] = std::move(poly.points);
  }, 64);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (rt.representative(i) != i) cells_[i] = cells_[rt.representative(i)];
    edges_.insert(edges_.end(), pieces[i].begin(), pieces[i].end());
  }
}

PowerDiagramStats PowerDiagram::stats() const {
  PowerDiagramStats s;
  s.sites = cells_.size();
  for (std::uint32_t i = 0; i < cells_.size(); ++i) {
    if (triangulation_.is_redundant(i)) ++s.redundant;
    if (!cells_[i].empty() && triangulation_.representative(i) == i) ++s.cells;
    s.cell_vertices += cells_[i].size();
  }
  s.edges = edges_.size();
  return s;
}

void PowerDiagram::validate() const {
  triangulation_.validate();
  const auto fail = [](const std::string& what) { throw Error("PowerDiagram::validate: " + what); };
  const double side = std::max(box_.hi[0] - box_.lo[0], box_.hi[1] - box_.lo[1]);
  for (std::size_t i = 0; i < cells_.size(); ++i) detail::check_cell(cells_[i], box_, "PowerDiagram::validate: cell " + std::to_string(i));
  for (const Edge& e : edges_) {
    const Vec2d &pa = points()[e.a], &pb = points()[e.b];
    const double wa = weights()[e.a], wb = weights()[e.b];
    for (const Vec2d& x : {e.p0, e.p1}) {
      const double da = power_distance(x, pa, wa), db = power_distance(x, pb, wb);
      // (|x|: far from the origin a corner is only as exact as its coordinates' own rounding.)
      const double reach = (x - pa).norm() + (x - pb).norm() + side;
      const double scale = reach * (reach + x.cwiseAbs().maxCoeff()) + std::abs(wa) + std::abs(wb);
      if (std::abs(da - db) > 1e-9 * scale) fail("an edge end has unequal powers for its sites");
    }
  }
}

}  // namespace geods::voronoi
