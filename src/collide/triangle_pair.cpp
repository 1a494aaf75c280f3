// Exact triangle-triangle intersection from orientation signs only, and the
// double-precision distance between two triangles.
//
// The decision reduces everything to three exact primitives:
// - coplanar sets are tested in the three axis projections (orient2d): two
//   coplanar convex sets meet iff their projections meet in all three, since
//   they meet in every projection if they meet, and at least one projection is
//   one-to-one on their plane (or line);
// - a segment meets a non-degenerate triangle iff its end points are not
//   strictly on one side of the triangle's plane and the line through it
//   passes the three edges with consistent orient3d signs (coplanar: 2-D);
// - two triangles meet iff an edge of one meets the other (non-coplanar
//   triangles: an end point of their common segment lies on an edge; a
//   degenerate triangle is the union of its edges), after the usual plane
//   rejection; coplanar non-degenerate triangles go to 2-D.
#include "geods/collide/triangle_pair.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geods/core/predicates.hpp"
#include "geods/core/triangle.hpp"

namespace geods::collide {
namespace {

int sign(double x) { return (x > 0) - (x < 0); }

// The coordinates of p with axis k dropped.
struct P2 {
  double xy[2];
};
P2 project(const Vec3d& p, int k) {
  const int u = k == 0 ? 1 : 0, v = k == 2 ? 1 : 2;
  return {{p[u], p[v]}};
}
double orient(const P2& a, const P2& b, const P2& c) { return orient2d(a.xy, b.xy, c.xy); }

bool between(const P2& p, const P2& a, const P2& b) {  // p in the bounding box of ab
  for (int i = 0; i < 2; ++i)
    if (p.xy[i] < std::min(a.xy[i], b.xy[i]) || p.xy[i] > std::max(a.xy[i], b.xy[i])) return false;
  return true;
}

// Closed segments pq and rs in the plane (points allowed).
bool segments_meet_2d(const P2& p, const P2& q, const P2& r, const P2& s) {
  const int d1 = sign(orient(r, s, p)), d2 = sign(orient(r, s, q));
  const int d3 = sign(orient(p, q, r)), d4 = sign(orient(p, q, s));
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  return (d1 == 0 && between(p, r, s)) || (d2 == 0 && between(q, r, s)) || (d3 == 0 && between(r, p, q)) ||
         (d4 == 0 && between(s, p, q));
}

// p inside or on the closed triangle abc, which must not be degenerate in the plane.
bool point_in_triangle_2d(const P2& p, const P2& a, const P2& b, const P2& c) {
  const int o = sign(orient(a, b, c));
  if (o == 0) return false;
  return sign(orient(a, b, p)) * o >= 0 && sign(orient(b, c, p)) * o >= 0 && sign(orient(c, a, p)) * o >= 0;
}

bool segment_triangle_2d(const P2& p, const P2& q, const P2 (&t)[3]) {
  for (int i = 0; i < 3; ++i)
    if (segments_meet_2d(p, q, t[i], t[(i + 1) % 3])) return true;
  return point_in_triangle_2d(p, t[0], t[1], t[2]);
}

bool triangles_meet_2d(const P2 (&s)[3], const P2 (&t)[3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_meet_2d(s[i], s[(i + 1) % 3], t[j], t[(j + 1) % 3])) return true;
  return point_in_triangle_2d(s[0], t[0], t[1], t[2]) || point_in_triangle_2d(t[0], s[0], s[1], s[2]);
}

bool collinear(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  for (int k = 0; k < 3; ++k)
    if (orient(project(a, k), project(b, k), project(c, k)) != 0) return false;
  return true;
}

// Coplanar segments (or points), exact.
bool segments_meet_3d(const Vec3d& p, const Vec3d& q, const Vec3d& r, const Vec3d& s) {
  if (orient3d(p, q, r, s) != 0) return false;
  for (int k = 0; k < 3; ++k)
    if (!segments_meet_2d(project(p, k), project(q, k), project(r, k), project(s, k))) return false;
  return true;
}

// Segment pq against a triangle known not to be degenerate; op, oq the
// orient3d of p and q against the triangle's plane.
bool segment_triangle_nondegenerate(const Vec3d& p, const Vec3d& q, const TriangleD& t, double op, double oq) {
  if (op == 0 && oq == 0) {
    for (int k = 0; k < 3; ++k) {
      const P2 t2[3] = {project(t[0], k), project(t[1], k), project(t[2], k)};
      if (!segment_triangle_2d(project(p, k), project(q, k), t2)) return false;
    }
    return true;
  }
  if ((op > 0 && oq > 0) || (op < 0 && oq < 0)) return false;
  const int a = sign(orient3d(p, q, t[0], t[1]));
  const int b = sign(orient3d(p, q, t[1], t[2]));
  const int c = sign(orient3d(p, q, t[2], t[0]));
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

}  // namespace

bool segment_intersects_triangle(const Vec3d& p, const Vec3d& q, const TriangleD& t) {
  if (collinear(t[0], t[1], t[2])) {
    for (int i = 0; i < 3; ++i)
      if (segments_meet_3d(p, q, t[i], t[(i + 1) % 3])) return true;
    return false;
  }
  return segment_triangle_nondegenerate(p, q, t, orient3d(t[0], t[1], t[2], p), orient3d(t[0], t[1], t[2], q));
}

bool triangles_intersect(const TriangleD& s, const TriangleD& t) {
  // Plane rejection first: the common case, and free of the degeneracy tests.
  double ot[3], os[3];
  for (int i = 0; i < 3; ++i) ot[i] = orient3d(s[0], s[1], s[2], t[i]);
  if ((ot[0] > 0 && ot[1] > 0 && ot[2] > 0) || (ot[0] < 0 && ot[1] < 0 && ot[2] < 0)) return false;
  for (int i = 0; i < 3; ++i) os[i] = orient3d(t[0], t[1], t[2], s[i]);
  if ((os[0] > 0 && os[1] > 0 && os[2] > 0) || (os[0] < 0 && os[1] < 0 && os[2] < 0)) return false;
  // (A degenerate triangle gives zeros above and is not rejected.)
  const bool s_flat = collinear(s[0], s[1], s[2]), t_flat = collinear(t[0], t[1], t[2]);
  if (s_flat || t_flat) {
    const TriangleD& edges = s_flat ? s : t;  // the union of its edges
    const TriangleD& other = s_flat ? t : s;
    for (int i = 0; i < 3; ++i)
      if (segment_intersects_triangle(edges[i], edges[(i + 1) % 3], other)) return true;
    return false;
  }
  if (ot[0] == 0 && ot[1] == 0 && ot[2] == 0) {
    for (int k = 0; k < 3; ++k) {
      const P2 s2[3] = {project(s[0], k), project(s[1], k), project(s[2], k)};
      const P2 t2[3] = {project(t[0], k), project(t[1], k), project(t[2], k)};
      if (!triangles_meet_2d(s2, t2)) return false;
    }
    return true;
  }
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (segment_triangle_nondegenerate(s[i], s[j], t, os[i], os[j])) return true;
    if (segment_triangle_nondegenerate(t[i], t[j], s, ot[i], ot[j])) return true;
  }
  return false;
}

double segment_segment_closest(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0, const Vec3d& q1, Vec3d& on_p,
                               Vec3d& on_q) {
  const Vec3d d1 = p1 - p0, d2 = q1 - q0;
  const auto [s, t] = geods::segment_segment_closest(p0, d1, q0, d2);
  on_p = p0 + s * d1;
  on_q = q0 + t * d2;
  return (on_p - on_q).squaredNorm();
}

TrianglePairDistance triangle_distance(const TriangleD& s, const TriangleD& t) {
  TrianglePairDistance r;
  double best = std::numeric_limits<double>::infinity();
  auto offer = [&](const Vec3d& a, const Vec3d& b) {
    const double d = (a - b).squaredNorm();
    if (d < best) best = d, r.on_s = a, r.on_t = b;
  };
  for (int i = 0; i < 3; ++i) {
    offer(s[i], closest_point_on_triangle(s[i], t[0], t[1], t[2]));
    offer(closest_point_on_triangle(t[i], s[0], s[1], s[2]), t[i]);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Vec3d a, b;
      segment_segment_closest(s[i], s[(i + 1) % 3], t[j], t[(j + 1) % 3], a, b);
      offer(a, b);
    }
  if (best > 0 && triangles_intersect(s, t)) {
    // An edge pierces the other triangle: its crossing of the plane is a common point.
    auto pierce = [&](const TriangleD& e, const TriangleD& f, bool e_is_s) {
      const Vec3d n = (f[1] - f[0]).cross(f[2] - f[0]);
      for (int i = 0; i < 3; ++i) {
        const Vec3d &p = e[i], &q = e[(i + 1) % 3];
        const double dp = n.dot(p - f[0]), dq = n.dot(q - f[0]);
        if (dp == dq || dp * dq > 0) continue;
        const Vec3d x = p + (dp / (dp - dq)) * (q - p);
        const Vec3d y = closest_point_on_triangle(x, f[0], f[1], f[2]);
        if (e_is_s) offer(x, y); else offer(y, x);
      }
    };
    pierce(s, t, true);
    pierce(t, s, false);
    best = 0;
  }
  r.distance = std::sqrt(best);
  return r;
}

}  // namespace geods::collide
