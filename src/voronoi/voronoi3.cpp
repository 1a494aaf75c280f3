// Voronoi3: each cell is the box clipped by the bisectors of its site and the
// site's Delaunay neighbours (Sutherland-Hodgman on every face, the cut closed
// by a cap polygon ordered around its centre).
#include "geods/voronoi/voronoi3.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "exact_compare.hpp"

namespace geods::voronoi {
namespace {

struct Face {
  std::vector<Vec3d> loop;  // counter-clockwise seen from outside
  std::uint32_t label;
};

// Whether x and y are one point up to rounding: within 1e-12 of the box's
// extent on every axis. (Per axis: a coordinate's rounding scales with the
// box's extent along its own axis; a box thin along one axis is thinner than
// a tolerance scaled by its diagonal, and its two sides would merge.)
bool same_point(const Vec3d& x, const Vec3d& y, const Vec3d& extent) {
  return ((x - y).cwiseAbs().array() <= 1e-12 * extent.array()).all();
}

// Keeps the part of the convex polyhedron where normal . x <= offset; the cut
// becomes a face labelled `label`. `extent`: the box's (same_point).
void clip(std::vector<Face>& faces, const Vec3d& normal, double offset, std::uint32_t label, const Vec3d& extent) {
  std::vector<Vec3d> cut;
  std::vector<Face> kept;
  kept.reserve(faces.size() + 1);
  bool any_outside = false;
  for (Face& face : faces) {
    const std::size_t m = face.loop.size();
    std::vector<double> side(m);
    bool inside = false, outside = false;
    for (std::size_t k = 0; k < m; ++k) {
      side[k] = normal.dot(face.loop[k]) - offset;
      inside |= side[k] <= 0;
      outside |= side[k] > 0;
    }
    any_outside |= outside;
    if (!outside) {
      for (std::size_t k = 0; k < m; ++k)
        if (side[k] == 0) cut.push_back(face.loop[k]);
      kept.push_back(std::move(face));
      continue;
    }
    if (!inside) continue;
    Face out{{}, face.label};
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3d& a = face.loop[k];
      const Vec3d& b = face.loop[(k + 1) % m];
      const double sa = side[k], sb = side[(k + 1) % m];
      if (sa <= 0) out.loop.push_back(a);
      if (sa == 0) cut.push_back(a);
      if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) {
        // computed from the lexicographically smaller end, so that the two faces of the edge agree bit for bit
        const bool forward = std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
        const Vec3d x = forward ? Vec3d(a + (b - a) * (sa / (sa - sb))) : Vec3d(b + (a - b) * (sb / (sb - sa)));
        out.loop.push_back(x);
        cut.push_back(x);
      }
    }
    if (out.loop.size() >= 3) kept.push_back(std::move(out));
  }
  faces.swap(kept);
  if (!any_outside || faces.empty()) return;
  // The cap: the cut points, merged and ordered counter-clockwise around the
  // outward normal, in coordinates where the box is a unit cube (on a box far
  // thinner along one axis than the others, the corners of a cap's two long
  // sides would differ by less than a rounding in the angles around its
  // centre). Merged before the sort, so that no two copies of a corner sort
  // apart.
  std::vector<Vec3d> corners;
  for (const Vec3d& x : cut)
    if (std::none_of(corners.begin(), corners.end(), [&](const Vec3d& y) { return same_point(x, y, extent); }))
      corners.push_back(x);
  Vec3d centre = Vec3d::Zero();
  for (const Vec3d& x : corners) centre += x;
  centre /= double(corners.size());
  // The normal in the unit cube's coordinates (each factor at most 1: no
  // overflow or underflow in the product at extreme scales).
  const Vec3d n = normal.normalized().cwiseProduct(extent / extent.maxCoeff()).normalized();
  const Vec3d u = (std::abs(n[0]) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0)).cross(n).normalized();
  const Vec3d v = n.cross(u);
  struct Around {
    double u, v;  // the corner's offset from the centre in the plane
    Vec3d x;
    int half() const { return v > 0 || (v == 0 && u > 0) ? 0 : 1; }  // angle in [0, pi) or [pi, 2 pi)
  };
  std::vector<Around> around;
  for (const Vec3d& x : corners) {
    const Vec3d d = (x - centre).cwiseQuotient(extent);
    around.push_back({d.dot(u), d.dot(v), x});
  }
  // By angle, without atan2 (whose roundings tie angles a few ulps apart):
  // the half-plane, then the sign of the cross product.
  std::sort(around.begin(), around.end(), [](const Around& a, const Around& b) {
    if (a.half() != b.half()) return a.half() < b.half();
    return a.u * b.v - a.v * b.u > 0;
  });
  Face cap{{}, label};
  for (const Around& a : around) cap.loop.push_back(a.x);
  if (cap.loop.size() >= 3) faces.push_back(std::move(cap));
}

Voronoi3Cell make_cell(std::uint32_t site, const std::vector<Face>& faces, const Vec3d& extent) {
  Voronoi3Cell cell;
  cell.site = site;
  cell.face_offsets.push_back(0);
  for (const Face& face : faces) {
    for (const Vec3d& x : face.loop) {
      // the corners shared by faces: equal, or within rounding of each other
      auto it = std::find_if(cell.vertices.begin(), cell.vertices.end(),
                             [&](const Vec3d& y) { return same_point(x, y, extent); });
      if (it == cell.vertices.end()) {
        cell.vertices.push_back(x);
        it = cell.vertices.end() - 1;
      }
      cell.face_vertices.push_back(std::uint32_t(it - cell.vertices.begin()));
    }
    cell.face_offsets.push_back(std::uint32_t(cell.face_vertices.size()));
    cell.face_neighbors.push_back(face.label);
  }
  if (faces.empty()) return cell;
  // Volume and centroid: tetrahedra from a point inside to the fan of each face.
  Vec3d reference = Vec3d::Zero();
  for (const Vec3d& x : cell.vertices) reference += x;
  reference /= double(cell.vertices.size());
  Vec3d moment = Vec3d::Zero();
  for (const Face& face : faces)
    for (std::size_t k = 1; k + 1 < face.loop.size(); ++k) {
      const Vec3d a = face.loop[0] - reference, b = face.loop[k] - reference, c = face.loop[k + 1] - reference;
      const double v = a.dot(b.cross(c)) / 6;
      cell.volume += v;
      moment += v * (a + b + c) / 4;
    }
  cell.centroid = cell.volume > 0 ? Vec3d(reference + moment / cell.volume) : reference;
  return cell;
}

}  // namespace

Voronoi3::Voronoi3(const Delaunay3& dt, const AABB3d& box) : box_(box) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]) ||
        !std::isfinite(box.hi[a] - box.lo[a]))
      throw Error("Voronoi3: the box must have finite corners with lo < hi on every axis");
  build(dt, {});
}

Voronoi3::Voronoi3(const Delaunay3& dt) {
  if (dt.dimension() != 3)
    throw Error("Voronoi3: clipping to the convex hull needs points that span space (dimension " +
                std::to_string(dt.dimension()) + "); give a box instead");
  for (const std::uint32_t v : dt.tetrahedra()) box_.extend(dt.points()[v]);
  std::vector<Plane> hull;
  // The cells start from a box a little larger than the hull's, so that the hull planes cut every box face away.
  const AABB3d bounds = box_;
  const Vec3d margin = (bounds.hi - bounds.lo) * (1.0 / 16);
  box_ = AABB3d(bounds.lo - margin, bounds.hi + margin);
  for (const auto& t : dt.hull()) {
    const Vec3d &a = dt.points()[t[0]], &b = dt.points()[t[1]], &c = dt.points()[t[2]];
    const Vec3d normal = (b - a).cross(c - a);  // outwards: the triangle is counter-clockwise seen from outside
    hull.push_back({normal, normal.dot(a)});
  }
  build(dt, hull);
  box_ = bounds;
}

void Voronoi3::build(const Delaunay3& dt, std::span<const Plane> hull) {
  const AABB3d& box = box_;
  const auto points = dt.points();
  // Cell volumes are cubic in the coordinates: refuse what they cannot hold.
  if (!points.empty()) check_coordinate_range(points.front().data(), points.size(), 3, 3, 3, "Voronoi3");
  const std::array<Vec3d, 2> corners{box.lo, box.hi};
  check_coordinate_range(corners.front().data(), 2, 3, 3, 3, "Voronoi3 box");
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < points.size(); ++i)
    if (dt.representative(i) == i) sites.push_back(i);
  // With a hull: the sites whose cells may cross it, those on it and those
  // with a Voronoi vertex (a circumcentre) outside it.
  std::vector<std::uint8_t> crosses_hull;
  if (!hull.empty()) {
    crosses_hull.assign(points.size(), 0);
    for (const auto& t : dt.hull())
      for (const std::uint32_t v : t) crosses_hull[v] = 1;
    const auto& tets = dt.tetrahedra();
    std::vector<std::uint8_t> outside(dt.tetrahedron_count());
    parallel_for(0, outside.size(), 1 << 12, [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        const Vec3d c = detail::circumcentre(points[tets[4 * t]], points[tets[4 * t + 1]], points[tets[4 * t + 2]],
                                             points[tets[4 * t + 3]]);
        outside[t] = !std::isfinite(c[0] + c[1] + c[2]) || dt.locate(c, std::uint32_t(t)) == Delaunay3::no_index;
      }
    });
    for (std::size_t t = 0; t < outside.size(); ++t)
      if (outside[t])
        for (int k = 0; k < 4; ++k) crosses_hull[tets[4 * t + k]] = 1;
  }
  const Vec3d extent = box.hi - box.lo;
  std::vector<Face> initial;
  const Vec3d& lo = box.lo;
  const Vec3d& hi = box.hi;
  const Vec3d c[8] = {{lo[0], lo[1], lo[2]}, {hi[0], lo[1], lo[2]}, {lo[0], hi[1], lo[2]}, {hi[0], hi[1], lo[2]},
                      {lo[0], lo[1], hi[2]}, {hi[0], lo[1], hi[2]}, {lo[0], hi[1], hi[2]}, {hi[0], hi[1], hi[2]}};
  initial.push_back({{c[0], c[4], c[6], c[2]}, box_side(0)});
  initial.push_back({{c[1], c[3], c[7], c[5]}, box_side(1)});
  initial.push_back({{c[0], c[1], c[5], c[4]}, box_side(2)});
  initial.push_back({{c[2], c[6], c[7], c[3]}, box_side(3)});
  initial.push_back({{c[0], c[2], c[3], c[1]}, box_side(4)});
  initial.push_back({{c[4], c[5], c[7], c[6]}, box_side(5)});
  cells_.resize(sites.size());
  parallel_for_each_index(
      0, sites.size(),
      [&](std::size_t k) {
        const std::uint32_t s = sites[k];
        std::vector<std::uint32_t> neighbors = dt.vertex_neighbors(s);
        if (dt.dimension() < 3) neighbors.assign(sites.begin(), sites.end());
        // Nearest neighbours first: their bisectors cut the most, the later ones less.
        const Vec3d& p = points[s];
        std::sort(neighbors.begin(), neighbors.end(), [&](std::uint32_t a, std::uint32_t b) {
          return (points[a] - p).squaredNorm() < (points[b] - p).squaredNorm() ||
                 ((points[a] - p).squaredNorm() == (points[b] - p).squaredNorm() && a < b);
        });
        std::vector<Face> faces = initial;
        for (const std::uint32_t w : neighbors) {
          if (w == s) continue;
          // A unit normal: with the sites' difference itself, sites 1e-300
          // apart made products that underflowed to 0, and cells vanished.
          const Vec3d normal = (points[w] - p).stableNormalized();
          clip(faces, normal, normal.dot((points[w] + p) * 0.5), w, extent);
          if (faces.empty()) break;
        }
        if (!hull.empty() && crosses_hull[s]) {
          for (std::uint32_t h = 0; h < hull.size() && !faces.empty(); ++h) {
            // skip the planes the cell's bounding box lies within
            AABB3d bounds;
            for (const Face& f : faces)
              for (const Vec3d& x : f.loop) bounds.extend(x);
            const Vec3d& n = hull[h].normal;
            double reach = 0;
            for (int a = 0; a < 3; ++a) reach += n[a] * (n[a] > 0 ? bounds.hi[a] : bounds.lo[a]);
            if (reach > hull[h].offset) clip(faces, n, hull[h].offset, hull_face(h), extent);
          }
        }
        cells_[k] = make_cell(s, faces, extent);
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
