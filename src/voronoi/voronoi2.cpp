// Voronoi2: the dual of a Delaunay triangulation in half-edge form, and cells clipped to boxes.
#include "geods/voronoi/voronoi2.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/predicates.hpp"
#include "geods/voronoi/delaunay2.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "exact_compare.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t next_half_edge(std::uint32_t e) { return e % 3 == 2 ? e - 2 : e + 1; }
constexpr std::uint32_t prev_half_edge(std::uint32_t e) { return e % 3 == 0 ? e + 2 : e - 1; }

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// The parameter interval of the line p + t d inside `box` (d a unit vector); empty when lo > hi.
std::pair<double, double> line_box_interval(const Vec2d& p, const Vec2d& d, const AABB2d& box) {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0) {
      if (p[k] < box.lo[k] || p[k] > box.hi[k]) return {hi, lo};  // parallel to the side and outside: empty
      continue;
    }
    const double t1 = (box.lo[k] - p[k]) / d[k], t2 = (box.hi[k] - p[k]) / d[k];
    lo = std::max(lo, std::min(t1, t2));
    hi = std::min(hi, std::max(t1, t2));
  }
  return {lo, hi};
}

// Position of a point of the boundary of `box` along it, counter-clockwise from
// the lower-left corner: [0, 1) bottom, [1, 2) right, [2, 3) top, [3, 4) left.
double perimeter_position(const Vec2d& p, const AABB2d& box) {
  const double w = box.hi[0] - box.lo[0], h = box.hi[1] - box.lo[1];
  const double to_side[4] = {std::abs(p[1] - box.lo[1]) / h, std::abs(p[0] - box.hi[0]) / w,
                             std::abs(p[1] - box.hi[1]) / h, std::abs(p[0] - box.lo[0]) / w};
  const int side = int(std::min_element(to_side, to_side + 4) - to_side);
  switch (side) {
    case 0: return std::clamp((p[0] - box.lo[0]) / w, 0.0, 1.0);
    case 1: return 1 + std::clamp((p[1] - box.lo[1]) / h, 0.0, 1.0);
    case 2: return 2 + std::clamp((box.hi[0] - p[0]) / w, 0.0, 1.0);
    default: return std::fmod(3 + std::clamp((box.hi[1] - p[1]) / h, 0.0, 1.0), 4.0);
  }
}

Vec2d box_corner(const AABB2d& box, int k) {
  switch (k % 4) {
    case 0: return box.lo;
    case 1: return {box.hi[0], box.lo[1]};
    case 2: return box.hi;
    default: return {box.lo[0], box.hi[1]};
  }
}

}  // namespace

namespace {

std::vector<std::uint32_t> representatives(const Delaunay2& triangulation) {
  std::vector<std::uint32_t> rep(triangulation.points().size());
  for (std::uint32_t i = 0; i < rep.size(); ++i) {
    rep[i] = triangulation.representative(i);
    if (rep[i] == Delaunay2::no_edge)
      throw Error("Voronoi2: point " + std::to_string(i) + " was removed from the triangulation");
  }
  return rep;
}

}  // namespace

Voronoi2::Voronoi2(std::span<const Vec2d> points) : Voronoi2(Delaunay2(points)) {}

Voronoi2::Voronoi2(const Delaunay2& triangulation)
    : Voronoi2(triangulation.points(), triangulation.triangles(), triangulation.halfedges(),
               representatives(triangulation)) {}

Voronoi2::Voronoi2(std::span<const Vec2d> points, std::span<const std::uint32_t> triangles,
                   std::span<const std::uint32_t> halfedges, std::span<const std::uint32_t> representative)
    : points_(std::vector<Vec2d>(points.begin(), points.end())),
      representative_(std::vector<std::uint32_t>(representative.begin(), representative.end())) {
  const std::size_t n = points.size();
  if (n == 0) throw Error("Voronoi2: no points");
  if (n >= kInfinity) throw Error("Voronoi2: 2^32 - 1 points or more");
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]))
      throw Error("Voronoi2: non-finite coordinates at point " + std::to_string(i));
  // Circumcentres are cubic in the coordinates: refuse what they cannot hold.
  check_coordinate_range(points.front().data(), n, 2, 2, 3, "Voronoi2");
  if (representative.size() != n)
    throw Error("Voronoi2: " + std::to_string(representative.size()) + " representatives for " + std::to_string(n) +
                " points");
  for (std::size_t i = 0; i < n; ++i)
    if (representative[i] > i || representative[representative[i]] != representative[i])
      throw Error("Voronoi2: representative[" + std::to_string(i) + "] is not a first occurrence");
  if (triangles.size() % 3 != 0 || halfedges.size() != triangles.size())
    throw Error("Voronoi2: " + std::to_string(triangles.size()) + " triangle indices and " +
                std::to_string(halfedges.size()) + " half-edges do not form triangles");
  for (std::size_t e = 0; e < triangles.size(); ++e) {
    if (triangles[e] >= n || representative[triangles[e]] != triangles[e])
      throw Error("Voronoi2: triangle index " + std::to_string(e) + " is not a representative point");
    if (halfedges[e] != kNoEdge && (halfedges[e] >= triangles.size() || halfedges[halfedges[e]] != e))
      throw Error("Voronoi2: half-edge " + std::to_string(e) + " has an inconsistent twin");
  }
  std::vector<Vec2d> vertices;
  std::vector<Edge> edges;
  std::vector<std::uint32_t> cell_edge(n, kNoEdge);
  if (triangles.empty()) {
    build_collinear(edges, cell_edge);
  } else {
    build_dual(triangles, halfedges, vertices, edges, cell_edge);
  }
  vertices_ = std::move(vertices);
  edges_ = std::move(edges);
  cell_edge_ = std::move(cell_edge);
  build_neighbors(triangles);
}

void Voronoi2::build_dual(std::span<const std::uint32_t> triangles, std::span<const std::uint32_t> halfedges,
                          std::vector<Vec2d>& vertices, std::vector<Edge>& edges, std::vector<std::uint32_t>& cell_edge) const {
  const auto m = std::uint32_t(triangles.size());
  const std::uint32_t triangle_count = m / 3;

  // Triangles with the same circumcircle (a flip-able edge between co-circular
  // sites) become one Voronoi vertex.
  std::vector<std::uint32_t> parent(triangle_count);
  std::iota(parent.begin(), parent.end(), 0u);
  for (std::uint32_t e = 0; e < m; ++e) {
    const std::uint32_t f = halfedges[e];
    if (f == kNoEdge || f < e) continue;
    const Vec2d& a = points_[triangles[e]];
    const Vec2d& b = points_[triangles[next_half_edge(e)]];
    const Vec2d& c = points_[triangles[prev_half_edge(e)]];
    const Vec2d& d = points_[triangles[prev_half_edge(f)]];
    if (incircle(a, b, c, d) == 0) {
      const std::uint32_t ra = find_root(parent, e / 3), rb = find_root(parent, f / 3);
      parent[std::max(ra, rb)] = std::min(ra, rb);  // the smallest triangle stays the root
    }
  }
  std::vector<std::uint32_t> vertex_of(triangle_count);
  std::vector<std::uint32_t> vertex_of_root(triangle_count, kInfinity);
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t r = find_root(parent, t);
    if (vertex_of_root[r] == kInfinity) {
      vertex_of_root[r] = std::uint32_t(vertices.size());
      vertices.push_back(
          detail::circumcentre(points_[triangles[3 * r]], points_[triangles[3 * r + 1]], points_[triangles[3 * r + 2]]));
    }
    vertex_of[t] = vertex_of_root[r];
  }

  // One candidate half-edge per Delaunay half-edge e (the cell of e's origin,
  // from the circumcentre across e to the one of e's triangle) and one more for
  // each hull half-edge g (the outer side: from g's circumcentre to infinity).
  std::vector<std::uint32_t> hull_index(m, kNoEdge), hull_out(points_.size(), kNoEdge);
  std::vector<std::uint32_t> hull;
  for (std::uint32_t e = 0; e < m; ++e)
    if (halfedges[e] == kNoEdge) {
      hull_index[e] = std::uint32_t(hull.size());
      hull.push_back(e);
      hull_out[triangles[e]] = e;
    }
  const std::uint32_t total = m + std::uint32_t(hull.size());
  std::vector<Edge> all(total);
  for (std::uint32_t e = 0; e < m; ++e) {
    const std::uint32_t f = halfedges[e], p = prev_half_edge(e);
    all[e] = {triangles[e], f != kNoEdge ? f : m + hull_index[e],
              halfedges[p] != kNoEdge ? halfedges[p] : m + hull_index[p],
              f != kNoEdge ? vertex_of[f / 3] : kInfinity, vertex_of[e / 3]};
  }
  for (std::uint32_t k = 0; k < hull.size(); ++k) {
    const std::uint32_t g = hull[k], b = triangles[next_half_edge(g)];
    all[m + k] = {b, g, hull_out[b], vertex_of[g / 3], kInfinity};
  }

  // Drop the zero-length edges between merged circumcentres and relink around them.
  const auto degenerate = [&](std::uint32_t e) { return all[e].origin != kInfinity && all[e].origin == all[e].target; };
  std::vector<std::uint32_t> new_index(total, kNoEdge);
  for (std::uint32_t e = 0; e < total; ++e)
    if (!degenerate(e)) {
      new_index[e] = std::uint32_t(edges.size());
      edges.push_back(all[e]);
    }
  for (Edge& edge : edges) {
    std::uint32_t next = edge.next;
    while (degenerate(next)) next = all[next].next;
    edge.next = new_index[next];
    edge.twin = new_index[edge.twin];
  }
  for (std::uint32_t e = 0; e < total; ++e)
    if (new_index[e] != kNoEdge && cell_edge[all[e].site] == kNoEdge) cell_edge[all[e].site] = new_index[e];
  // Hull cells start at the edge that comes in from infinity.
  for (std::uint32_t g : hull) cell_edge[triangles[g]] = new_index[g];
}

void Voronoi2::build_collinear(std::vector<Edge>& edges, std::vector<std::uint32_t>& cell_edge) const {
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (representative_[i] == i) sites.push_back(i);
  // Collinear points sorted lexicographically are in order along their line.
  std::sort(sites.begin(), sites.end(), [&](std::uint32_t a, std::uint32_t b) {
    return std::pair(points_[a][0], points_[a][1]) < std::pair(points_[b][0], points_[b][1]);
  });
  for (std::uint32_t k = 0; k + 1 < sites.size(); ++k) {
    const std::uint32_t left = 2 * k, right = 2 * k + 1;
    // Within a middle cell the two bisector lines follow each other through infinity.
    const std::uint32_t right_next = k + 2 < sites.size() ? 2 * (k + 1) : right;
    edges.push_back({sites[k], right, k > 0 ? 2 * (k - 1) + 1 : left, kInfinity, kInfinity});
    edges.push_back({sites[k + 1], left, right_next, kInfinity, kInfinity});
    cell_edge[sites[k]] = left;
    cell_edge[sites[k + 1]] = right;
  }
}

void Voronoi2::build_neighbors(std::span<const std::uint32_t> triangles) {
  const std::size_t n = points_.size();
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  if (triangles.empty()) {
    for (const Edge& e : edges_) pairs.push_back({e.site, edges_[e.twin].site});
  } else {
    pairs.reserve(triangles.size() + 16);
    for (std::uint32_t e = 0; e < triangles.size(); ++e) {
      const std::uint32_t a = triangles[e], b = triangles[next_half_edge(e)];
      pairs.push_back({a, b});
      pairs.push_back({b, a});  // hull edges have no twin to add this direction
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<std::uint32_t> offsets(n + 1, 0), neighbors(pairs.size());
  for (const auto& [a, b] : pairs) ++offsets[a + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  for (std::size_t i = 0; i < pairs.size(); ++i) neighbors[i] = pairs[i].second;
  neighbor_offsets_ = std::move(offsets);
  neighbors_ = std::move(neighbors);
}

bool Voronoi2::bounded(std::uint32_t i) const {
  const std::uint32_t start = cell_edge(i);
  if (start == kNoEdge) return false;
  std::uint32_t e = start;
  do {
    if (edges_[e].target == kInfinity) return false;
    e = edges_[e].next;
  } while (e != start);
  return true;
}

Vec2d Voronoi2::direction(std::uint32_t e) const {
  const Vec2d d = points_[opposite_site(e)] - points_[edges_[e].site];
  return Vec2d(-d[1], d[0]).normalized();
}

Vec2d Voronoi2::line_point(std::uint32_t e) const {
  return (points_[edges_[e].site] + points_[opposite_site(e)]) / 2;
}

AABB2d frame_around(std::span<const Vec2d> points, double margin) {
  if (points.empty()) throw Error("frame_around: no points");
  AABB2d box;
  for (const Vec2d& p : points) box.extend(p);
  const double side = std::max(box.hi[0] - box.lo[0], box.hi[1] - box.lo[1]);
  const double grow = side > 0 ? margin * side : 0.5;
  box.lo.array() -= grow;
  box.hi.array() += grow;
  return box;
}

std::optional<std::pair<Vec2d, Vec2d>> Voronoi2::clipped_edge(std::uint32_t e, const AABB2d& box) const {
  const Edge& edge = edges_[e];
  const Vec2d p = line_point(e), d = direction(e);
  auto [t0, t1] = line_box_interval(p, d, box);
  if (edge.origin != kInfinity) t0 = std::max(t0, (vertices_[edge.origin] - p).dot(d));
  if (edge.target != kInfinity) t1 = std::min(t1, (vertices_[edge.target] - p).dot(d));
  if (!(t0 < t1)) return std::nullopt;
  const Vec2d a = edge.origin != kInfinity && t0 == (vertices_[edge.origin] - p).dot(d) ? vertices_[edge.origin] : Vec2d(p + t0 * d);
  const Vec2d b = edge.target != kInfinity && t1 == (vertices_[edge.target] - p).dot(d) ? vertices_[edge.target] : Vec2d(p + t1 * d);
  return std::pair(a, b);
}

std::vector<Vec2d> Voronoi2::cell_polygon(std::uint32_t i, const AABB2d& box) const {
  if (box.empty()) throw Error("Voronoi2::cell_polygon: empty box");
  const std::uint32_t start = cell_edge(i);
  if (start == kNoEdge) return {box_corner(box, 0), box_corner(box, 1), box_corner(box, 2), box_corner(box, 3)};

  // First the cell within a frame around the sites and the box, each edge cut
  // to it along its bisector (as clipped_edge does: exact sites, not a far
  // vertex, give the crossing, the same one from both cells; clipping
  // polygons whose corners reached 1e10 left gaps of 1e-7 between cells).
  // Where an edge leaves the frame, the frame's corners lead, counter-clockwise,
  // to where the next edge comes back in.
  AABB2d frame = box;
  for (const Vec2d& p : points_) frame.extend(p);
  const double side = std::max({frame.hi[0] - frame.lo[0], frame.hi[1] - frame.lo[1], 1e-300});
  frame.lo.array() -= side;
  frame.hi.array() += side;

  struct Piece {
    Vec2d a, b;
    bool enters, leaves;  // a, b on the frame (the edge goes on beyond it)
  };
  std::vector<Piece> pieces;
  std::uint32_t e = start;
  do {
    const Edge& edge = edges_[e];
    if (const auto clipped = clipped_edge(e, frame))
      pieces.push_back({clipped->first, clipped->second,
                        edge.origin == kInfinity || clipped->first != vertices_[edge.origin],
                        edge.target == kInfinity || clipped->second != vertices_[edge.target]});
    e = edge.next;
  } while (e != start);
  std::vector<Vec2d> polygon;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const Piece &piece = pieces[k], &next = pieces[(k + 1) % pieces.size()];
    for (const Vec2d& v : {piece.a, piece.b})
      if (polygon.empty() || polygon.back() != v) polygon.push_back(v);
    if (piece.leaves && next.enters) {
      const double from = perimeter_position(piece.b, frame);
      double to = perimeter_position(next.a, frame);
      if (to <= from) to += 4;
      for (int corner = int(std::floor(from)) + 1; corner < to; ++corner) polygon.push_back(box_corner(frame, corner));
    }
  }
  if (polygon.size() > 1 && polygon.front() == polygon.back()) polygon.pop_back();
  return clip_polygon_to_box(polygon, box);
}

std::vector<std::vector<Vec2d>> Voronoi2::cell_polygons(const AABB2d& box) const {
  std::vector<std::vector<Vec2d>> cells(points_.size());
  parallel_for_each_index(0, points_.size(), [&](std::size_t i) { cells[i] = cell_polygon(std::uint32_t(i), box); }, 64);
  return cells;
}

Voronoi2Stats Voronoi2::stats() const {
  Voronoi2Stats s;
  s.sites = points_.size();
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    if (representative_[i] != i) continue;
    ++s.distinct;
    s.unbounded_cells += !bounded(i);
  }
  s.vertices = vertices_.size();
  s.edges = edges_.size() / 2;
  s.bytes = points_.size() * (sizeof(Vec2d) + 2 * sizeof(std::uint32_t)) + vertices_.size() * sizeof(Vec2d) +
            edges_.size() * sizeof(Edge) + (neighbor_offsets_.size() + neighbors_.size()) * sizeof(std::uint32_t);
  return s;
}

void Voronoi2::check_cells() const {
  const auto fail = [](const std::string& what) { throw Error("Voronoi2::validate: " + what); };
  const std::size_t m = edges_.size();
  for (std::uint32_t e = 0; e < m; ++e) {
    const Edge& edge = edges_[e];
    const auto name = [e] { return "half-edge " + std::to_string(e); };  // built only on failure
    if (edge.twin >= m || edges_[edge.twin].twin != e) fail(name() + ": twin is not mutual");
    if (edge.next >= m) fail(name() + ": next out of range");
    if (edge.site >= points_.size()) fail(name() + ": site out of range");
    const Edge& twin = edges_[edge.twin];
    if (twin.site == edge.site) fail(name() + ": same site on both sides");
    if (twin.origin != edge.target || twin.target != edge.origin) fail(name() + ": twin has other end points");
    if (edges_[edge.next].site != edge.site) fail(name() + ": next belongs to another cell");
    if ((edge.target == kInfinity) != (edges_[edge.next].origin == kInfinity) ||
        (edge.target != kInfinity && edges_[edge.next].origin != edge.target))
      fail(name() + ": next does not start where this one ends");
    if (edge.origin != kInfinity && edge.origin == edge.target) fail(name() + ": zero length");
    for (std::uint32_t v : {edge.origin, edge.target})
      if (v != kInfinity && v >= vertices_.size()) fail(name() + ": vertex out of range");
  }
  // next is a permutation, so following it from any half-edge comes back.
  std::vector<char> entered(m, 0);
  for (std::uint32_t e = 0; e < m; ++e)
    if (entered[edges_[e].next]++) fail("half-edge " + std::to_string(edges_[e].next) + " is the next of two");
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    if (representative_[i] != i) continue;
    const std::uint32_t start = cell_edge_[i];
    if (start == kNoEdge ? m != 0 : start >= m || edges_[start].site != i) fail("site " + std::to_string(i) + " has no cell");
  }
}

void Voronoi2::validate() const {
  const auto fail = [](const std::string& what) { throw Error("Voronoi2::validate: " + what); };
  check_cells();
  // Each cell is one cycle: every half-edge is on the cycle of its site's cell_edge.
  const std::size_t m = edges_.size();
  std::vector<char> seen(m, 0);
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    if (representative_[i] != i || cell_edge_[i] == kNoEdge) continue;
    std::uint32_t e = cell_edge_[i];
    do {
      seen[e] = 1;
      e = edges_[e].next;
    } while (e != cell_edge_[i]);
  }
  if (std::count(seen.begin(), seen.end(), 0) != 0) fail("a half-edge belongs to no cell cycle");
  double scale = 0;
  for (const Vec2d& p : points_) scale = std::max(scale, p.cwiseAbs().maxCoeff());
  for (std::uint32_t e = 0; e < edges_.size(); ++e) {
    const Edge& edge = edges_[e];
    const auto name = [e] { return "half-edge " + std::to_string(e); };
    // The site lies strictly left of its edge's line. (Its offset from the
    // line is half its difference from the other site, exactly; the
    // midpoint of sites an ulp apart rounds onto one of them.)
    const Vec2d s = (points_[edge.site] - points_[opposite_site(e)]) / 2;
    if (!(cross(direction(e), s) > 0)) fail(name() + ": its site is not on its left");
    for (std::uint32_t v : {edge.origin, edge.target}) {
      if (v == kInfinity) continue;
      const double da = (vertices_[v] - points_[edge.site]).norm(), db = (vertices_[v] - points_[edges_[edge.twin].site]).norm();
      if (std::abs(da - db) > 1e-9 * (da + db + scale)) fail(name() + ": vertex not equidistant from its sites");
    }
  }
}

}  // namespace geods::voronoi
