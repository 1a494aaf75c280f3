#include "geods/bsp/plane_based.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geods/core/error.hpp"

namespace geods::bsp {

// ---------------------------------------------------------------- Int256

Int256 Int256::from(__int128 v) {
  Int256 r;
  const auto u = static_cast<unsigned __int128>(v);
  r.limb[0] = static_cast<std::uint64_t>(u);
  r.limb[1] = static_cast<std::uint64_t>(u >> 64);
  const std::uint64_t ext = v < 0 ? ~std::uint64_t{0} : 0;
  r.limb[2] = ext;
  r.limb[3] = ext;
  return r;
}

Int256 operator+(const Int256& x, const Int256& y) {
  Int256 r;
  unsigned __int128 carry = 0;
  for (int i = 0; i < 4; ++i) {
    const unsigned __int128 s = static_cast<unsigned __int128>(x.limb[i]) + y.limb[i] + carry;
    r.limb[i] = static_cast<std::uint64_t>(s);
    carry = s >> 64;
  }
  return r;
}

Int256 operator-(const Int256& x, const Int256& y) {
  Int256 neg;
  for (int i = 0; i < 4; ++i) neg.limb[i] = ~y.limb[i];
  return x + neg + Int256::from(1);
}

Int256 operator*(const Int256& x, const Int256& y) {
  Int256 r;
  for (int i = 0; i < 4; ++i) {
    unsigned __int128 carry = 0;
    for (int j = 0; i + j < 4; ++j) {
      const unsigned __int128 p = static_cast<unsigned __int128>(x.limb[i]) * y.limb[j] + r.limb[i + j] + carry;
      r.limb[i + j] = static_cast<std::uint64_t>(p);
      carry = p >> 64;
    }
  }
  return r;
}

int Int256::sign() const {
  if (limb[3] >> 63) return -1;
  return (limb[0] | limb[1] | limb[2] | limb[3]) ? 1 : 0;
}

// ---------------------------------------------------------------- PlaneSet

PlaneSet::PlaneSet() {
  for (int axis = 0; axis < 3; ++axis)
    for (int s : {1, -1}) {
      Plane p;
      (axis == 0 ? p.a : axis == 1 ? p.b : p.c) = s;
      p.d = -kUniverse;
      add(p);
    }
}

std::uint32_t PlaneSet::add(const Plane& p) {
  planes_.push_back(p);
  approx_.push_back({static_cast<double>(p.a), static_cast<double>(p.b), static_cast<double>(p.c),
                     static_cast<double>(p.d)});
  return static_cast<std::uint32_t>(planes_.size() - 1);
}

Plane PlaneSet::through(const std::array<std::int64_t, 3>& p, const std::array<std::int64_t, 3>& q,
                        const std::array<std::int64_t, 3>& r) {
  const std::int64_t u0 = q[0] - p[0], u1 = q[1] - p[1], u2 = q[2] - p[2];
  const std::int64_t v0 = r[0] - p[0], v1 = r[1] - p[1], v2 = r[2] - p[2];
  Plane h;
  h.a = u1 * v2 - u2 * v1;
  h.b = u2 * v0 - u0 * v2;
  h.c = u0 * v1 - u1 * v0;
  h.d = -(h.a * p[0] + h.b * p[1] + h.c * p[2]);
  return h;
}

int PlaneSet::normal_dot_sign(std::uint32_t p, std::uint32_t q) const {
  const int flip = ((p ^ q) & kFlip) ? -1 : 1;
  const Plane& x = planes_[plane_index(p)];
  const Plane& y = planes_[plane_index(q)];
  const __int128 s = static_cast<__int128>(x.a) * y.a + static_cast<__int128>(x.b) * y.b +
                     static_cast<__int128>(x.c) * y.c;
  return flip * ((s > 0) - (s < 0));
}

namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;

// 2x2 minor m[i][j] of columns (c0, c1) over rows (r0, r1) in doubles.
inline double det3(const double* a, const double* b, const double* c, const double* x, const double* y,
                   const double* z, int i, int j, int k) {
  // rows are planes x, y, z; columns i, j, k of each plane's (a, b, c, d)
  (void)a, (void)b, (void)c;
  return x[i] * (y[j] * z[k] - y[k] * z[j]) - x[j] * (y[i] * z[k] - y[k] * z[i]) +
         x[k] * (y[i] * z[j] - y[j] * z[i]);
}

inline double perm3(const double* x, const double* y, const double* z, int i, int j, int k) {
  using std::fabs;
  return fabs(x[i]) * (fabs(y[j] * z[k]) + fabs(y[k] * z[j])) + fabs(x[j]) * (fabs(y[i] * z[k]) + fabs(y[k] * z[i])) +
         fabs(x[k]) * (fabs(y[i] * z[j]) + fabs(y[j] * z[i]));
}

inline std::int64_t coef(const Plane& p, int i) { return i == 0 ? p.a : i == 1 ? p.b : i == 2 ? p.c : p.d; }

// Exact 3x3 determinant of columns i, j, k over planes x, y, z; column 3 (d) may be one of them.
Int256 det3_exact(const Plane& x, const Plane& y, const Plane& z, int i, int j, int k) {
  auto minor = [&](int c0, int c1) -> Int256 {
    // y[c0] z[c1] - y[c1] z[c0]: products of an int64 below 2^62 and one below 2^41 fit __int128.
    const __int128 m = static_cast<__int128>(coef(y, c0)) * coef(z, c1) - static_cast<__int128>(coef(y, c1)) * coef(z, c0);
    return Int256::from(m);
  };
  return Int256::from(coef(x, i)) * minor(j, k) - Int256::from(coef(x, j)) * minor(i, k) +
         Int256::from(coef(x, k)) * minor(i, j);
}

// Exact sign of the sum of doubles (Shewchuk's grow-expansion).
int expansion_sign(const double* terms, int n) {
  double e[32];
  int m = 0;
  for (int t = 0; t < n; ++t) {
    double q = terms[t];
    int k = 0;
    for (int i = 0; i < m; ++i) {
      const double s = q + e[i];
      const double bv = s - q;
      const double err = (q - (s - bv)) + (e[i] - bv);
      if (err != 0) e[k++] = err;
      q = s;
    }
    if (q != 0) e[k++] = q;
    m = k;
  }
  if (m == 0) return 0;
  return (e[m - 1] > 0) - (e[m - 1] < 0);
}

}  // namespace

int PlaneSet::side(std::uint32_t h, std::uint32_t p, std::uint32_t q, std::uint32_t r) const {
  const int flip = (h & kFlip) ? -1 : 1;
  h = plane_index(h), p = plane_index(p), q = plane_index(q), r = plane_index(r);
  if (h == p || h == q || h == r) return 0;  // one of the planes through the point
  const double* x = approx_[p].data();
  const double* y = approx_[q].data();
  const double* z = approx_[r].data();
  const double* hh = approx_[h].data();
  // Homogeneous point: W = det(a b c), X = -det(d b c), Y = -det(a d c), Z = -det(a b d).
  const double w = det3(nullptr, nullptr, nullptr, x, y, z, 0, 1, 2);
  const double xx = -det3(nullptr, nullptr, nullptr, x, y, z, 3, 1, 2);
  const double yy = -det3(nullptr, nullptr, nullptr, x, y, z, 0, 3, 2);
  const double zz = -det3(nullptr, nullptr, nullptr, x, y, z, 0, 1, 3);
  const double v = hh[0] * xx + hh[1] * yy + hh[2] * zz + hh[3] * w;
  const double pw = perm3(x, y, z, 0, 1, 2);
  const double bound = 32 * kU *
                       (std::fabs(hh[0]) * perm3(x, y, z, 3, 1, 2) + std::fabs(hh[1]) * perm3(x, y, z, 0, 3, 2) +
                        std::fabs(hh[2]) * perm3(x, y, z, 0, 1, 3) + std::fabs(hh[3]) * pw);
  const double wbound = 16 * kU * pw;
  if (std::fabs(v) > bound && std::fabs(w) > wbound) return ((v > 0) == (w > 0)) ? flip : -flip;
  const Plane& P = planes_[p];
  const Plane& Q = planes_[q];
  const Plane& R = planes_[r];
  const Plane& H = planes_[h];
  const Int256 W = det3_exact(P, Q, R, 0, 1, 2);
  const Int256 X = Int256::from(0) - det3_exact(P, Q, R, 3, 1, 2);
  const Int256 Y = Int256::from(0) - det3_exact(P, Q, R, 0, 3, 2);
  const Int256 Z = Int256::from(0) - det3_exact(P, Q, R, 0, 1, 3);
  const Int256 V = Int256::from(H.a) * X + Int256::from(H.b) * Y + Int256::from(H.c) * Z + Int256::from(H.d) * W;
  const int ws = W.sign();
  if (ws == 0) throw Error("bsp: three planes without a common point (internal error)");
  return V.sign() * ws * flip;
}

std::array<double, 3> PlaneSet::point(std::uint32_t p, std::uint32_t q, std::uint32_t r, double* radius) const {
  p = plane_index(p), q = plane_index(q), r = plane_index(r);
  const double* x = approx_[p].data();
  const double* y = approx_[q].data();
  const double* z = approx_[r].data();
  const double w = det3(nullptr, nullptr, nullptr, x, y, z, 0, 1, 2);
  if (w == 0) {
    if (radius) *radius = std::numeric_limits<double>::infinity();
    return {0, 0, 0};
  }
  const std::array<double, 3> v{-det3(nullptr, nullptr, nullptr, x, y, z, 3, 1, 2) / w,
                                -det3(nullptr, nullptr, nullptr, x, y, z, 0, 3, 2) / w,
                                -det3(nullptr, nullptr, nullptr, x, y, z, 0, 1, 3) / w};
  if (radius) {
    const double pw = perm3(x, y, z, 0, 1, 2);
    const double pm = std::max({perm3(x, y, z, 3, 1, 2), perm3(x, y, z, 0, 3, 2), perm3(x, y, z, 0, 1, 3)});
    const double m = std::max({std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2])});
    *radius = 64 * kU * (pm + m * pw) / std::fabs(w) + 1e-300;
  }
  return v;
}

int PlaneSet::side(std::uint32_t h, const double* x) const {
  const int flip = (h & kFlip) ? -1 : 1;
  h = plane_index(h);
  const double* c = approx_[h].data();
  const double v = c[0] * x[0] + c[1] * x[1] + c[2] * x[2] + c[3];
  const double bound =
      8 * kU * (std::fabs(c[0] * x[0]) + std::fabs(c[1] * x[1]) + std::fabs(c[2] * x[2]) + std::fabs(c[3]));
  if (std::fabs(v) > bound) return v > 0 ? flip : -flip;
  // Exact: a, b, c are exact doubles (< 2^41); each product is split by fma, d into two doubles.
  const Plane& P = planes_[h];
  double t[8];
  for (int i = 0; i < 3; ++i) {
    const double ci = static_cast<double>(coef(P, i));
    const double prod = ci * x[i];
    t[2 * i] = prod;
    t[2 * i + 1] = std::fma(ci, x[i], -prod);
  }
  const double dhi = static_cast<double>(P.d);
  t[6] = dhi;
  t[7] = static_cast<double>(P.d - static_cast<std::int64_t>(dhi));
  return flip * expansion_sign(t, 8);
}

void PlaneSet::reserve(std::size_t planes, std::size_t points) {
  planes_.reserve(planes);
  approx_.reserve(planes);
  points_.reserve(points);
}

std::uint32_t PlaneSet::add_point(const std::array<std::int64_t, 3>& q) {
  points_.push_back(q);
  return static_cast<std::uint32_t>(points_.size() - 1);
}

int PlaneSet::side(std::uint32_t h, const Vertex& v) const {
  if (v.point == kNoPoint) return side(h, v.p, v.q, v.r);
  const Plane& P = planes_[plane_index(h)];
  const auto& x = points_[v.point];
  const __int128 val = static_cast<__int128>(P.a) * x[0] + static_cast<__int128>(P.b) * x[1] +
                       static_cast<__int128>(P.c) * x[2] + P.d;
  const int s = (val > 0) - (val < 0);
  return (h & kFlip) ? -s : s;
}

std::array<double, 3> PlaneSet::point(const Vertex& v, double* radius) const {
  if (v.point == kNoPoint) return point(v.p, v.q, v.r, radius);
  if (radius) *radius = 0;
  const auto& x = points_[v.point];
  return {static_cast<double>(x[0]), static_cast<double>(x[1]), static_cast<double>(x[2])};
}

// ---------------------------------------------------------------- polygons

Polygon Polygon::reversed() const {
  // Vertex k of the reversed edge list is vertex n - k of this one.
  Polygon r;
  const std::size_t n = edges.size();
  r.support = support ^ kFlip;
  r.source = source;
  r.edges.assign(edges.rbegin(), edges.rend());
  r.points.resize(n);
  for (std::size_t k = 0; k < n; ++k) r.points[k] = points[(n - k) % n];
  return r;
}

Side classify(const PlaneSet& planes, const Polygon& poly, std::uint32_t h, std::vector<int>* signs) {
  const std::size_t n = poly.edges.size();
  bool neg = false, pos = false;
  if (signs) signs->resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const int s = planes.side(h, poly.vertex(k));
    if (signs) (*signs)[k] = s;
    neg |= s < 0;
    pos |= s > 0;
  }
  if (neg && pos) return Side::straddling;
  if (neg) return Side::negative;
  if (pos) return Side::positive;
  return Side::coplanar;
}

void split(const PlaneSet& planes, const Polygon& poly, std::uint32_t h, const std::vector<int>& signs, Polygon& neg,
           Polygon& pos) {
  (void)planes;
  const std::size_t n = poly.edges.size();
  for (int side : {-1, 1}) {
    Polygon& out = side < 0 ? neg : pos;
    out.support = poly.support;
    out.source = poly.source;
    out.edges.clear();
    out.points.clear();
    // Edge k runs from vertex k to vertex k+1; it is kept if part of it is strictly on `side`.
    // The vertices strictly on `side` are one cyclic run (convexity): start at the edge that
    // enters it, close the piece with h after the edge that leaves it. A new vertex on h that
    // is an old vertex (sign 0) keeps its snapped point.
    auto on_side = [&](std::size_t k) { return signs[k % n] * side > 0; };
    std::size_t start = 0;
    while (!(!on_side(start) && on_side(start + 1))) ++start;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = (start + i) % n;
      if (!on_side(k) && !on_side(k + 1)) continue;
      // The vertex where this edge starts: the old vertex k, or h ∩ edge k (entering edge).
      out.points.push_back(on_side(k) || signs[k] == 0 ? poly.points[k] : kNoPoint);
      out.edges.push_back(poly.edges[k]);
      // Edge planes keep the interior on their negative side, so the positive piece
      // closes with the opposite of h.
      if (!on_side(k + 1)) {
        const std::size_t k1 = (k + 1) % n;
        out.points.push_back(signs[k1] == 0 ? poly.points[k1] : kNoPoint);  // edge k ∩ h
        out.edges.push_back(side < 0 ? h : (h ^ kFlip));
      }
    }
  }
}

bool clip(const PlaneSet& planes, Polygon& poly, std::uint32_t h, int keep) {
  std::vector<int> signs;
  const Side s = classify(planes, poly, h, &signs);
  if (s == Side::coplanar) return false;
  if (s == Side::negative) return keep < 0;
  if (s == Side::positive) return keep > 0;
  Polygon neg, pos;
  split(planes, poly, h, signs, neg, pos);
  poly = keep < 0 ? std::move(neg) : std::move(pos);
  return true;
}

Plane edge_plane(const std::array<std::int64_t, 3>& a, const std::array<std::int64_t, 3>& b,
                 const std::array<std::int64_t, 3>& c, int axis) {
  const std::int64_t u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  std::int64_t e[3] = {0, 0, 0};
  e[axis] = 1;
  Plane m;
  m.a = u[1] * e[2] - u[2] * e[1];
  m.b = u[2] * e[0] - u[0] * e[2];
  m.c = u[0] * e[1] - u[1] * e[0];
  const std::int64_t s = m.a * (c[0] - a[0]) + m.b * (c[1] - a[1]) + m.c * (c[2] - a[2]);
  if (s > 0) m.a = -m.a, m.b = -m.b, m.c = -m.c;
  m.d = -(m.a * a[0] + m.b * a[1] + m.c * a[2]);
  return m;
}

bool triangle_polygon(PlaneSet& planes, const std::array<std::int64_t, 3>& p0, const std::array<std::int64_t, 3>& p1,
                      const std::array<std::int64_t, 3>& p2, std::array<std::uint32_t, 3> ids, Polygon& out) {
  const Plane s = PlaneSet::through(p0, p1, p2);
  if (s.a == 0 && s.b == 0 && s.c == 0) return false;
  const std::int64_t an[3] = {s.a < 0 ? -s.a : s.a, s.b < 0 ? -s.b : s.b, s.c < 0 ? -s.c : s.c};
  const int axis = an[0] >= an[1] && an[0] >= an[2] ? 0 : (an[1] >= an[2] ? 1 : 2);
  out.support = planes.add(s);
  out.edges = {planes.add(edge_plane(p0, p1, p2, axis)), planes.add(edge_plane(p1, p2, p0, axis)),
               planes.add(edge_plane(p2, p0, p1, axis))};
  out.points = {ids[0], ids[1], ids[2]};
  return true;
}

Polygon universe_polygon(const PlaneSet& planes, std::uint32_t h) {
  const Plane& H = planes[h];
  const std::int64_t f = (h & kFlip) ? -1 : 1;
  const std::int64_t n[3] = {f * H.a, f * H.b, f * H.c};
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if ((n[i] < 0 ? -n[i] : n[i]) > (n[k] < 0 ? -n[k] : n[k])) k = i;
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  // Box planes: 2 * axis is "x_axis <= L", 2 * axis + 1 is "x_axis >= -L".
  Polygon p;
  p.support = h;
  p.edges = {static_cast<std::uint32_t>(2 * j + 1), static_cast<std::uint32_t>(2 * i),
             static_cast<std::uint32_t>(2 * j), static_cast<std::uint32_t>(2 * i + 1)};
  if (n[k] < 0) std::swap(p.edges[1], p.edges[3]);
  p.points.assign(4, kNoPoint);
  if (!clip(planes, p, static_cast<std::uint32_t>(2 * k), -1) ||
      !clip(planes, p, static_cast<std::uint32_t>(2 * k + 1), -1))
    throw Error("bsp: a plane misses the universe box (internal error)");
  return p;
}

double approx_area(const PlaneSet& planes, const Polygon& poly) {
  const std::size_t n = poly.edges.size();
  std::array<double, 3> c{0, 0, 0};
  std::vector<std::array<double, 3>> v(n);
  for (std::size_t k = 0; k < n; ++k) v[k] = planes.point(poly.vertex(k));
  double s[3] = {0, 0, 0};
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const double a[3] = {v[k][0] - v[0][0], v[k][1] - v[0][1], v[k][2] - v[0][2]};
    const double b[3] = {v[k + 1][0] - v[0][0], v[k + 1][1] - v[0][1], v[k + 1][2] - v[0][2]};
    s[0] += a[1] * b[2] - a[2] * b[1];
    s[1] += a[2] * b[0] - a[0] * b[2];
    s[2] += a[0] * b[1] - a[1] * b[0];
  }
  (void)c;
  return 0.5 * std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

std::array<double, 3> approx_centroid(const PlaneSet& planes, const Polygon& poly) {
  std::array<double, 3> c{0, 0, 0};
  const std::size_t n = poly.edges.size();
  for (std::size_t k = 0; k < n; ++k) {
    const auto v = planes.point(poly.vertex(k));
    for (int i = 0; i < 3; ++i) c[i] += v[i] / static_cast<double>(n);
  }
  return c;
}

}  // namespace geods::bsp
