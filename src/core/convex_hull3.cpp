// Quickhull in 3D: a tetrahedron of four affinely independent points, each
// other point in the outside set of one face it sees; repeatedly the farthest
// point of an outside set replaces the faces it sees by a cone over their
// horizon, and the outside sets of the removed faces are handed to the new
// faces. Visibility is decided by the exact orient3d, distances ("farthest")
// only choose the order and are computed in plain doubles.
#include "geods/core/convex_hull3.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"

namespace geods {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

bool lex_less(const Vec3d& a, const Vec3d& b) {
  return a[0] != b[0] ? a[0] < b[0] : a[1] != b[1] ? a[1] < b[1] : a[2] < b[2];
}

// Exact: whether a, b, c are collinear (all three coordinate projections are).
bool collinear(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  for (int drop = 0; drop < 3; ++drop) {
    const int x = (drop + 1) % 3, y = (drop + 2) % 3;
    if (orient2d(Vec2d(a[x], a[y]), Vec2d(b[x], b[y]), Vec2d(c[x], c[y])) != 0) return false;
  }
  return true;
}

// Corners of the planar hull of coplanar points (Andrew's monotone chain on
// the projection to a coordinate plane in which a, b, c are not collinear: an
// affine bijection of their plane, so corners stay corners).
std::vector<std::uint32_t> planar_hull(std::span<const Vec3d> p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  int x = 0, y = 1;
  for (int drop = 0; drop < 3; ++drop) {
    x = (drop + 1) % 3, y = (drop + 2) % 3;
    if (orient2d(Vec2d(a[x], a[y]), Vec2d(b[x], b[y]), Vec2d(c[x], c[y])) != 0) break;
  }
  std::vector<std::uint32_t> order(p.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
    return p[i][x] != p[j][x] ? p[i][x] < p[j][x] : p[i][y] != p[j][y] ? p[i][y] < p[j][y] : i < j;
  });
  auto q = [&](std::uint32_t i) { return Vec2d(p[i][x], p[i][y]); };
  std::vector<std::uint32_t> chain;
  auto add_half = [&](auto first, auto last) {
    const std::size_t base = chain.size();
    for (auto it = first; it != last; ++it) {
      while (chain.size() >= base + 2 && orient2d(q(chain[chain.size() - 2]), q(chain.back()), q(*it)) <= 0)
        chain.pop_back();
      chain.push_back(*it);
    }
    chain.pop_back();  // the last point starts the other half
  };
  add_half(order.begin(), order.end());
  add_half(order.rbegin(), order.rend());
  std::sort(chain.begin(), chain.end());
  chain.erase(std::unique(chain.begin(), chain.end()), chain.end());
  return chain;
}

class Quickhull {
 public:
  explicit Quickhull(std::span<const Vec3d> points) : p_(points), start_of_(points.size(), kNone) {}

  ConvexHull3 run(const std::array<std::uint32_t, 4>& tetra) {
    add_tetrahedron(tetra);
    std::vector<std::uint32_t> all;
    for (std::uint32_t i = 0; i < p_.size(); ++i)
      if (i != tetra[0] && i != tetra[1] && i != tetra[2] && i != tetra[3]) all.push_back(i);
    assign(all, 0);
    for (std::uint32_t f = 0; f < faces_.size(); ++f) {
      // New faces are appended, so this loop reaches them too.
      while (faces_[f].alive && !faces_[f].outside.empty()) add_point(f);
    }
    ConvexHull3 hull;
    hull.dimension = 3;
    for (const Face& f : faces_) {
      if (!f.alive) continue;
      hull.faces.push_back(f.v);
      hull.vertices.insert(hull.vertices.end(), f.v.begin(), f.v.end());
    }
    std::sort(hull.vertices.begin(), hull.vertices.end());
    hull.vertices.erase(std::unique(hull.vertices.begin(), hull.vertices.end()), hull.vertices.end());
    return hull;
  }

 private:
  struct Face {
    std::array<std::uint32_t, 3> v;
    std::array<std::uint32_t, 3> next;  // the face across edge (v[i], v[i+1])
    std::vector<std::uint32_t> outside;
    Vec3d normal;  // not normalized; only orders candidate points
    bool alive = true;
  };

  // Exact: whether point i lies strictly outside the plane of face f.
  bool sees(const Face& f, std::uint32_t i) const { return orient3d(p_[f.v[0]], p_[f.v[1]], p_[f.v[2]], p_[i]) < 0; }

  std::uint32_t new_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    Face f;
    f.v = {a, b, c};
    f.next = {kNone, kNone, kNone};
    f.normal = (p_[b] - p_[a]).cross(p_[c] - p_[a]);
    faces_.push_back(std::move(f));
    return std::uint32_t(faces_.size() - 1);
  }

  void add_tetrahedron(const std::array<std::uint32_t, 4>& t) {
    // Faces oriented so that the fourth corner is on their inner side.
    const bool flip = orient3d(p_[t[0]], p_[t[1]], p_[t[2]], p_[t[3]]) < 0;
    const std::uint32_t a = t[0], b = flip ? t[2] : t[1], c = flip ? t[1] : t[2], d = t[3];
    new_face(a, b, c);  // d below
    new_face(a, d, b);
    new_face(b, d, c);
    new_face(c, d, a);
    for (std::uint32_t f = 0; f < 4; ++f)
      for (int e = 0; e < 3; ++e)
        for (std::uint32_t g = 0; g < 4; ++g)
          for (int k = 0; k < 3; ++k)
            if (faces_[g].v[k] == faces_[f].v[(e + 1) % 3] && faces_[g].v[(k + 1) % 3] == faces_[f].v[e])
              faces_[f].next[e] = g;
  }

  // Gives each point to the first face from `first` on that it sees; points
  // that see none are inside the hull and dropped.
  void assign(const std::vector<std::uint32_t>& points, std::uint32_t first) {
    for (std::uint32_t i : points) {
      for (std::uint32_t f = first; f < faces_.size(); ++f) {
        if (faces_[f].alive && sees(faces_[f], i)) {
          faces_[f].outside.push_back(i);
          break;
        }
      }
    }
  }

  void add_point(std::uint32_t f0) {
    Face& f = faces_[f0];
    std::uint32_t apex = f.outside[0];
    double best = -1;
    for (std::uint32_t i : f.outside) {
      const double d = f.normal.dot(p_[i] - p_[f.v[0]]);
      if (d > best) best = d, apex = i;
    }
    // The faces the apex sees form a connected patch: collect it by a
    // depth-first search that records its boundary (the horizon).
    visible_.clear();
    horizon_.clear();
    faces_[f0].alive = false;
    visible_.push_back(f0);
    for (std::size_t k = 0; k < visible_.size(); ++k) {
      const std::uint32_t fi = visible_[k];
      for (int e = 0; e < 3; ++e) {
        const std::uint32_t g = faces_[fi].next[e];
        if (!faces_[g].alive) continue;  // already in the patch
        if (sees(faces_[g], apex)) {
          faces_[g].alive = false;
          visible_.push_back(g);
        } else {
          horizon_.push_back({fi, e});
        }
      }
    }
    // Cone: one face per horizon edge (a, b) of a visible face, (a, b, apex).
    const std::uint32_t first = std::uint32_t(faces_.size());
    for (const auto& [fi, e] : horizon_) {
      const std::uint32_t a = faces_[fi].v[e], b = faces_[fi].v[(e + 1) % 3];
      const std::uint32_t kept = faces_[fi].next[e];
      const std::uint32_t nf = new_face(a, b, apex);
      faces_[nf].next[0] = kept;
      for (int k = 0; k < 3; ++k)
        if (faces_[kept].next[k] == fi) faces_[kept].next[k] = nf;
      start_of_[a] = nf;
    }
    // The horizon is a simple cycle: face (a, b, apex) meets, across (b, apex),
    // the cone face that starts at b, and across (apex, a) the one ending at a.
    for (std::uint32_t nf = first; nf < faces_.size(); ++nf) {
      const std::uint32_t g = start_of_[faces_[nf].v[1]];
      faces_[nf].next[1] = g;
      faces_[g].next[2] = nf;
    }
    for (std::uint32_t nf = first; nf < faces_.size(); ++nf) start_of_[faces_[nf].v[0]] = kNone;
    orphans_.clear();
    for (std::uint32_t fi : visible_) {
      for (std::uint32_t i : faces_[fi].outside)
        if (i != apex) orphans_.push_back(i);
      faces_[fi].outside.clear();
      faces_[fi].outside.shrink_to_fit();
    }
    // A point that saw a removed face and is outside the new hull sees a cone face.
    assign(orphans_, first);
  }

  std::span<const Vec3d> p_;
  std::vector<Face> faces_;
  std::vector<std::uint32_t> start_of_;  // per point: the cone face whose first corner it is
  std::vector<std::uint32_t> visible_, orphans_;
  std::vector<std::pair<std::uint32_t, int>> horizon_;
};

}  // namespace

ConvexHull3 convex_hull3(std::span<const Vec3d> points) {
  if (points.size() >= kNone) throw Error("convex_hull3: more than 2^32 - 1 points");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) throw Error("convex_hull3: point " + std::to_string(i) + " is not finite");
  ConvexHull3 hull;
  if (points.empty()) return hull;
  // Two extremes, then the point farthest from their line, then from their
  // plane (by plain doubles), each confirmed exactly; a full scan decides when
  // the estimate was wrong.
  std::uint32_t i0 = 0, i1 = 0;
  for (std::uint32_t i = 1; i < points.size(); ++i) {
    if (lex_less(points[i], points[i0])) i0 = i;
    if (lex_less(points[i1], points[i])) i1 = i;
  }
  if (points[i0] == points[i1]) {
    hull.dimension = 0;
    hull.vertices = {0};
    return hull;
  }
  const Vec3d &a = points[i0], &b = points[i1];
  std::uint32_t i2 = kNone;
  double best = 0;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    const double d = (b - a).cross(points[i] - a).squaredNorm();
    if (d > best) best = d, i2 = i;
  }
  if (i2 == kNone || collinear(a, b, points[i2])) {
    i2 = kNone;
    for (std::uint32_t i = 0; i < points.size() && i2 == kNone; ++i)
      if (!collinear(a, b, points[i])) i2 = i;
  }
  if (i2 == kNone) {
    hull.dimension = 1;
    hull.vertices = {std::min(i0, i1), std::max(i0, i1)};
    return hull;
  }
  const Vec3d& c = points[i2];
  const Vec3d normal = (b - a).cross(c - a);
  std::uint32_t i3 = kNone;
  best = 0;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    const double d = std::abs(normal.dot(points[i] - a));
    if (d > best) best = d, i3 = i;
  }
  if (i3 == kNone || orient3d(a, b, c, points[i3]) == 0) {
    i3 = kNone;
    for (std::uint32_t i = 0; i < points.size() && i3 == kNone; ++i)
      if (orient3d(a, b, c, points[i]) != 0) i3 = i;
  }
  if (i3 == kNone) {
    hull.dimension = 2;
    hull.vertices = planar_hull(points, a, b, c);
    return hull;
  }
  return Quickhull(points).run({i0, i1, i2, i3});
}

}  // namespace geods
