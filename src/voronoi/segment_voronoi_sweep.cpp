// Fortune's sweep for the Voronoi diagram of points and segments.
//
// The structure follows Boost.Polygon's voronoi_builder (site events for
// points and segments sorted along x, a beach line of bisector nodes (left
// arc, right arc) ordered along y, circle events for consecutive triples, a
// temporary node per segment between its two sides until its second
// endpoint is reached); the predicates and the tangent-circle constructions
// are our own: orientation tests on the snapped integers are exact in double,
// and the circles tangent to points and lines come from closed forms whose
// root is chosen by the cyclic order of the three tangency points on the
// circle (clockwise for a circle event). Every decision is exact: the circle
// forms are evaluated in filtered interval arithmetic and, when the filter
// cannot decide, in MPFR balls beyond the expression's BFMSS separation bound
// (segment_voronoi_exact.hpp); no epsilon.
#include "segment_voronoi_sweep.hpp"

#include "segment_voronoi_exact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <type_traits>
#include <utility>

namespace geods::voronoi::detail {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

struct Pt {
  double x = 0, y = 0;
  friend bool operator==(const Pt& a, const Pt& b) { return a.x == b.x && a.y == b.y; }
  friend bool operator!=(const Pt& a, const Pt& b) { return !(a == b); }
};
inline bool point_less(const Pt& a, const Pt& b) { return a.x != b.x ? a.x < b.x : a.y < b.y; }

// Sign of the cross product (b - a) x (c - a); exact for |coordinates| <= 2^25.
inline int orient(const Pt& a, const Pt& b, const Pt& c) {
  const double v = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  return (v > 0) - (v < 0);
}
inline int cross_sign(double ax, double ay, double bx, double by) {
  const double v = ax * by - ay * bx;
  return (v > 0) - (v < 0);
}
constexpr int kRight = -1, kLeft = 1;

struct Site {
  Pt p0, p1;
  std::uint32_t sorted_index = 0;
  std::uint32_t id = 0;  // elementary site id
  bool segment = false;
  bool inverse = false;
  double x0() const { return p0.x; }
  double y0() const { return p0.y; }
  double y1() const { return p1.y; }
  Site& invert() {
    std::swap(p0, p1);
    inverse = !inverse;
    return *this;
  }
  friend bool operator==(const Site& a, const Site& b) { return a.p0 == b.p0 && a.p1 == b.p1; }
};
inline bool is_vertical(const Site& s) { return s.p0.x == s.p1.x; }

bool site_less(const Site& lhs, const Site& rhs) {
  if (lhs.x0() != rhs.x0()) return lhs.x0() < rhs.x0();
  if (!lhs.segment) {
    if (!rhs.segment) return lhs.y0() < rhs.y0();
    if (is_vertical(rhs)) return lhs.y0() <= rhs.y0();
    return true;
  }
  if (is_vertical(rhs)) {
    if (is_vertical(lhs)) return lhs.y0() < rhs.y0();
    return false;
  }
  if (is_vertical(lhs)) return true;
  if (lhs.y0() != rhs.y0()) return lhs.y0() < rhs.y0();
  return orient(lhs.p1, lhs.p0, rhs.p1) == kLeft;
}

// ---------------------------------------------------------------- distance predicate
// Does the horizontal line through the new point hit the right arc of the
// node (left, right) first (the point is above the breakpoint)? Each side is
// the x distance, from the new point, of the centre of the circle through (or
// tangent to) the arc's site and tangent to the horizontal line at the point
// (up to a common factor); the comparisons are exact (integers, or
// exact::filtered_sign for the segment arcs, whose values hold a square root).
template <class T>
T distance_to_point_arc(const Site& site, const Pt& p) {  // site.p0.x != p.x
  const double dx = site.p0.x - p.x, dy = site.p0.y - p.y;
  return T(dx * dx + dy * dy) / T(2 * dx);  // integers below 2^53: exact
}
template <class T>
T distance_to_segment_arc(const Site& site, const Pt& p) {
  if (is_vertical(site)) return T(site.p0.x - p.x) * T(0.5);
  const double a1 = site.p1.x - site.p0.x, b1 = site.p1.y - site.p0.y;
  const T len = sqrt(T(a1 * a1 + b1 * b1));
  const T k = b1 >= 0 ? T(1) / (T(b1) + len) : (len - T(b1)) / T(a1 * a1);
  const double cross = a1 * (p.y - site.p0.y) - b1 * (p.x - site.p0.x);  // exact
  return k * T(cross);
}

// n1 / dx1 < n2 / dx2 for integers (|n| < 2^54, |dx| < 2^27), dx = 0 meaning +infinity.
bool point_arc_less(const Site& left, const Site& right, const Pt& p) {
  using i128 = __int128;
  const double dx1 = left.p0.x - p.x, dy1 = left.p0.y - p.y, dx2 = right.p0.x - p.x, dy2 = right.p0.y - p.y;
  if (dx1 == 0) return false;
  if (dx2 == 0) return true;
  using i64 = std::int64_t;  // through 64-bit integers: a direct double -> __int128 conversion is a library call
  const i128 n1 = static_cast<i64>(dx1 * dx1 + dy1 * dy1), n2 = static_cast<i64>(dx2 * dx2 + dy2 * dy2);
  const i128 l = n1 * static_cast<i64>(dx2), r = n2 * static_cast<i64>(dx1);
  return (dx1 > 0) == (dx2 > 0) ? l < r : l > r;
}

bool pp_predicate(const Site& left, const Site& right, const Pt& p) {
  const Pt& l = left.p0;
  const Pt& r = right.p0;
  if (l.x > r.x) {
    if (p.y <= l.y) return false;
  } else if (l.x < r.x) {
    if (p.y >= r.y) return true;
  } else {
    return l.y + r.y < 2 * p.y;
  }
  return point_arc_less(left, right, p);
}

enum class Fast { less, undefined, more };

Fast fast_ps(const Site& left, const Site& right, const Pt& p, bool reverse_order) {
  const Pt& site_point = left.p0;
  const Pt& s0 = right.p0;
  const Pt& s1 = right.p1;
  if (orient(s0, s1, p) != kRight) return !right.inverse ? Fast::less : Fast::more;
  if (is_vertical(right)) {
    if (p.y < site_point.y && !reverse_order) return Fast::more;
    if (p.y > site_point.y && reverse_order) return Fast::less;
    return Fast::undefined;
  }
  const int o = cross_sign(s1.x - s0.x, s1.y - s0.y, p.x - site_point.x, p.y - site_point.y);
  if (o == kLeft) {
    if (!right.inverse) return reverse_order ? Fast::less : Fast::undefined;
    return reverse_order ? Fast::undefined : Fast::more;
  }
  // a (dy^2 - dx^2) against 2 b dx dy, exactly (|terms| < 2^80).
  using i128 = __int128;
  using i64 = std::int64_t;
  const i128 a = static_cast<i64>(s1.x - s0.x), b = static_cast<i64>(s1.y - s0.y);
  const i128 dx = static_cast<i64>(p.x - site_point.x), dy = static_cast<i64>(p.y - site_point.y);
  const i128 lhs = a * (dy + dx) * (dy - dx), rhs = 2 * b * dx * dy;
  if (lhs != rhs) {
    if ((lhs > rhs) ^ reverse_order) return reverse_order ? Fast::less : Fast::more;
    return Fast::undefined;
  }
  return Fast::undefined;
}

bool ps_predicate(const Site& left, const Site& right, const Pt& p, bool reverse_order) {
  const Fast f = fast_ps(left, right, p, reverse_order);
  if (f != Fast::undefined) return f == Fast::less;
  if (left.p0.x == p.x) return reverse_order;  // the point arc's distance is +infinity
  const int s = exact::filtered_sign([&](auto type) {
    using T = typename decltype(type)::type;
    return distance_to_point_arc<T>(left, p) - distance_to_segment_arc<T>(right, p);
  });
  return reverse_order ^ (s < 0);
}

bool ss_predicate(const Site& left, const Site& right, const Pt& p) {
  if (left.sorted_index == right.sorted_index) return orient(left.p0, left.p1, p) == kLeft;
  return exact::filtered_sign([&](auto type) {
           using T = typename decltype(type)::type;
           return distance_to_segment_arc<T>(left, p) - distance_to_segment_arc<T>(right, p);
         }) < 0;
}

bool distance_predicate(const Site& left, const Site& right, const Pt& p) {
  if (!left.segment) return !right.segment ? pp_predicate(left, right, p) : ps_predicate(left, right, p, false);
  return !right.segment ? ps_predicate(right, left, p, true) : ss_predicate(left, right, p);
}

// ---------------------------------------------------------------- beach line
struct Key {
  mutable Site left, right;
  Key() = default;
  explicit Key(const Site& s) : left(s), right(s) {}
  Key(const Site& l, const Site& r) : left(l), right(r) {}
};

const Site& comparison_site(const Key& k) {
  return k.left.sorted_index > k.right.sorted_index ? k.left : k.right;
}
const Pt& comparison_point(const Site& s) { return point_less(s.p0, s.p1) ? s.p0 : s.p1; }
std::pair<double, int> comparison_y(const Key& k, bool is_new = true) {
  if (k.left.sorted_index == k.right.sorted_index) return {k.left.y0(), 0};
  if (k.left.sorted_index > k.right.sorted_index) {
    if (!is_new && k.left.segment && is_vertical(k.left)) return {k.left.y0(), 1};
    return {k.left.y1(), 1};
  }
  return {k.right.y0(), -1};
}

struct KeyLess {
  bool operator()(const Key& n1, const Key& n2) const {
    const Site& s1 = comparison_site(n1);
    const Site& s2 = comparison_site(n2);
    const Pt& p1 = comparison_point(s1);
    const Pt& p2 = comparison_point(s2);
    if (p1.x < p2.x) return distance_predicate(n1.left, n1.right, p2);
    if (p1.x > p2.x) return !distance_predicate(n2.left, n2.right, p1);
    if (s1.sorted_index == s2.sorted_index) return comparison_y(n1) < comparison_y(n2);
    if (s1.sorted_index < s2.sorted_index) {
      const auto y1 = comparison_y(n1, false), y2 = comparison_y(n2, true);
      if (y1.first != y2.first) return y1.first < y2.first;
      return !s1.segment ? y1.second < 0 : false;
    }
    const auto y1 = comparison_y(n1, true), y2 = comparison_y(n2, false);
    if (y1.first != y2.first) return y1.first < y2.first;
    return !s2.segment ? y2.second > 0 : true;
  }
};

struct NodeData {
  std::uint32_t edge = kNone;
  std::uint8_t end = 0;
  std::uint32_t circle = kNone;
};
using BeachLine = std::map<Key, NodeData, KeyLess>;
using BeachIt = BeachLine::iterator;

// ---------------------------------------------------------------- circles
// The circle tangent to three sites, computed in a number type T (exact::Iv,
// the filter, or exact::Bx, the exact evaluation): every branch is taken on
// an exact sign (sgn of T throws when the filter cannot tell), so both types
// follow the same path and the event exists exactly when the exact circle
// does. The forms keep the expressions shallow (integer coefficients and the
// segment lengths L = sqrt(dx^2 + dy^2); one more square root for the
// quadratics), which keeps the separation bounds of the exact stage small.
template <class T>
struct CircleT {
  T x, y, lower_x;
};

// A segment site's supporting line: c = (dy, -dx) is the integer right normal
// (the site's side), L^2 = dx^2 + dy^2, and the signed distance of X is
// (c . (X - a)) / L.
struct LineI {
  double cx, cy, ax, ay, len2;
};
inline LineI site_line(const Site& s) {
  const double dx = s.p1.x - s.p0.x, dy = s.p1.y - s.p0.y;
  return LineI{dy, -dx, s.p0.x, s.p0.y, dx * dx + dy * dy};  // exact (|len2| <= 2^53)
}
// c . (p - a) for an integer point: exact (|terms| <= 2^52).
inline double line_offset(const LineI& l, const Pt& p) { return l.cx * (p.x - l.ax) + l.cy * (p.y - l.ay); }

template <class T>
bool circle_ppp(const Site& a, const Site& b, const Site& c, CircleT<T>& out) {
  if (orient(a.p0, b.p0, c.p0) != kRight) return false;
  const double ax = a.p0.x, ay = a.p0.y;
  const double bx = b.p0.x - ax, by = b.p0.y - ay, cx = c.p0.x - ax, cy = c.p0.y - ay;  // exact
  const T d(2 * (bx * cy - by * cx));                                                    // exact
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;                            // exact
  const T ux = (T(cy) * T(b2) - T(by) * T(c2)) / d, uy = (T(bx) * T(c2) - T(cx) * T(b2)) / d;
  out.x = T(ax) + ux;
  out.y = T(ay) + uy;
  out.lower_x = out.x + sqrt(ux * ux + uy * uy);
  return true;
}

// Roots of A s^2 + 2 B s + C = 0 (A = 0 when `linear`, decided exactly by the
// caller), in the stable form s0 = q / A, s1 = C / q with q = -(B + sign(B) sqrt(B^2 - AC)).
template <class T>
int quadratic_roots(const T& A, const T& B, const T& C, bool linear, T s[2]) {
  const int sb = sgn(B);
  if (linear) {
    if (sb == 0) return 0;
    s[0] = -C / (T(2) * B);
    return 1;
  }
  const T disc = B * B - A * C;
  if (sgn(disc) < 0) return 0;
  const T sq = sqrt(disc);
  const T q = sb >= 0 ? -(B + sq) : sq - B;
  if (sgn(q) == 0) {  // B = 0 and C = 0: the double root 0
    s[0] = T(0);
    return 1;
  }
  s[0] = q / A;
  s[1] = C / q;
  return 2;
}

// Of the candidate centres (radius r >= 0), the one whose tangency order has
// the required orientation: the largest required * orient, compared exactly.
template <class T>
struct Candidate {
  bool found = false;
  T x, y, r, score;
  void offer(const T& cx, const T& cy, const T& cr, const T& s) {
    if (!found || sgn(s - score) > 0) {
      found = true;
      x = cx;
      y = cy;
      r = cr;
      score = s;
    }
  }
};

// Circle through points p, q, tangent to the segment site s; `index` is the
// position of the segment in the triple (1, 2 or 3): the tangency point T must
// satisfy orient(p, q, T) < 0 for 1 and 3, > 0 for 2.
template <class T>
bool circle_pps(const Site& sp, const Site& sq, const Site& s, int index, CircleT<T>& out) {
  const Pt& p = sp.p0;
  const Pt& q = sq.p0;
  const int op = orient(s.p0, s.p1, p), oq = orient(s.p0, s.p1, q);
  if (op == kLeft || oq == kLeft) return false;
  const LineI l = site_line(s);
  const T L = sqrt(T(l.len2));
  if (op == 0 || oq == 0) {
    // Tangent at the point on the line: the centre is on the normal there, at
    // rho = |off - on|^2 / (2 n.(off - on)) = |off - on|^2 L / (2 c.(off - on)).
    const Pt& on = op == 0 ? p : q;
    const Pt& off = op == 0 ? q : p;
    const double ox = off.x - on.x, oy = off.y - on.y;
    const double cross = l.cx * ox + l.cy * oy;  // exact
    if (!(cross > 0)) return false;
    const T f = T(ox * ox + oy * oy) / T(2 * cross);
    out.x = T(on.x) + f * T(l.cx);
    out.y = T(on.y) + f * T(l.cy);
    out.lower_x = out.x + f * L;
    return true;
  }
  const int required = index == 2 ? 1 : -1;
  // Centre X = M + t w on the perpendicular bisector of pq (M = (p + q) / 2,
  // w = perp(q - p)); its distance to the line is (g + t k) / L with
  // g = c.(M - a), k = c.w, and to p sqrt(hh + t^2 ww), so
  // (k^2 - L^2 ww) t^2 + 2 g k t + (g^2 - L^2 hh) = 0.
  const double ux = q.x - p.x, uy = q.y - p.y;
  const double wx = -uy, wy = ux;
  const double ww = ux * ux + uy * uy, hh = ww / 4;  // exact
  const double mx = p.x + ux / 2, my = p.y + uy / 2;  // exact halves
  const T g = (T(l.cx) * T(2 * mx - 2 * l.ax) + T(l.cy) * T(2 * my - 2 * l.ay)) / T(2);
  const T k = T(l.cx) * T(wx) + T(l.cy) * T(wy);
  const T len2(l.len2);
  const bool linear = cross_sign(ux, uy, -l.cy, l.cx) == 0;  // pq parallel to the line: k^2 = L^2 ww
  T t[2];
  const int n = quadratic_roots(k * k - len2 * T(ww), g * k, g * g - len2 * T(hh), linear, t);
  Candidate<T> best;
  for (int i = 0; i < n; ++i) {
    const T rl = g + t[i] * k;  // r L
    if (sgn(rl) < 0) continue;
    const T x = T(mx) + t[i] * T(wx), y = T(my) + t[i] * T(wy);
    const T f = rl / len2;  // T = X - r n = X - f c
    const T tx = x - f * T(l.cx), ty = y - f * T(l.cy);
    const T o = T(ux) * (ty - T(p.y)) - T(uy) * (tx - T(p.x));
    best.offer(x, y, rl / L, required > 0 ? o : -o);
  }
  if (!best.found) return false;
  out.x = best.x;
  out.y = best.y;
  out.lower_x = best.x + best.r;
  return true;
}

// Do two segment sites lie on parallel lines with the same orientation (same right normal)?
inline bool same_normal(const Site& a, const Site& b) {
  const double ax = a.p1.x - a.p0.x, ay = a.p1.y - a.p0.y, bx = b.p1.x - b.p0.x, by = b.p1.y - b.p0.y;
  return cross_sign(ax, ay, bx, by) == 0 && ax * bx + ay * by > 0;  // exact (|terms| <= 2^52)
}

// Circle through point p tangent to segment sites s1, s2; the cyclic order of
// tangency is (p, s1, s2) for index 1 and 3, (s1, p, s2) for index 2.
template <class T>
bool circle_pss(const Site& sp, const Site& s1, const Site& s2, int index, CircleT<T>& out) {
  const Pt& p = sp.p0;
  const int required = index == 2 ? 1 : -1;  // sign of orient(p, T1, T2)
  const int o1 = orient(s1.p0, s1.p1, p), o2 = orient(s2.p0, s2.p1, p);
  if (o1 == kLeft || o2 == kLeft) return false;
  if (o1 == 0 && o2 == 0) {  // p is the lines' intersection: a circle of radius 0
    out.x = T(p.x);
    out.y = T(p.y);
    out.lower_x = T(p.x);
    return true;
  }
  if (same_normal(s1, s2)) return false;  // parallel lines facing the same way: no circle
  const LineI l1 = site_line(s1), l2 = site_line(s2);
  const T L1 = sqrt(T(l1.len2)), L2 = sqrt(T(l2.len2));
  const T px(p.x), py(p.y);
  const T c12 = T(l1.cx) * T(l2.cx) + T(l1.cy) * T(l2.cy);
  // e_i = c_i . (p - a_i) = L_i d_i(p) >= 0, exact.
  const double e1 = line_offset(l1, p), e2 = line_offset(l2, p);
  if (o1 == 0 || o2 == 0) {
    // Tangent at p to the line through it: the centre is on that line's normal
    // at p, at t = d_other(p) / (1 - n1.n2) = e_other L_at / (L1 L2 - c1.c2).
    const LineI& at = o1 == 0 ? l1 : l2;
    const T& L_at = o1 == 0 ? L1 : L2;
    const T den = L1 * L2 - c12;
    if (sgn(den) <= 0) return false;
    const T f = T(o1 == 0 ? e2 : e1) / den;  // X = p + f c_at, r = f L_at
    if (sgn(f) <= 0) return false;
    out.x = px + f * T(at.cx);
    out.y = py + f * T(at.cy);
    out.lower_x = out.x + f * L_at;
    return true;
  }
  // With Y = X - p: d_i = (c_i . Y + e_i) / L_i. The bisector d1 = d2 is
  // m . Y = h0 with m = L2 c1 - L1 c2, h0 = L1 e2 - L2 e1; Y = (h0 m + s v) / mm
  // with v = perp(m), mm = |m|^2; then d1 = (beta + s alpha) / (mm L1) with
  // alpha = c1 . v, beta = h0 (c1 . m) + e1 mm, and d1^2 = |Y|^2 = (h0^2 + s^2) / mm:
  // (alpha^2 - L1^2 mm) s^2 + 2 alpha beta s + (beta^2 - L1^2 mm h0^2) = 0.
  const T mx = L2 * T(l1.cx) - L1 * T(l2.cx), my = L2 * T(l1.cy) - L1 * T(l2.cy);
  const T h0 = L1 * T(e2) - L2 * T(e1);
  const T mm = mx * mx + my * my;
  const T vx = -my, vy = mx;
  const T alpha = T(l1.cx) * vx + T(l1.cy) * vy;
  const T beta = h0 * (T(l1.cx) * mx + T(l1.cy) * my) + T(e1) * mm;
  const T l1mm = T(l1.len2) * mm;
  T s[2];
  const int n = quadratic_roots(alpha * alpha - l1mm, alpha * beta, beta * beta - l1mm * h0 * h0, false, s);
  Candidate<T> best;
  for (int i = 0; i < n; ++i) {
    const T rn = beta + s[i] * alpha;  // r mm L1
    if (sgn(rn) < 0) continue;
    const T x = px + (h0 * mx + s[i] * vx) / mm, y = py + (h0 * my + s[i] * vy) / mm;
    const T r = rn / (mm * L1);
    // Tangency points T_i = X - r c_i / L_i.
    const T f1 = r / L1, f2 = r / L2;
    const T t1x = x - f1 * T(l1.cx), t1y = y - f1 * T(l1.cy), t2x = x - f2 * T(l2.cx), t2y = y - f2 * T(l2.cy);
    const T o = (t1x - px) * (t2y - py) - (t1y - py) * (t2x - px);
    best.offer(x, y, r, required > 0 ? o : -o);
  }
  if (!best.found) return false;
  out.x = best.x;
  out.y = best.y;
  out.lower_x = best.x + best.r;
  return true;
}

// Circle tangent to three segment sites: c_i . X - L_i r = c_i . a_i, by Cramer's rule.
template <class T>
bool circle_sss(const Site& s1, const Site& s2, const Site& s3, CircleT<T>& out) {
  const LineI l[3] = {site_line(s1), site_line(s2), site_line(s3)};
  T m[3][3], rhs[3];
  for (int i = 0; i < 3; ++i) {
    m[i][0] = T(l[i].cx);
    m[i][1] = T(l[i].cy);
    m[i][2] = -sqrt(T(l[i].len2));
    rhs[i] = T(l[i].cx * l[i].ax + l[i].cy * l[i].ay);  // exact (|terms| <= 2^51)
  }
  auto det3 = [](const T a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  const T d = det3(m);
  if (sgn(d) == 0) return false;
  T sol[3];
  for (int j = 0; j < 3; ++j) {
    T mj[3][3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) mj[i][k] = k == j ? rhs[i] : m[i][k];
    sol[j] = det3(mj) / d;
  }
  if (sgn(sol[2]) < 0) return false;
  out.x = sol[0];
  out.y = sol[1];
  out.lower_x = sol[0] + sol[2];
  return true;
}

bool exists_pps(const Site& s1, const Site& s2, const Site& s3, int index) {
  if (index != 2) {
    const int o1 = orient(s1.p0, s2.p0, s3.p0);
    const int o2 = orient(s1.p0, s2.p0, s3.p1);
    if (index == 1 && s1.x0() >= s2.x0()) {
      if (o1 != kRight) return false;
    } else if (index == 3 && s2.x0() >= s1.x0()) {
      if (o2 != kRight) return false;
    } else if (o1 != kRight && o2 != kRight) {
      return false;
    }
    return true;
  }
  return s3.p0 != s1.p0 || s3.p1 != s2.p0;
}

bool exists_pss(const Site& s1, const Site& s2, const Site& s3, int index) {
  if (s2.sorted_index == s3.sorted_index) return false;
  if (index == 2) {
    if (!s2.inverse && s3.inverse) return false;
    if (s2.inverse == s3.inverse && orient(s2.p0, s1.p0, s3.p1) != kRight) return false;
  }
  return true;
}

// Is the centre outside the y range of a vertical segment site? Exact: the
// centre's y equals an endpoint's y when the circle passes through it.
template <class T>
bool outside_vertical(const CircleT<T>& c, const Site& s) {
  if (!s.segment || !is_vertical(s)) return false;
  const double y0 = s.inverse ? s.y1() : s.y0();
  const double y1 = s.inverse ? s.y0() : s.y1();
  return sgn(c.y - T(y0)) < 0 || sgn(c.y - T(y1)) > 0;
}

template <class T>
bool circle_formation(const Site& s1, const Site& s2, const Site& s3, CircleT<T>& c) {
  bool ok;
  if (!s1.segment) {
    if (!s2.segment) {
      if (!s3.segment)
        ok = circle_ppp(s1, s2, s3, c);
      else
        ok = exists_pps(s1, s2, s3, 3) && circle_pps(s1, s2, s3, 3, c);
    } else {
      if (!s3.segment)
        ok = exists_pps(s1, s3, s2, 2) && circle_pps(s1, s3, s2, 2, c);
      else
        ok = exists_pss(s1, s2, s3, 1) && circle_pss(s1, s2, s3, 1, c);
    }
  } else {
    if (!s2.segment) {
      if (!s3.segment)
        ok = exists_pps(s2, s3, s1, 1) && circle_pps(s2, s3, s1, 1, c);
      else
        ok = exists_pss(s2, s1, s3, 2) && circle_pss(s2, s1, s3, 2, c);
    } else {
      if (!s3.segment)
        ok = exists_pss(s3, s1, s2, 3) && circle_pss(s3, s1, s2, 3, c);
      else
        ok = s1.sorted_index != s2.sorted_index && s2.sorted_index != s3.sorted_index && circle_sss(s1, s2, s3, c);
    }
  }
  if (!ok) return false;
  if (outside_vertical(c, s1) || outside_vertical(c, s2) || outside_vertical(c, s3)) return false;
  // A circle tangent to a vertical segment from its left touches the sweep line
  // exactly when it reaches the segment's x, so that the events at one
  // vertical segment are ordered by y.
  for (const Site* s : {&s1, &s2, &s3})
    if (s->segment && is_vertical(*s) && s->p0.y > s->p1.y) c.lower_x = T(s->p0.x);
  return true;
}

// A circle event: enclosures of the centre and of its lower x (points when
// exact), refined by the exact evaluation when the filter was not sure or not
// tight enough for the output vertex.
struct Circle {
  exact::Iv x, y, lower_x;
};

template <class T>
Circle to_circle(const CircleT<T>& c) {
  if constexpr (std::is_same_v<T, exact::Iv>) {
    return Circle{c.x, c.y, c.lower_x};
  } else {
    auto iv = [](const exact::Bx& b) { return exact::Iv(b.lower(), b.upper()); };
    return Circle{iv(c.x), iv(c.y), iv(c.lower_x)};
  }
}

inline bool tight(const exact::Iv& v) { return v.hi - v.lo <= 0x1p-40 * (std::fabs(v.lo) + std::fabs(v.hi) + 1); }

bool circle_event(const Site& s1, const Site& s2, const Site& s3, Circle& out) {
  try {
    CircleT<exact::Iv> c;
    if (!circle_formation(s1, s2, s3, c)) return false;
    out = to_circle(c);
    if (tight(out.x) && tight(out.y) && tight(out.lower_x)) return true;
  } catch (const exact::Uncertain&) {
  }
  bool found = false;
  exact::exact_sign([&](auto type) {
    using T = typename decltype(type)::type;
    CircleT<T> c;
    found = circle_formation(s1, s2, s3, c);
    if (found) {
      out = to_circle(c);
      // The output needs a tight enclosure, not only the branch signs.
      if (!(tight(out.x) && tight(out.y) && tight(out.lower_x))) throw exact::NeedPrecision{};
    }
    return T(0);
  });
  return found;
}

// ---------------------------------------------------------------- the builder
class Builder {
 public:
  explicit Builder(const SweepInput& in) {
    const auto np = static_cast<std::uint32_t>(in.points.size());
    for (std::uint32_t i = 0; i < np; ++i) {
      Site s;
      s.p0 = s.p1 = Pt{in.points[i][0], in.points[i][1]};
      s.id = i;
      sites_.push_back(s);
    }
    for (std::uint32_t i = 0; i < in.segments.size(); ++i) {
      Site s;
      Pt a{in.points[in.segments[i][0]][0], in.points[in.segments[i][0]][1]};
      Pt b{in.points[in.segments[i][1]][0], in.points[in.segments[i][1]][1]};
      if (point_less(b, a)) std::swap(a, b);
      s.p0 = a;
      s.p1 = b;
      s.segment = true;
      s.id = np + i;
      sites_.push_back(s);
      segment_first_.push_back(Pt{in.points[in.segments[i][0]][0], in.points[in.segments[i][0]][1]});
    }
    num_points_ = np;
    std::sort(sites_.begin(), sites_.end(), site_less);
    for (std::uint32_t i = 0; i < sites_.size(); ++i) sites_[i].sorted_index = i;
  }

  SweepOutput run() {
    if (sites_.size() >= 2) init_beach_line();
    while (!queue_.empty() || next_ != sites_.size()) {
      if (queue_.empty()) {
        process_site();
      } else if (next_ == sites_.size()) {
        process_circle();
      } else if (site_before_circle(sites_[next_], events_[queue_.top()])) {
        process_site();
      } else {
        process_circle();
      }
      while (!queue_.empty() && !events_[queue_.top()].active) queue_.pop();
    }
    return std::move(out_);
  }

 private:
  struct Event {
    Circle c;
    BeachIt node;
    std::array<std::uint32_t, 3> site{};  // sorted indices of the three sites
    std::uint8_t inverse = 0;             // bit i: site i inverted
    bool active = true;
  };
  struct EventLess {
    const Builder* builder;
    bool operator()(std::uint32_t a, std::uint32_t b) const { return builder->compare_events(a, b) > 0; }
  };

  Site event_site(const Event& e, int i) const {
    Site s = sites_[e.site[i]];
    if ((e.inverse >> i) & 1) s.invert();
    return s;
  }
  // Exact sign of a - b, for intervals known to enclose a and b, or 2 when they cannot tell.
  static int interval_compare(const exact::Iv& a, const exact::Iv& b) {
    if (a.hi < b.lo) return -1;
    if (a.lo > b.hi) return 1;
    if (a.point() && b.point() && a.lo == b.lo) return 0;
    return 2;
  }
  // Events ordered by the lower x of their circles, then by the centre's y, exactly.
  int compare_events(std::uint32_t ia, std::uint32_t ib) const {
    const Event& a = events_[ia];
    const Event& b = events_[ib];
    if (a.c.lower_x.hi < b.c.lower_x.lo) return -1;  // the usual case, inline
    if (a.c.lower_x.lo > b.c.lower_x.hi) return 1;
    return compare_events_slow(a, b);
  }
  [[gnu::noinline]] int compare_events_slow(const Event& a, const Event& b) const {
    for (const bool by_y : {false, true}) {
      int s = by_y ? interval_compare(a.c.y, b.c.y) : interval_compare(a.c.lower_x, b.c.lower_x);
      if (s == 2) {
        const Site a0 = event_site(a, 0), a1 = event_site(a, 1), a2 = event_site(a, 2);
        const Site b0 = event_site(b, 0), b1 = event_site(b, 1), b2 = event_site(b, 2);
        s = exact::exact_sign([&](auto type) {
          using T = typename decltype(type)::type;
          CircleT<T> ca, cb;
          circle_formation(a0, a1, a2, ca);
          circle_formation(b0, b1, b2, cb);
          return by_y ? ca.y - cb.y : ca.lower_x - cb.lower_x;
        });
      }
      if (s != 0) return s;
    }
    return 0;
  }
  // The site comes first when its x is below the circle's lower x (equal: the circle first).
  bool site_before_circle(const Site& s, const Event& e) const {
    const double x = s.x0();
    if (x < e.c.lower_x.lo) return true;
    if (x >= e.c.lower_x.hi) return false;
    const Site e0 = event_site(e, 0), e1 = event_site(e, 1), e2 = event_site(e, 2);
    return exact::exact_sign([&](auto type) {
             using T = typename decltype(type)::type;
             CircleT<T> c;
             circle_formation(e0, e1, e2, c);
             return T(x) - c.lower_x;
           }) < 0;
  }
  struct EndPoint {
    Pt p;
    BeachIt node;
  };
  struct EndPointLess {
    bool operator()(const EndPoint& a, const EndPoint& b) const { return point_less(b.p, a.p); }
  };

  std::int8_t side_of(const Site& s) const {
    // The region of a segment site is right of p0 -> p1 (its current orientation).
    const Pt& first = segment_first_[s.id - num_points_];
    return s.p0 == first ? 1 : -1;
  }

  // A new edge between arc site a and site b; returns its id.
  std::uint32_t new_edge(const Site& a, const Site& b) {
    SweepEdge e;
    e.site = {a.id, b.id};
    e.vertex = {kNone, kNone};
    e.side = {static_cast<std::int8_t>(a.segment ? side_of(a) : 0), static_cast<std::int8_t>(b.segment ? side_of(b) : 0)};
    out_.edges.push_back(e);
    return static_cast<std::uint32_t>(out_.edges.size() - 1);
  }

  void init_beach_line() {
    // Vertical run of first sites (points, or vertical segments, on x = x of the first).
    next_ = 0;
    std::size_t skip = 0;
    while (next_ < sites_.size() && sites_[next_].p0.x == sites_[0].p0.x && is_vertical(sites_[next_])) {
      ++next_;
      ++skip;
    }
    if (skip == 1) {
      insert_new_arc(sites_[0], sites_[0], sites_[1], beach_.end());
      next_ = 2;
    } else {
      for (std::size_t i = 0; i + 1 < next_; ++i) {
        Key key(sites_[i], sites_[i + 1]);
        NodeData d;
        d.edge = new_edge(sites_[i], sites_[i + 1]);
        d.end = 0;
        beach_.insert(beach_.end(), {key, d});
      }
    }
  }

  BeachIt insert_new_arc(const Site& arc1, const Site& arc2, const Site& site, BeachIt position) {
    Key left_node(arc1, site);
    Key right_node(site, arc2);
    if (site.segment) right_node.left.invert();
    // The edge between the arc and the new site: end 0 at the left node, end 1 at the right one.
    const std::uint32_t e = new_edge(arc2, site);
    // Moving towards end 0 (left node (arc, site)), the arc is on the right: site[0] = arc.
    // But the right node (site', arc) records the side of the inverted segment at its end; the
    // sides are those of the left node's sites.
    NodeData right_data{e, 1, kNone};
    position = beach_.insert(position, {right_node, right_data});
    if (site.segment) {
      Key temp(site, site);
      temp.right.invert();
      position = beach_.insert(position, {temp, NodeData{}});
      ends_.push(EndPoint{site.p1, position});
    }
    NodeData left_data{e, 0, kNone};
    position = beach_.insert(position, {left_node, left_data});
    return position;
  }

  void deactivate(NodeData& d) {
    if (d.circle != kNone) {
      events_[d.circle].active = false;
      d.circle = kNone;
    }
  }

  void activate(const Site& s1, const Site& s2, const Site& s3, BeachIt node) {
    Circle c;
    if (circle_event(s1, s2, s3, c)) {
      const auto inverse = static_cast<std::uint8_t>(int(s1.inverse) | int(s2.inverse) << 1 | int(s3.inverse) << 2);
      events_.push_back(Event{c, node, {s1.sorted_index, s2.sorted_index, s3.sorted_index}, inverse, true});
      const auto id = static_cast<std::uint32_t>(events_.size() - 1);
      node->second.circle = id;
      queue_.push(id);
    }
  }

  void process_site() {
    Site site = sites_[next_];
    std::size_t last = next_ + 1;
    if (!site.segment) {
      while (!ends_.empty() && ends_.top().p == site.p0) {
        beach_.erase(ends_.top().node);
        ends_.pop();
      }
    } else {
      while (last < sites_.size() && sites_[last].segment && sites_[last].p0 == site.p0) ++last;
    }
    Key new_key(sites_[next_]);
    BeachIt right_it = beach_.lower_bound(new_key);
    for (; next_ != last; ++next_) {
      site = sites_[next_];
      BeachIt left_it = right_it;
      if (right_it == beach_.end()) {
        --left_it;
        const Site arc = left_it->first.right;
        right_it = insert_new_arc(arc, arc, site, right_it);
        activate(left_it->first.left, left_it->first.right, site, right_it);
      } else if (right_it == beach_.begin()) {
        const Site arc = right_it->first.left;
        left_it = insert_new_arc(arc, arc, site, right_it);
        if (site.segment) site.invert();
        activate(site, right_it->first.left, right_it->first.right, right_it);
        right_it = left_it;
      } else {
        const Site arc2 = right_it->first.left;
        const Site s3 = right_it->first.right;
        deactivate(right_it->second);
        --left_it;
        const Site arc1 = left_it->first.right;
        const Site s1 = left_it->first.left;
        BeachIt new_it = insert_new_arc(arc1, arc2, site, right_it);
        activate(s1, arc1, site, new_it);
        if (site.segment) site.invert();
        activate(site, arc2, s3, right_it);
        right_it = new_it;
      }
    }
  }

  void process_circle() {
    const std::uint32_t ev = queue_.top();
    const Circle c = events_[ev].c;
    BeachIt it_first = events_[ev].node;
    BeachIt it_last = it_first;
    Site site3 = it_first->first.right;
    const NodeData d2 = it_first->second;
    --it_first;
    const NodeData d1 = it_first->second;
    const Site site1 = it_first->first.left;
    if (!site1.segment && site3.segment && site3.p1 == site1.p0) site3.invert();
    // The vertex.
    const long double cx = c.x.mid(), cy = c.y.mid();
    out_.vertices.push_back(SweepVertex{cx, cy, static_cast<long double>(c.lower_x.mid()) - cx});
    const auto v = static_cast<std::uint32_t>(out_.vertices.size() - 1);
    if (d1.edge != kNone) out_.edges[d1.edge].vertex[d1.end] = v;
    if (d2.edge != kNone) out_.edges[d2.edge].vertex[d2.end] = v;
    it_first->first.right = site3;
    const std::uint32_t e = new_edge(site1, site3);
    out_.edges[e].vertex[1] = v;
    it_first->second.edge = e;
    it_first->second.end = 0;
    beach_.erase(it_last);
    it_last = it_first;
    queue_.pop();
    events_[ev].active = false;
    if (it_first != beach_.begin()) {
      deactivate(it_first->second);
      --it_first;
      const Site l1 = it_first->first.left;
      activate(l1, site1, site3, it_last);
    }
    ++it_last;
    if (it_last != beach_.end()) {
      deactivate(it_last->second);
      const Site r1 = it_last->first.right;
      activate(site1, site3, r1, it_last);
    }
  }

  std::vector<Site> sites_;
  std::vector<Pt> segment_first_;
  std::uint32_t num_points_ = 0;
  std::size_t next_ = 0;
  BeachLine beach_;
  std::vector<Event> events_;
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, EventLess> queue_{EventLess{this}};
  std::priority_queue<EndPoint, std::vector<EndPoint>, EndPointLess> ends_;
  SweepOutput out_;
};

}  // namespace

SweepOutput sweep_segment_voronoi(const SweepInput& input) {
  return Builder(input).run();
}

}  // namespace geods::voronoi::detail
