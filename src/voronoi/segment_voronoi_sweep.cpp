// Fortune's sweep for the Voronoi diagram of points and segments.
//
// The structure follows Boost.Polygon's voronoi_builder (site events for
// points and segments sorted along x, a beach line of bisector nodes (left
// arc, right arc) ordered along y, circle events for consecutive triples, a
// temporary node per segment between its two sides until its second
// endpoint is reached); the predicates and the tangent-circle constructions
// are our own: orientation tests on the snapped integers are exact in double,
// and the circles tangent to points and lines are computed in long double
// from closed forms whose root is chosen by exact signs (the cyclic order of
// the three tangency points on the circle is clockwise for a circle event).
#include "segment_voronoi_sweep.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <utility>

namespace geods::voronoi::detail {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
using real = long double;

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

struct Circle {
  real x = 0, y = 0, lower_x = 0;
};

// ---------------------------------------------------------------- distance predicate
// Does the horizontal line through the new point hit the right arc of the
// node (left, right) first (the point is above the breakpoint)?
real distance_to_point_arc(const Site& site, const Pt& p) {
  const real dx = real(site.p0.x) - p.x, dy = real(site.p0.y) - p.y;
  return (dx * dx + dy * dy) / (2 * dx);
}
real distance_to_segment_arc(const Site& site, const Pt& p) {
  if (is_vertical(site)) return (real(site.p0.x) - p.x) * 0.5L;
  const real a1 = real(site.p1.x) - site.p0.x, b1 = real(site.p1.y) - site.p0.y;
  real k = std::sqrt(a1 * a1 + b1 * b1);
  k = b1 >= 0 ? 1 / (b1 + k) : (k - b1) / (a1 * a1);
  const real cross = real((site.p1.x - site.p0.x) * (p.y - site.p0.y) - (site.p1.y - site.p0.y) * (p.x - site.p0.x));
  return k * cross;
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
  return distance_to_point_arc(left, p) < distance_to_point_arc(right, p);
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
  const auto a = static_cast<i128>(s1.x - s0.x), b = static_cast<i128>(s1.y - s0.y);
  const auto dx = static_cast<i128>(p.x - site_point.x), dy = static_cast<i128>(p.y - site_point.y);
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
  const real d1 = distance_to_point_arc(left, p);
  const real d2 = distance_to_segment_arc(right, p);
  return reverse_order ^ (d1 < d2);
}

bool ss_predicate(const Site& left, const Site& right, const Pt& p) {
  if (left.sorted_index == right.sorted_index) return orient(left.p0, left.p1, p) == kLeft;
  return distance_to_segment_arc(left, p) < distance_to_segment_arc(right, p);
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
struct Line {
  real ax, ay;  // a point
  real ux, uy;  // unit direction
  real nx, ny;  // unit right normal (the site's side)
};
Line site_line(const Site& s) {
  Line l;
  l.ax = s.p0.x;
  l.ay = s.p0.y;
  const real dx = real(s.p1.x) - s.p0.x, dy = real(s.p1.y) - s.p0.y;
  const real len = std::sqrt(dx * dx + dy * dy);
  l.ux = dx / len;
  l.uy = dy / len;
  l.nx = l.uy;
  l.ny = -l.ux;
  return l;
}
inline real side_dist(const Line& l, real x, real y) { return l.nx * (x - l.ax) + l.ny * (y - l.ay); }

bool circle_ppp(const Site& a, const Site& b, const Site& c, Circle& out) {
  if (orient(a.p0, b.p0, c.p0) != kRight) return false;
  const real ax = a.p0.x, ay = a.p0.y;
  const real bx = real(b.p0.x) - ax, by = real(b.p0.y) - ay, cx = real(c.p0.x) - ax, cy = real(c.p0.y) - ay;
  const real d = 2 * real(bx * cy - by * cx);  // exact in double already
  const real b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const real ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  out.x = ax + ux;
  out.y = ay + uy;
  out.lower_x = out.x + std::sqrt(ux * ux + uy * uy);
  return true;
}

// Roots of (1 - E^2) t^2 - 2 D E t + (g2 - D^2) = 0, the parameters t where
// a point X = B + t v of a line (unit v, B the foot of the point p) is as far
// from p (|B - p|^2 = g2) as from a line (distance D + t E). Stable for
// E^2 near 1 (one root far away) and E = +-1 (linear: `linear` set by the caller
// from an exact test).
int tangent_roots(real D, real E, real g2, bool linear, real t[2]) {
  if (linear) {
    if (D * E == 0) return 0;
    t[0] = (g2 - D * D) / (2 * D * E);
    return 1;
  }
  const real a = 1 - E * E;
  real disc = D * D - g2 * a;
  if (disc < 0) return 0;
  const real sq = std::sqrt(disc);
  const real q = D * E + (D * E >= 0 ? sq : -sq);
  if (q == 0) {
    t[0] = 0;
    return 1;
  }
  t[0] = q / a;
  t[1] = (g2 - D * D) / q;
  return 2;
}

// Of the candidate centres X (radius R, tangency points T_i = X - R n_i on the
// lines), the one whose tangency order has the required orientation: the
// candidate with the largest required * orient, in floating point (the
// candidates are far apart whenever there are two).
struct Candidate {
  real x, y, r, score;
};

// Circle through points p, q, tangent to the segment site s; `index` is the
// position of the segment in the triple (1, 2 or 3): the tangency point T must
// satisfy orient(p, q, T) < 0 for 1 and 3, > 0 for 2.
bool circle_pps(const Site& sp, const Site& sq, const Site& s, int index, Circle& out) {
  const Pt& p = sp.p0;
  const Pt& q = sq.p0;
  const int op = orient(s.p0, s.p1, p), oq = orient(s.p0, s.p1, q);
  if (op == kLeft || oq == kLeft) return false;
  const Line l = site_line(s);
  const int required = index == 2 ? 1 : -1;
  if (op == 0 || oq == 0) {
    // Tangent at the point on the line: the centre is on the normal there.
    const Pt& on = op == 0 ? p : q;
    const Pt& off = op == 0 ? q : p;
    const real dn = l.nx * (real(off.x) - on.x) + l.ny * (real(off.y) - on.y);
    if (!(dn > 0)) return false;
    const real dx = real(off.x) - on.x, dy = real(off.y) - on.y;
    const real rho = (dx * dx + dy * dy) / (2 * dn);
    out.x = on.x + rho * l.nx;
    out.y = on.y + rho * l.ny;
    out.lower_x = out.x + rho;
    return true;
  }
  // Centre X = M + t w on the perpendicular bisector of pq.
  const real hx = (real(q.x) - p.x) / 2, hy = (real(q.y) - p.y) / 2;
  const real h = std::sqrt(hx * hx + hy * hy);
  const real wx = -hy / h, wy = hx / h;
  const real mx = p.x + hx, my = p.y + hy;
  const real D = side_dist(l, mx, my), E = l.nx * wx + l.ny * wy;
  const bool linear = cross_sign(q.x - p.x, q.y - p.y, s.p1.x - s.p0.x, s.p1.y - s.p0.y) == 0;
  real t[2];
  const int n = tangent_roots(D, E, h * h, linear, t);
  Candidate best{0, 0, 0, -std::numeric_limits<real>::infinity()};
  for (int i = 0; i < n; ++i) {
    const real x = mx + t[i] * wx, y = my + t[i] * wy, r = D + t[i] * E;
    if (!(r >= 0)) continue;
    const real tx = x - r * l.nx, ty = y - r * l.ny;
    const real o = (real(q.x) - p.x) * (ty - p.y) - (real(q.y) - p.y) * (tx - p.x);
    const real score = required * o;
    if (score > best.score) best = Candidate{x, y, r, score};
  }
  if (!(best.score > -std::numeric_limits<real>::infinity())) return false;
  out.x = best.x;
  out.y = best.y;
  out.lower_x = best.x + best.r;
  return true;
}

// Circle through point p tangent to segment sites s1, s2; the cyclic order of
// tangency is (p, s1, s2) for index 1 and 3, (s1, p, s2) for index 2.
bool circle_pss(const Site& sp, const Site& s1, const Site& s2, int index, Circle& out) {
  const Pt& p = sp.p0;
  const Line l1 = site_line(s1), l2 = site_line(s2);
  const int required = index == 2 ? 1 : -1;  // sign of orient(p, T1, T2)
  const real px = p.x, py = p.y;
  const int o1 = orient(s1.p0, s1.p1, p), o2 = orient(s2.p0, s2.p1, p);
  if (o1 == kLeft || o2 == kLeft) return false;
  if (o1 == 0 && o2 == 0) {  // p is the lines' intersection: a circle of radius 0
    out.x = px;
    out.y = py;
    out.lower_x = px;
    return true;
  }
  const real k = 1 + l1.nx * l2.nx + l1.ny * l2.ny;
  if (o1 == 0 || o2 == 0) {
    // Tangent at p to the line through it: the centre is on that line's normal at p,
    // at the distance t where it is as far from the other line: t = d_other(p) / (1 - n1.n2).
    const Line& at = o1 == 0 ? l1 : l2;
    const Line& other = o1 == 0 ? l2 : l1;
    const real t = side_dist(other, px, py) / (2 - k);
    if (!(t > 0)) return false;
    out.x = px + t * at.nx;
    out.y = py + t * at.ny;
    out.lower_x = out.x + t;
    return true;
  }
  // The bisector d1 = d2: m.X = c with m = n1 - n2; B the foot of p on it, v its direction.
  const real mxv = l1.nx - l2.nx, myv = l1.ny - l2.ny;
  const real m2 = mxv * mxv + myv * myv;
  if (!(m2 > 0)) return false;  // same lines facing the same way
  const real c = l1.nx * l1.ax + l1.ny * l1.ay - (l2.nx * l2.ax + l2.ny * l2.ay);
  const real f = (mxv * px + myv * py - c) / m2;
  const real bx = px - f * mxv, by = py - f * myv;
  const real ml = std::sqrt(m2);
  const real vx = -myv / ml, vy = mxv / ml;
  const real D = side_dist(l1, bx, by), E = l1.nx * vx + l1.ny * vy;
  const real g2 = f * f * m2;
  real t[2];
  const int n = tangent_roots(D, E, g2, false, t);
  Candidate best{0, 0, 0, -std::numeric_limits<real>::infinity()};
  for (int i = 0; i < n; ++i) {
    const real x = bx + t[i] * vx, y = by + t[i] * vy, r = D + t[i] * E;
    if (!(r >= 0)) continue;
    const real t1x = x - r * l1.nx, t1y = y - r * l1.ny, t2x = x - r * l2.nx, t2y = y - r * l2.ny;
    const real o = (t1x - px) * (t2y - py) - (t1y - py) * (t2x - px);
    const real score = required * o;
    if (score > best.score) best = Candidate{x, y, r, score};
  }
  if (!(best.score > -std::numeric_limits<real>::infinity())) return false;
  out.x = best.x;
  out.y = best.y;
  out.lower_x = best.x + best.r;
  return true;
}

bool circle_sss(const Site& s1, const Site& s2, const Site& s3, Circle& out) {
  const Line l[3] = {site_line(s1), site_line(s2), site_line(s3)};
  // n_i . X - r = n_i . a_i
  real m[3][3], rhs[3];
  for (int i = 0; i < 3; ++i) {
    m[i][0] = l[i].nx;
    m[i][1] = l[i].ny;
    m[i][2] = -1;
    rhs[i] = l[i].nx * l[i].ax + l[i].ny * l[i].ay;
  }
  auto det3 = [](real a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  const real d = det3(m);
  if (d == 0) return false;
  real sol[3];
  for (int j = 0; j < 3; ++j) {
    real mj[3][3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) mj[i][k] = k == j ? rhs[i] : m[i][k];
    sol[j] = det3(mj) / d;
  }
  if (!(sol[2] >= 0)) return false;
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

bool outside_vertical(const Circle& c, const Site& s) {
  if (!s.segment || !is_vertical(s)) return false;
  const real y0 = s.inverse ? s.y1() : s.y0();
  const real y1 = s.inverse ? s.y0() : s.y1();
  // The centre's y is rounded (it is an endpoint's y exactly when the circle
  // passes through that endpoint): compared within 64 units in the last place
  // of a double, as Boost.Polygon does.
  const real tol = 64 * std::numeric_limits<double>::epsilon() * std::max<real>({std::fabs(c.y), std::fabs(y0), std::fabs(y1), 1});
  return c.y < y0 - tol || c.y > y1 + tol;
}

bool circle_formation(const Site& s1, const Site& s2, const Site& s3, Circle& c) {
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
  // exactly when it reaches the segment's x: exact, so that the events at one
  // vertical segment are ordered by y and not by rounding.
  for (const Site* s : {&s1, &s2, &s3})
    if (s->segment && is_vertical(*s) && s->p0.y > s->p1.y) c.lower_x = s->p0.x;
  return true;
}

// Site x against a circle's lower x: the site first when it is below by more
// than the rounding of the circle's computation (64 units in the last place of a double).
bool site_before_circle(const Site& s, const Circle& c) {
  const real x = s.x0();
  const real tol = 64 * std::numeric_limits<double>::epsilon() * std::max<real>(std::fabs(x), std::fabs(c.lower_x));
  return x < c.lower_x - tol;
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
      } else if (site_before_circle(sites_[next_], events_[queue_.top()].c)) {
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
    bool active = true;
  };
  struct EventLess {
    const std::vector<Event>* events;
    bool operator()(std::uint32_t a, std::uint32_t b) const {
      const Circle& ca = (*events)[a].c;
      const Circle& cb = (*events)[b].c;
      if (ca.lower_x != cb.lower_x) return ca.lower_x > cb.lower_x;
      return ca.y > cb.y;
    }
  };
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
    if (circle_formation(s1, s2, s3, c)) {
      events_.push_back(Event{c, node, true});
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
    out_.vertices.push_back(SweepVertex{c.x, c.y, c.lower_x - c.x});
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
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, EventLess> queue_{EventLess{&events_}};
  std::priority_queue<EndPoint, std::vector<EndPoint>, EndPointLess> ends_;
  SweepOutput out_;
};

}  // namespace

SweepOutput sweep_segment_voronoi(const SweepInput& input) { return Builder(input).run(); }

}  // namespace geods::voronoi::detail
