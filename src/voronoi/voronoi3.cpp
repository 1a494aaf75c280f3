// Voronoi3: a cell is the dual of its site's star of tetrahedra where that
// stands for it (dual_cell), cut by the box's planes where it reaches out;
// otherwise the box clipped by the bisectors of its site and the site's
// Delaunay neighbours. Clipping is Sutherland-Hodgman on every face, the cut
// closed by a cap made of the edges left without a twin, its corners joined
// by identity, not by coordinates.
#include "geods/voronoi/voronoi3.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include <tbb/enumerable_thread_specific.h>

#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/parallel.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "exact_compare.hpp"

namespace geods::voronoi {
namespace {

struct Plane {
  Vec3d normal;
  double offset;  // the half-space normal . x <= offset
};

// A corner of a cell being clipped, with its identity: the box's corners are
// 0..7, and each cut of an edge by a plane gets the next number, the same in
// both faces of the edge. Faces and caps are joined by these numbers, never
// by coordinates, so that a cell stays closed however close its corners lie.
struct Corner {
  Vec3d x;
  std::uint32_t id;
};

struct Face {
  std::vector<Corner> loop;  // counter-clockwise seen from outside
  std::uint32_t label;
};

// Keeps the part of the convex polyhedron where normal . x <= offset; the cut
// becomes a face labelled `label` (one per loop of the cut). `next_id`: the
// number of the next corner. `reach`: per axis, the largest magnitude of the
// box's coordinates.
void clip(std::vector<Face>& faces, const Vec3d& normal, double offset, std::uint32_t label, std::uint32_t& next_id,
          const Vec3d& reach) {
  // A plane the polyhedron lies within, up to the rounding of its corners
  // (another of coplanar hull triangles, a face already cut by it) cuts
  // nothing: cut in rounding, it would leave slivers of no width.
  const double rounding = 16 * std::numeric_limits<double>::epsilon() * (normal.cwiseAbs().dot(reach) + std::abs(offset));
  // Scratch arrays kept by each thread from cut to cut (a cell takes dozens of cuts).
  thread_local std::vector<double> sides;  // every face's corners' signed distances, face after face
  thread_local std::vector<std::uint32_t> on_plane;                                  // corners on the plane or cut into it
  thread_local std::vector<std::pair<std::uint64_t, Corner>> cuts;  // this plane's cuts, by their edge (its ids, low first)
  thread_local std::vector<std::size_t> touching;  // the kept faces with a corner on the plane
  thread_local std::vector<std::pair<Corner, Corner>> edges, open;  // on the plane as the faces run; the cap's
  thread_local std::vector<std::uint8_t> used;
  thread_local std::vector<Corner> loop;  // a cut face's new loop, copied into the face's own storage
  thread_local std::vector<Face> kept;    // swapped with faces: the two arrays take turns
  sides.clear(), on_plane.clear(), cuts.clear(), touching.clear(), edges.clear(), open.clear();
  bool beyond_rounding = false;
  for (const Face& face : faces)
    for (const Corner& c : face.loop) {
      sides.push_back(normal.dot(c.x) - offset);
      beyond_rounding |= sides.back() > rounding;
    }
  if (!beyond_rounding) return;
  kept.clear();
  std::size_t first = 0;  // the face's first corner in sides
  for (Face& face : faces) {
    const std::size_t m = face.loop.size();
    const double* side = sides.data() + first;
    first += m;
    bool inside = false, outside = false, on = false;
    for (std::size_t k = 0; k < m; ++k) {
      inside |= side[k] <= 0;
      outside |= side[k] > 0;
      if (side[k] == 0) on_plane.push_back(face.loop[k].id), on = true;
    }
    if (!outside) {
      if (on) touching.push_back(kept.size());
      kept.push_back(std::move(face));
      continue;
    }
    if (!inside) continue;
    loop.clear();
    for (std::size_t k = 0; k < m; ++k) {
      const Corner& a = face.loop[k];
      const Corner& b = face.loop[(k + 1) % m];
      const double sa = side[k], sb = side[(k + 1) % m];
      if (sa <= 0) loop.push_back(a);
      if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) {
        const std::uint64_t edge = std::uint64_t(std::min(a.id, b.id)) << 32 | std::max(a.id, b.id);
        auto it = std::find_if(cuts.begin(), cuts.end(), [&](const auto& c) { return c.first == edge; });
        if (it == cuts.end()) {  // the edge's first face computes the corner, its other face takes it
          cuts.push_back({edge, {Vec3d(a.x + (b.x - a.x) * (sa / (sa - sb))), next_id++}});
          on_plane.push_back(cuts.back().second.id);
          it = cuts.end() - 1;
        }
        loop.push_back(it->second);
      }
    }
    if (loop.size() >= 3) {
      face.loop.assign(loop.begin(), loop.end());  // in the face's storage: no allocation as a rule
      touching.push_back(kept.size());
      kept.push_back(std::move(face));
    }
  }
  faces.swap(kept);
  // The cap: the edges on the plane that no face has the other way round
  // (their other face was cut away), reversed and chained into loops.
  std::sort(on_plane.begin(), on_plane.end());
  const auto on = [&](std::uint32_t id) { return std::binary_search(on_plane.begin(), on_plane.end(), id); };
  for (const std::size_t f : touching)
    for (std::size_t k = 0; k < faces[f].loop.size(); ++k) {
      const Face& face = faces[f];
      const Corner& a = face.loop[k];
      const Corner& b = face.loop[(k + 1) % face.loop.size()];
      if (on(a.id) && on(b.id)) edges.push_back({a, b});
    }
  for (const auto& [a, b] : edges)
    if (std::none_of(edges.begin(), edges.end(), [&](const auto& e) { return e.first.id == b.id && e.second.id == a.id; }))
      open.push_back({b, a});
  // Each loop ends where it started: at a corner where the cut touches
  // itself, the next edge is any unused one leaving it.
  used.assign(open.size(), 0);
  for (std::size_t start = 0; start < open.size(); ++start) {
    if (used[start]) continue;
    Face cap{{}, label};
    cap.loop.reserve(open.size());
    for (std::size_t e = start;;) {
      used[e] = 1;
      cap.loop.push_back(open[e].first);
      const std::uint32_t to = open[e].second.id;
      if (to == open[start].first.id) break;
      std::size_t next = 0;
      while (next < open.size() && (used[next] || open[next].first.id != to)) ++next;
      if (next == open.size()) break;
      e = next;
    }
    // A loop through a corner twice is two loops.
    for (std::size_t k = 1; k < cap.loop.size(); ++k)
      for (std::size_t j = 0; j < k; ++j)
        if (cap.loop[j].id == cap.loop[k].id) {
          Face part{{cap.loop.begin() + std::ptrdiff_t(j), cap.loop.begin() + std::ptrdiff_t(k)}, label};
          if (part.loop.size() >= 3) faces.push_back(std::move(part));
          cap.loop.erase(cap.loop.begin() + std::ptrdiff_t(j), cap.loop.begin() + std::ptrdiff_t(k));
          k = j;
          break;
        }
    if (cap.loop.size() >= 3) faces.push_back(std::move(cap));
  }
}

// The cell's volume and centroid from its faces: tetrahedra from a point
// inside to the fan of each face.
std::pair<double, Vec3d> measure(const Voronoi3Cell& cell) {
  if (cell.face_count() == 0) return {0.0, Vec3d::Zero()};
  Vec3d reference = Vec3d::Zero();
  for (const Vec3d& x : cell.vertices) reference += x;
  reference /= double(cell.vertices.size());
  // The moment in units of the cell's radius: volume times coordinates is
  // quartic in them and overflows where the volumes still fit.
  double radius = 0;
  for (const Vec3d& x : cell.vertices) radius = std::max(radius, (x - reference).cwiseAbs().maxCoeff());
  if (!(radius > 0)) radius = 1;
  double volume = 0;
  Vec3d moment = Vec3d::Zero();
  for (std::size_t f = 0; f < cell.face_count(); ++f) {
    const std::uint32_t* loop = &cell.face_vertices[cell.face_offsets[f]];
    for (std::uint32_t k = 1; k + 1 < cell.face_offsets[f + 1] - cell.face_offsets[f]; ++k) {
      const Vec3d a = cell.vertices[loop[0]] - reference, b = cell.vertices[loop[k]] - reference,
                  c = cell.vertices[loop[k + 1]] - reference;
      const double v = a.dot(b.cross(c)) / 6;
      volume += v;
      moment += v * ((a + b + c) / (4 * radius));
    }
  }
  return {volume, volume > 0 ? Vec3d(reference + moment / volume * radius) : reference};
}

// Twice face f's vector area (its normal by the loop's turn) and its perimeter.
std::pair<Vec3d, double> face_extent(const Voronoi3Cell& cell, std::size_t f) {
  const std::uint32_t* loop = &cell.face_vertices[cell.face_offsets[f]];
  const std::size_t m = cell.face_offsets[f + 1] - cell.face_offsets[f];
  Vec3d area = Vec3d::Zero();
  double perimeter = 0;
  const Vec3d& x0 = cell.vertices[loop[0]];
  for (std::size_t k = 0; k < m; ++k) {
    const Vec3d& a = cell.vertices[loop[k]];
    const Vec3d& b = cell.vertices[loop[(k + 1) % m]];
    area += (a - x0).cross(b - x0);
    perimeter += (b - a).stableNorm();
  }
  return {area, perimeter};
}

// Whether each edge of the cell's faces is used once in each direction (a
// closed, oriented surface); `edges` is scratch space.
bool is_closed(const Voronoi3Cell& cell, std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges) {
  edges.clear();
  for (std::size_t f = 0; f < cell.face_count(); ++f) {
    const std::uint32_t begin = cell.face_offsets[f], end = cell.face_offsets[f + 1];
    for (std::uint32_t k = begin; k < end; ++k)
      edges.emplace_back(cell.face_vertices[k], cell.face_vertices[k + 1 < end ? k + 1 : begin]);
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t e = 0; e < edges.size(); ++e)
    if ((e > 0 && edges[e] == edges[e - 1]) ||
        !std::binary_search(edges.begin(), edges.end(), std::pair(edges[e].second, edges[e].first)))
      return false;
  return true;
}

// The cell of `site` from its faces: their corners numbered by identity, in the order met.
Voronoi3Cell make_cell(std::uint32_t site, const std::vector<Face>& faces, std::uint32_t corner_ids) {
  Voronoi3Cell cell;
  cell.site = site;
  cell.face_offsets.push_back(0);
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> index(corner_ids, kNone);
  for (const Face& face : faces) {
    for (const Corner& c : face.loop) {
      if (index[c.id] == kNone) {
        index[c.id] = std::uint32_t(cell.vertices.size());
        cell.vertices.push_back(c.x);
      }
      cell.face_vertices.push_back(index[c.id]);
    }
    cell.face_offsets.push_back(std::uint32_t(cell.face_vertices.size()));
    cell.face_neighbors.push_back(face.label);
  }
  std::tie(cell.volume, cell.centroid) = measure(cell);
  return cell;
}

// The bisector of sites p and w, its unit normal towards w. (With the sites'
// difference itself as the normal, sites 1e-300 apart made products that
// underflowed to 0, and cells vanished.)
Plane bisector_plane(const Vec3d& p, const Vec3d& w) {
  const Vec3d normal = (w - p).stableNormalized();
  return {normal, normal.dot((p + w) * 0.5)};
}

// The plane of hull triangle t, its normal pointing out of the hull.
Plane hull_plane(std::span<const Vec3d> points, const std::array<std::uint32_t, 3>& t) {
  const Vec3d &a = points[t[0]], &b = points[t[1]], &c = points[t[2]];
  const Vec3d normal = (b - a).cross(c - a);  // the triangle is counter-clockwise seen from outside
  return {normal, normal.dot(a)};
}

// The Voronoi vertices and the tetrahedra around each site, from which the
// cells of sites off the hull are read off the tetrahedralization (seed
// §5.3.1: the diagram is the dual of Delaunay3) instead of cut out of the box.
struct Dual {
  enum Place : std::uint8_t { inside, near, far };  // of a centre: in the box by a margin, within the box's size of it, beyond
  std::vector<std::uint32_t> tets;      // Delaunay3::tetrahedra(), in an order of their own
  std::vector<std::uint32_t> adjacent;  // Delaunay3::neighbors(), in that order
  std::vector<Vec3d> centre;               // per tetrahedron: its circumcentre, a Voronoi vertex
  std::vector<Place> place;                // per tetrahedron: where its centre lies
  std::vector<std::uint32_t> first;        // per point: a tetrahedron it is a vertex of (no_index: none)
};

// A thread's scratch for dual_cell: per tetrahedron, the site whose star last
// took it (site + 1: 0 is none) and its place in that star; per point, the
// site whose face to it was last made. (Searching the star instead took most
// of the time.)
struct DualMarks {
  DualMarks(std::size_t tetrahedra, std::size_t points) : star_of(tetrahedra, 0), index(tetrahedra), face_of(points, 0) {}
  std::vector<std::uint32_t> star_of, index, face_of;
  std::vector<std::uint32_t> star;  // the star being gathered
};

// The cell of site s as the dual of its star, unclipped: a corner per
// tetrahedron around s (its circumcentre), a face per Delaunay edge (s, w)
// through the centres of the tetrahedra around the edge; volume and centroid
// left to the caller. `clipped` is set where a corner lies outside the box.
// False where the dual cannot stand for the clipped cell: s on the hull (an
// unbounded cell), a corner far beyond the box (a sliver near the hull: cut
// from there, its faces would round), or two corners of a face within 2^-30
// of the cell's coordinates (five sites on a sphere or nearly: a face or an
// edge of no length, which clipping drops).
bool dual_cell(const Dual& d, DualMarks& marks, std::uint32_t s, Voronoi3Cell& cell, bool& clipped) {
  std::vector<std::uint32_t>& star = marks.star;
  const std::uint32_t* tets = d.tets.data();
  star.clear();
  clipped = false;
  // The star: from one tetrahedron across the faces that hold s.
  const auto take = [&](std::uint32_t t) {
    marks.star_of[t] = s + 1;
    marks.index[t] = std::uint32_t(star.size());
    star.push_back(t);
  };
  take(d.first[s]);
  for (std::size_t k = 0; k < star.size(); ++k) {
    const std::uint32_t t = star[k];
    if (d.place[t] == Dual::far) return false;
    clipped |= d.place[t] == Dual::near;
    for (int i = 0; i < 4; ++i) {
      if (tets[4 * t + i] == s) continue;
      const std::uint32_t n = d.adjacent[4 * t + i];
      if (n == Delaunay3::no_index) return false;  // s is on the hull
      if (marks.star_of[n] != s + 1) take(n);
    }
  }
  double scale = 0;
  for (const std::uint32_t t : star) scale = std::max(scale, d.centre[t].cwiseAbs().maxCoeff());
  const double tolerance = std::ldexp(scale, -30);
  cell.site = s;
  cell.vertices.resize(star.size());
  for (std::size_t k = 0; k < star.size(); ++k) cell.vertices[k] = d.centre[star[k]];
  // (Each tetrahedron of the star is a corner of 3 faces; a simple polytope
  // with V corners has V / 2 + 2 faces.)
  cell.face_vertices.clear(), cell.face_vertices.reserve(3 * star.size());
  cell.face_neighbors.clear(), cell.face_neighbors.reserve(star.size() / 2 + 2);
  cell.face_offsets.assign(1, 0), cell.face_offsets.reserve(star.size() / 2 + 3);
  for (const std::uint32_t t0 : star)
    for (int i = 0; i < 4; ++i) {
      const std::uint32_t w = tets[4 * t0 + i];
      if (w == s || marks.face_of[w] == s + 1) continue;
      marks.face_of[w] = s + 1;
      // Around the edge from s to w: in a tetrahedron (s, w, a, b), an even
      // permutation of its positive order, b turns from a counter-clockwise
      // seen from w (det(w - s, a - s, b - s) > 0), and the next tetrahedron
      // that way shares the face (s, w, b): the one opposite a. The centres
      // in that order run counter-clockwise seen from outside the cell.
      std::uint32_t t = t0;
      do {
        const std::uint32_t* v = tets + 4 * t;
        int is = 0, iw = 0;
        while (v[is] != s) ++is;
        while (v[iw] != w) ++iw;
        int ia = 0;
        while (ia == is || ia == iw) ++ia;
        int ib = 6 - is - iw - ia;
        // (is, iw, ia, ib) is even when it has an even number of inversions.
        const int order[4] = {is, iw, ia, ib};
        int inversions = 0;
        for (int x = 0; x < 4; ++x)
          for (int y = x + 1; y < 4; ++y) inversions += order[x] > order[y];
        if (inversions % 2) std::swap(ia, ib);
        const std::uint32_t next = d.adjacent[4 * t + ia];
        if ((d.centre[next] - d.centre[t]).cwiseAbs().maxCoeff() <= tolerance) return false;
        cell.face_vertices.push_back(marks.index[t]);
        t = next;
      } while (t != t0);
      cell.face_offsets.push_back(std::uint32_t(cell.face_vertices.size()));
      cell.face_neighbors.push_back(w);
    }
  return true;
}

// The faces of a cell as loops of corners numbered by the cell's indices (to clip it further).
void faces_of(const Voronoi3Cell& cell, std::vector<Face>& faces) {
  faces.resize(cell.face_count());
  for (std::size_t f = 0; f < cell.face_count(); ++f) {
    faces[f].label = cell.face_neighbors[f];
    faces[f].loop.clear();
    for (std::uint32_t k = cell.face_offsets[f]; k < cell.face_offsets[f + 1]; ++k)
      faces[f].loop.push_back({cell.vertices[cell.face_vertices[k]], cell.face_vertices[k]});
  }
}

}  // namespace

Voronoi3::Voronoi3(const Delaunay3& dt, const AABB3d& box) : box_(box) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]) ||
        !std::isfinite(box.hi[a] - box.lo[a]))
      throw Error("Voronoi3: the box must have finite corners with lo < hi on every axis");
  build(dt);
}

Voronoi3::Voronoi3(const Delaunay3& dt) {
  if (dt.dimension() != 3)
    throw Error("Voronoi3: clipping to the convex hull needs points that span space (dimension " +
                std::to_string(dt.dimension()) + "); give a box instead");
  for (const std::uint32_t v : dt.tetrahedra()) box_.extend(dt.points()[v]);
  hull_ = dt.hull();
  // The cells start from a box a little larger than the hull's, so that the hull planes cut every box face away.
  const AABB3d bounds = box_;
  const Vec3d margin = (bounds.hi - bounds.lo) * (1.0 / 16);
  box_ = AABB3d(bounds.lo - margin, bounds.hi + margin);
  build(dt);
  box_ = bounds;
}

void Voronoi3::build(const Delaunay3& dt) {
  const AABB3d& box = box_;
  const auto points = dt.points();
  points_.assign(points.begin(), points.end());
  std::vector<Plane> hull;
  for (const auto& t : hull_) hull.push_back(hull_plane(points, t));
  // Cell volumes are cubic in the coordinates: refuse what they cannot hold.
  if (!points.empty()) check_coordinate_range(points.front().data(), points.size(), 3, 3, 3, "Voronoi3");
  const std::array<Vec3d, 2> corners{box.lo, box.hi};
  check_coordinate_range(corners.front().data(), 2, 3, 3, 3, "Voronoi3 box");
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < points.size(); ++i)
    if (dt.representative(i) == i) sites.push_back(i);
  const Vec3d reach = box.lo.cwiseAbs().cwiseMax(box.hi.cwiseAbs());
  std::vector<Face> initial;
  const Vec3d& lo = box.lo;
  const Vec3d& hi = box.hi;
  const Corner c[8] = {{{lo[0], lo[1], lo[2]}, 0}, {{hi[0], lo[1], lo[2]}, 1}, {{lo[0], hi[1], lo[2]}, 2},
                       {{hi[0], hi[1], lo[2]}, 3}, {{lo[0], lo[1], hi[2]}, 4}, {{hi[0], lo[1], hi[2]}, 5},
                       {{lo[0], hi[1], hi[2]}, 6}, {{hi[0], hi[1], hi[2]}, 7}};
  initial.push_back({{c[0], c[4], c[6], c[2]}, box_side(0)});
  initial.push_back({{c[1], c[3], c[7], c[5]}, box_side(1)});
  initial.push_back({{c[0], c[1], c[5], c[4]}, box_side(2)});
  initial.push_back({{c[2], c[6], c[7], c[3]}, box_side(3)});
  initial.push_back({{c[0], c[2], c[3], c[1]}, box_side(4)});
  initial.push_back({{c[4], c[5], c[7], c[6]}, box_side(5)});
  // The cells in Z-order of their sites: neighbouring cells share most of
  // their tetrahedra and bisectors, and find them still in cache.
  const std::vector<std::uint32_t> z_order = morton_order(points_);
  std::vector<std::uint32_t> cell_of(points.size(), Delaunay3::no_index);
  for (std::uint32_t k = 0; k < sites.size(); ++k) cell_of[sites[k]] = k;
  std::vector<std::uint32_t> order;
  order.reserve(sites.size());
  for (const std::uint32_t i : z_order)
    if (cell_of[i] != Delaunay3::no_index) order.push_back(cell_of[i]);
  // The dual, its tetrahedra in the Z-order of their first vertex in it (so
  // that a star lies in a few places of memory): every tetrahedron's centre,
  // and whether it lies inside the box by more than 2^-30 of the box's
  // coordinates (a cell whose corners all do lies inside the box, and the box
  // cuts nothing of it), within the box's size of it (the box cuts the cell),
  // or beyond.
  std::optional<Dual> dual;
  std::vector<std::uint32_t> renumbered;  // per tetrahedron of dt: its index in the dual
  if (dt.dimension() == 3) {
    const auto& given = dt.tetrahedra();
    const std::vector<std::uint32_t> given_adjacent = dt.neighbors();
    const std::size_t m = dt.tetrahedron_count();
    std::vector<std::uint32_t> rank(points.size());
    for (std::uint32_t r = 0; r < z_order.size(); ++r) rank[z_order[r]] = r;
    std::vector<std::uint32_t> key(m), slot(points.size() + 1, 0);
    renumbered.resize(m);
    parallel_for(0, m, 1 << 14, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t)
        key[t] = std::min(std::min(rank[given[4 * t]], rank[given[4 * t + 1]]),
                          std::min(rank[given[4 * t + 2]], rank[given[4 * t + 3]]));
    });
    for (const std::uint32_t k : key) ++slot[k + 1];
    for (std::size_t r = 0; r < points.size(); ++r) slot[r + 1] += slot[r];
    for (std::size_t t = 0; t < m; ++t) renumbered[t] = slot[key[t]]++;
    dual.emplace();
    dual->tets.resize(4 * m);
    dual->adjacent.resize(4 * m);
    dual->centre.resize(m);
    dual->place.resize(m);
    const double margin = std::ldexp(reach.maxCoeff(), -30);
    const AABB3d near(box.lo - (box.hi - box.lo), box.hi + (box.hi - box.lo));
    const auto place_of = [&](const Vec3d& c) {
      if ((c.array() > box.lo.array() + margin).all() && (c.array() < box.hi.array() - margin).all()) return Dual::inside;
      if ((c.array() >= near.lo.array()).all() && (c.array() <= near.hi.array()).all()) return Dual::near;
      return Dual::far;  // (NaN too)
    };
    parallel_for(0, m, 1 << 12, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        const std::uint32_t u = renumbered[t];
        for (int i = 0; i < 4; ++i) {
          dual->tets[4 * u + i] = given[4 * t + i];
          const std::uint32_t n = given_adjacent[4 * t + i];
          dual->adjacent[4 * u + i] = n == Delaunay3::no_index ? n : renumbered[n];
        }
        const Vec3d c = detail::circumcentre(points[given[4 * t]], points[given[4 * t + 1]],
                                             points[given[4 * t + 2]], points[given[4 * t + 3]]);
        dual->centre[u] = c;
        dual->place[u] = place_of(c);
      }
    });
    dual->first.assign(points.size(), Delaunay3::no_index);
    for (std::size_t i = 4 * m; i-- > 0;) dual->first[dual->tets[i]] = std::uint32_t(i / 4);
  }
  // With a hull: the sites whose cells may cross it, those on it and those
  // with a Voronoi vertex (a circumcentre) outside it.
  std::vector<std::uint8_t> crosses_hull;
  if (!hull.empty()) {
    crosses_hull.assign(points.size(), 0);
    for (const auto& t : hull_)
      for (const std::uint32_t v : t) crosses_hull[v] = 1;
    const auto& tets = dt.tetrahedra();
    std::vector<std::uint8_t> outside(dt.tetrahedron_count());
    parallel_for(0, outside.size(), 1 << 12, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        const Vec3d& c = dual->centre[renumbered[t]];
        outside[t] = !std::isfinite(c[0] + c[1] + c[2]) || dt.locate(c, std::uint32_t(t)) == Delaunay3::no_index;
      }
    });
    for (std::size_t t = 0; t < outside.size(); ++t)
      if (outside[t])
        for (int k = 0; k < 4; ++k) crosses_hull[tets[4 * t + k]] = 1;
  }
  tbb::enumerable_thread_specific<DualMarks> marks(
      [&] { return DualMarks(dual ? dual->place.size() : 0, points.size()); });
  cells_.resize(sites.size());
  parallel_for_each_index(
      0, order.size(),
      [&](std::size_t j) {
        const std::size_t k = order[j];
        const std::uint32_t s = sites[k];
        thread_local std::vector<Face> faces;
        Voronoi3Cell& cell = cells_[k];
        const bool crosses = !hull.empty() && crosses_hull[s];
        // The hull's planes that reach into the cell, skipping those its
        // bounding box lies within (the box computed again only after a cut).
        const auto clip_to_hull = [&](std::uint32_t& corner_ids) {
          const auto bounds_of = [&] {
            AABB3d bounds;
            for (const Face& f : faces)
              for (const Corner& c : f.loop) bounds.extend(c.x);
            return bounds;
          };
          AABB3d bounds = bounds_of();
          for (std::uint32_t h = 0; h < hull.size() && !faces.empty(); ++h) {
            const Vec3d& n = hull[h].normal;
            double reach_h = 0;
            for (int a = 0; a < 3; ++a) reach_h += n[a] * (n[a] > 0 ? bounds.hi[a] : bounds.lo[a]);
            if (reach_h > hull[h].offset) {
              clip(faces, n, hull[h].offset, hull_face(h), corner_ids, reach);
              bounds = bounds_of();
            }
          }
        };
        bool clipped = false;
        if (dual && dual->first[s] != Delaunay3::no_index && dual_cell(*dual, marks.local(), s, cell, clipped)) {
          if (clipped || crosses) {
            faces_of(cell, faces);
            std::uint32_t corner_ids = std::uint32_t(cell.vertices.size());
            for (int side = 0; side < 6 && clipped && !faces.empty(); ++side) {
              const int a = side / 2;
              const Vec3d normal = Vec3d::Unit(a) * (side % 2 ? 1.0 : -1.0);
              clip(faces, normal, side % 2 ? box.hi[a] : -box.lo[a], box_side(side), corner_ids, reach);
            }
            if (crosses) clip_to_hull(corner_ids);
            cell = make_cell(s, faces, corner_ids);
          } else {
            std::tie(cell.volume, cell.centroid) = measure(cell);
          }
          if (cell.volume > 0) return;
        }
        std::vector<std::uint32_t> neighbors = dt.vertex_neighbors(s);
        if (dt.dimension() < 3) neighbors.assign(sites.begin(), sites.end());
        // Nearest neighbours first: their bisectors cut the most, the later ones less.
        const Vec3d& p = points[s];
        std::sort(neighbors.begin(), neighbors.end(), [&](std::uint32_t a, std::uint32_t b) {
          return (points[a] - p).squaredNorm() < (points[b] - p).squaredNorm() ||
                 ((points[a] - p).squaredNorm() == (points[b] - p).squaredNorm() && a < b);
        });
        faces = initial;
        std::uint32_t corner_ids = 8;
        for (const std::uint32_t w : neighbors) {
          if (w == s) continue;
          const Plane bisector = bisector_plane(p, points[w]);
          clip(faces, bisector.normal, bisector.offset, w, corner_ids, reach);
          if (faces.empty()) break;
        }
        if (crosses) clip_to_hull(corner_ids);
        cell = make_cell(s, faces, corner_ids);
      },
      16);
}

double Voronoi3::volume_total() const {
  double total = 0;
  for (const Voronoi3Cell& cell : cells_) total += cell.volume;
  return total;
}

Voronoi3Stats Voronoi3::stats() const {
  Voronoi3Stats s;
  s.sites = cells_.size();
  s.bytes = cells_.capacity() * sizeof(Voronoi3Cell);
  for (const Voronoi3Cell& cell : cells_) {
    s.faces += cell.face_count();
    s.vertices += cell.vertices.size();
    s.empty += cell.face_count() == 0;
    s.bytes += cell.vertices.capacity() * sizeof(Vec3d) +
               (cell.face_offsets.capacity() + cell.face_vertices.capacity() + cell.face_neighbors.capacity()) *
                   sizeof(std::uint32_t);
  }
  return s;
}

TriMesh Voronoi3::mesh(double explode, std::vector<std::uint32_t>* cell_of_triangle) const {
  TriMesh out;
  const Vec3d centre = (box_.lo + box_.hi) * 0.5;
  if (cell_of_triangle) cell_of_triangle->clear();
  for (std::uint32_t c = 0; c < cells_.size(); ++c) {
    const Voronoi3Cell& cell = cells_[c];
    const Vec3d shift = (cell.centroid - centre) * explode;
    const std::uint32_t base = std::uint32_t(out.vertices.size());
    for (const Vec3d& x : cell.vertices) out.vertices.push_back((x + shift).cast<float>());
    for (std::size_t f = 0; f < cell.face_count(); ++f)
      for (std::uint32_t k = cell.face_offsets[f] + 1; k + 1 < cell.face_offsets[f + 1]; ++k) {
        out.triangles.push_back({base + cell.face_vertices[cell.face_offsets[f]], base + cell.face_vertices[k],
                                 base + cell.face_vertices[k + 1]});
        if (cell_of_triangle) cell_of_triangle->push_back(c);
      }
  }
  return out;
}

}  // namespace geods::voronoi

namespace geods::voronoi {

void Voronoi3::check_cells() const {
  if (!box_.lo.allFinite() || !box_.hi.allFinite() || !(box_.lo.array() < box_.hi.array()).all())
    throw Error("Voronoi3::validate: the box is not finite with lo < hi");
  const std::size_t n = points_.size();
  for (std::size_t h = 0; h < hull_.size(); ++h)
    for (const std::uint32_t v : hull_[h])
      if (v >= n) throw Error("Voronoi3::validate: hull triangle " + std::to_string(h) + " names no point");
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> cell_of(n, kNone);
  for (std::uint32_t c = 0; c < cells_.size(); ++c) {
    const std::uint32_t s = cells_[c].site;
    if (s >= n || (c > 0 && s <= cells_[c - 1].site))
      throw Error("Voronoi3::validate: cell " + std::to_string(c) + " has site " + std::to_string(s) +
                  ", not a point after the previous cell's");
    cell_of[s] = c;
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  std::vector<std::uint8_t> used;
  for (const Voronoi3Cell& cell : cells_) {
    const std::string name = "Voronoi3::validate: the cell of site " + std::to_string(cell.site);
    const std::size_t faces = cell.face_count();
    if (cell.face_offsets.size() != faces + 1 || cell.face_offsets.front() != 0 ||
        cell.face_offsets.back() != cell.face_vertices.size())
      throw Error(name + ": its face offsets do not fit its faces");
    if (faces == 0 && !cell.vertices.empty()) throw Error(name + " has corners but no faces");
    used.assign(cell.vertices.size(), 0);
    for (std::size_t f = 0; f < faces; ++f) {
      const std::uint32_t begin = cell.face_offsets[f], end = cell.face_offsets[f + 1];
      if (end < begin + 3 || end > cell.face_vertices.size())
        throw Error(name + ": face " + std::to_string(f) + " has fewer than 3 corners");
      for (std::uint32_t k = begin; k < end; ++k) {
        const std::uint32_t a = cell.face_vertices[k], b = cell.face_vertices[k + 1 < end ? k + 1 : begin];
        if (a >= cell.vertices.size() || a == b)
          throw Error(name + ": face " + std::to_string(f) + " has a corner out of range or repeated");
        used[a] = 1;
      }
      const std::uint32_t label = cell.face_neighbors[f];
      const bool valid = is_box_side(label)    ? hull_.empty()
                         : is_hull_face(label) ? (label & 0x7fffffffu) < hull_.size()
                                               : label < n && label != cell.site && cell_of[label] != kNone;
      if (!valid) throw Error(name + ": face " + std::to_string(f) + " has the label " + std::to_string(label) +
                              ", which is no other site's, " + (hull_.empty() ? "box side" : "hull triangle"));
    }
    if (!is_closed(cell, edges)) throw Error(name + " is not a closed oriented surface");
    if (std::find(used.begin(), used.end(), 0) != used.end()) throw Error(name + " has a corner on no face");
  }
}

void Voronoi3::validate() const {
  check_cells();
  constexpr double u = std::numeric_limits<double>::epsilon() / 2;
  // How far a corner may be from where it belongs, per axis: each cut rounds
  // (in a fuzz of nearly cospherical lattice subsets, 40 at each spacing
  // from 1e-2 to 1e-11 of the box, and of points on a sphere, none was off
  // by more). Per axis, so that a box thin along one axis is checked as
  // closely along it as any other.
  const Vec3d tolerance = 1e-11 * (box_.hi - box_.lo) + 64 * u * box_.lo.cwiseAbs().cwiseMax(box_.hi.cwiseAbs());
  const auto across = [&](const Vec3d& normal) { return normal.cwiseAbs().dot(tolerance); };  // off a plane
  const auto rounding = [&](const Vec3d& normal, const Vec3d& x) { return 64 * u * normal.cwiseAbs().dot(x.cwiseAbs()); };
  std::vector<Vec3d> sites;
  for (const Voronoi3Cell& cell : cells_) sites.push_back(points_[cell.site]);
  const spatial::KdTree<double, 3> tree{spatial::PointView<double>(std::span<const Vec3d>(sites))};
  std::vector<Plane> hull;
  for (const auto& t : hull_) {
    const Plane plane = hull_plane(points_, t);
    const double norm = plane.normal.norm();
    hull.push_back({plane.normal / norm, plane.offset / norm});
  }
  double total = 0, slack = 0;
  for (const Voronoi3Cell& cell : cells_) {
    const std::string name = "Voronoi3::validate: the cell of site " + std::to_string(cell.site);
    const Vec3d& p = points_[cell.site];
    const bool holds_site = !hull_.empty() || box_.contains(p);  // every site is in its hull
    if (cell.face_count() == 0) {
      // Empty, unless it holds its site: then only when another site lies
      // within the tolerance (the cell is no wider than a rounding).
      const auto nearest = tree.query(p, 2);
      if (holds_site && !(nearest.size() == 2 && std::sqrt(nearest[1].squared_distance) <= tolerance.norm()))
        throw Error(name + " is empty, but the site is inside the " + (hull_.empty() ? "box" : "hull"));
      if (cell.volume != 0) throw Error(name + " is empty, but has volume " + format_number(cell.volume));
      continue;
    }
    for (const Vec3d& x : cell.vertices) {
      if (!(x.array() >= box_.lo.array() - tolerance.array()).all() || !(x.array() <= box_.hi.array() + tolerance.array()).all())
        throw Error(name + " has a corner outside the box");
      for (std::size_t h = 0; h < hull.size(); ++h)
        if (!(hull[h].normal.dot(x) - hull[h].offset <= across(hull[h].normal) + 64 * u * std::abs(hull[h].offset)))
          throw Error(name + " has a corner outside hull triangle " + std::to_string(h));
      // No other site nearer: the cells do not overlap.
      const auto nearest = tree.query(x, 1);
      const double own = (x - p).norm(), other = std::sqrt(nearest[0].squared_distance);
      if (!(own <= other + tolerance.norm() + 8 * u * own))
        throw Error(name + " has a corner nearer to site " + std::to_string(cells_[nearest[0].index].site) + " (" +
                    format_number(other) + ") than to its own (" + format_number(own) + ")");
    }
    double cell_slack = 0;
    for (std::size_t f = 0; f < cell.face_count(); ++f) {
      const std::uint32_t* loop = &cell.face_vertices[cell.face_offsets[f]];
      const std::size_t m = cell.face_offsets[f + 1] - cell.face_offsets[f];
      // The plane its label names (a unit normal, pointing out of the cell).
      const std::uint32_t label = cell.face_neighbors[f];
      Plane plane;
      if (is_box_side(label)) {
        const int side = int(box_side(0) - label);
        plane.normal = Vec3d::Zero();
        plane.normal[side / 2] = side % 2 ? 1 : -1;
        plane.offset = plane.normal[side / 2] * (side % 2 ? box_.hi : box_.lo)[side / 2];
      } else if (is_hull_face(label)) {
        plane = hull[label & 0x7fffffffu];
      } else {
        plane = bisector_plane(p, points_[label]);
      }
      const double off_plane = across(plane.normal) + 64 * u * std::abs(plane.offset);
      const auto off = [&](const Vec3d& x) { return plane.normal.dot(x) - plane.offset; };
      const auto allowed = [&](const Vec3d& x) { return off_plane + rounding(plane.normal, x); };
      // The face's corners on it, the cell's others and its site inside: convex.
      for (std::size_t k = 0; k < m; ++k)
        if (!(std::abs(off(cell.vertices[loop[k]])) <= allowed(cell.vertices[loop[k]])))
          throw Error(name + ": a corner of face " + std::to_string(f) + " is " + format_number(off(cell.vertices[loop[k]])) +
                      " off the plane of its label " + std::to_string(label));
      for (const Vec3d& x : cell.vertices)
        if (!(off(x) <= allowed(x))) throw Error(name + " is not convex at face " + std::to_string(f));
      if (holds_site && !(off(p) <= allowed(p)))
        throw Error(name + " does not hold its site (beyond face " + std::to_string(f) + ")");
      // Counter-clockwise seen from outside: its vector area along the plane's outward normal.
      const auto [area, perimeter] = face_extent(cell, f);
      if (!(area.dot(plane.normal) >= -2 * perimeter * tolerance.norm()))
        throw Error(name + ": face " + std::to_string(f) + " turns the wrong way");
      cell_slack += area.stableNorm() / 2 * across(plane.normal);
    }
    const auto [volume, centroid] = measure(cell);
    if (!(std::abs(volume - cell.volume) <= 1e-9 * std::abs(volume) + cell_slack) ||
        !((centroid - cell.centroid).cwiseAbs().array() <= tolerance.array()).all())
      throw Error(name + ": its volume " + format_number(cell.volume) + " or centroid is not its faces' (" +
                  format_number(volume) + ")");
    total += cell.volume;
    slack += cell_slack;
  }
  // Together they cover the box (or the hull): they do not overlap, so their volumes add up to it.
  double expected = (box_.hi - box_.lo).prod();
  if (!hull_.empty()) {
    const Vec3d centre = (box_.lo + box_.hi) * 0.5;
    expected = 0;
    for (const auto& t : hull_)
      expected += (points_[t[0]] - centre).dot((points_[t[1]] - centre).cross(points_[t[2]] - centre)) / 6;
  }
  if (!(std::abs(total - expected) <= 1e-9 * expected + slack))
    throw Error("Voronoi3::validate: the cells' volumes add up to " + format_number(total) + ", not the " +
                (hull_.empty() ? "box's " : "hull's ") + format_number(expected));
}

}  // namespace geods::voronoi
