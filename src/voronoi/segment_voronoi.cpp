#include "geods/voronoi/segment_voronoi.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "geods/core/error.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "even_odd.hpp"
#include "segment_voronoi_sweep.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = SegmentVoronoi::kInfinity;
constexpr double kSnapLimit = 33554432.0;  // 2^25

struct IntPoint {
  std::int64_t x, y;
  bool operator==(const IntPoint& o) const { return x == o.x && y == o.y; }
};
struct IntPointHash {
  std::size_t operator()(const IntPoint& p) const {
    return std::hash<std::uint64_t>()(static_cast<std::uint64_t>(p.x) * 0x9E3779B97F4A7C15ULL ^
                                      static_cast<std::uint64_t>(p.y));
  }
};

// Exact for |coordinates| <= 2^26 (products <= 2^53).
int orient(const IntPoint& a, const IntPoint& b, const IntPoint& c) {
  const std::int64_t v = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  return (v > 0) - (v < 0);
}
// c strictly inside segment ab, given that it is collinear with it.
bool strictly_between(const IntPoint& a, const IntPoint& b, const IntPoint& c) {
  if (a.x != b.x) return (c.x > std::min(a.x, b.x)) && (c.x < std::max(a.x, b.x));
  return (c.y > std::min(a.y, b.y)) && (c.y < std::max(a.y, b.y));
}

Vec2d perp_cw(const Vec2d& w) { return Vec2d(w[1], -w[0]); }

}  // namespace

Vec2d SegmentVoronoi::EdgeCurve::point(double t) const {
  if (!parabolic) return origin + t * direction;
  const Vec2d n(-direction[1], direction[0]);  // left normal of the directrix
  const Vec2d rel = focus - origin;
  const double tp = rel.dot(direction);
  double h = rel.dot(n);
  const Vec2d side = h >= 0 ? n : Vec2d(-n);
  h = std::abs(h);
  const double y = ((t - tp) * (t - tp) + h * h) / (2 * h);
  return origin + t * direction + y * side;
}

SegmentVoronoi::SegmentVoronoi(std::span<const double> points, std::span<const double> segments) {
  build(points, segments);
}

void SegmentVoronoi::build(std::span<const double> points, std::span<const double> segments) {
  if (points.size() % 2 != 0) throw Error("segment voronoi: points must be rows of 2 coordinates");
  if (segments.size() % 4 != 0) throw Error("segment voronoi: segments must be rows of 4 coordinates (x0 y0 x1 y1)");
  input_points_ = points.size() / 2;
  input_segments_ = segments.size() / 4;
  if (input_points_ + input_segments_ == 0) throw Error("segment voronoi: no sites");
  AABB2d box;
  for (std::size_t i = 0; i < points.size(); i += 2) {
    if (!std::isfinite(points[i]) || !std::isfinite(points[i + 1]))
      throw Error("segment voronoi: point " + std::to_string(i / 2) + " is not finite");
    box.extend(Vec2d(points[i], points[i + 1]));
  }
  for (std::size_t i = 0; i < segments.size(); i += 4) {
    for (int k = 0; k < 4; ++k)
      if (!std::isfinite(segments[i + k]))
        throw Error("segment voronoi: segment " + std::to_string(i / 4) + " is not finite");
    box.extend(Vec2d(segments[i], segments[i + 1]));
    box.extend(Vec2d(segments[i + 2], segments[i + 3]));
  }
  centre_ = 0.5 * (box.lo + box.hi);
  const double half = 0.5 * (box.hi - box.lo).maxCoeff();
  if (half > 0) {
    const double room = kSnapLimit / half;
    if (!std::isfinite(room) || room < std::ldexp(1.0, -1000))
      throw Error("segment voronoi: coordinate extent " + format_number(half) + " out of range; scale the input");
    scale_ = std::ldexp(1.0, std::ilogb(room));
  }
  auto snap = [&](double x, double y) {
    return IntPoint{static_cast<std::int64_t>(std::nearbyint((x - centre_[0]) * scale_)),
                    static_cast<std::int64_t>(std::nearbyint((y - centre_[1]) * scale_))};
  };

  std::vector<IntPoint> ipts;
  std::unordered_map<IntPoint, std::uint32_t, IntPointHash> ids;
  auto get_id = [&](const IntPoint& p, std::uint32_t source) {
    auto [it, fresh] = ids.emplace(p, static_cast<std::uint32_t>(ipts.size()));
    if (fresh) {
      ipts.push_back(p);
      point_source_.push_back(source);
    } else if (point_source_[it->second] == kNone) {
      point_source_[it->second] = source;
    }
    return it->second;
  };
  for (std::size_t i = 0; i < input_points_; ++i)
    get_id(snap(points[2 * i], points[2 * i + 1]), static_cast<std::uint32_t>(i));
  std::vector<std::array<std::uint32_t, 2>> segs;
  std::vector<std::uint32_t> seg_source;
  for (std::size_t j = 0; j < input_segments_; ++j) {
    const std::uint32_t a = get_id(snap(segments[4 * j], segments[4 * j + 1]), kNone);
    const std::uint32_t b = get_id(snap(segments[4 * j + 2], segments[4 * j + 3]), kNone);
    if (a == b) continue;  // zero length: a point site
    segs.push_back({a, b});
    seg_source.push_back(static_cast<std::uint32_t>(j));
  }

  auto dedupe = [&]() {
    std::vector<std::uint32_t> order(segs.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    auto key = [&](std::uint32_t i) {
      return std::make_pair(std::min(segs[i][0], segs[i][1]), std::max(segs[i][0], segs[i][1]));
    };
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return key(a) != key(b) ? key(a) < key(b) : a < b;
    });
    std::vector<std::array<std::uint32_t, 2>> s2;
    std::vector<std::uint32_t> src2;
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (k > 0 && key(order[k]) == key(order[k - 1])) continue;
      s2.push_back(segs[order[k]]);
      src2.push_back(seg_source[order[k]]);
    }
    segs = std::move(s2);
    seg_source = std::move(src2);
  };
  dedupe();

  // Split crossing segments, and segments with a point (an isolated point or
  // another segment's endpoint) in their interior, until none is left.
  for (int round = 0;; ++round) {
    const std::size_t ns = segs.size();
    if (ns == 0) break;
    // A uniform grid over the snapped box for candidate pairs.
    const int g = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(ns))), 1, 2048);
    std::int64_t lo_x = INT64_MAX, lo_y = INT64_MAX, hi_x = INT64_MIN, hi_y = INT64_MIN;
    for (const auto& p : ipts) {
      lo_x = std::min(lo_x, p.x);
      lo_y = std::min(lo_y, p.y);
      hi_x = std::max(hi_x, p.x);
      hi_y = std::max(hi_y, p.y);
    }
    const double cw = std::max(1.0, static_cast<double>(hi_x - lo_x + 1) / g);
    const double ch = std::max(1.0, static_cast<double>(hi_y - lo_y + 1) / g);
    auto cell_x = [&](std::int64_t x) { return std::min(g - 1, static_cast<int>((x - lo_x) / cw)); };
    auto cell_y = [&](std::int64_t y) { return std::min(g - 1, static_cast<int>((y - lo_y) / ch)); };
    std::vector<std::vector<std::uint32_t>> grid(static_cast<std::size_t>(g) * g);
    for (std::uint32_t s = 0; s < ns; ++s) {
      const IntPoint& a = ipts[segs[s][0]];
      const IntPoint& b = ipts[segs[s][1]];
      for (int y = cell_y(std::min(a.y, b.y)); y <= cell_y(std::max(a.y, b.y)); ++y)
        for (int x = cell_x(std::min(a.x, b.x)); x <= cell_x(std::max(a.x, b.x)); ++x)
          grid[static_cast<std::size_t>(y) * g + x].push_back(s);
    }
    std::vector<std::vector<std::uint32_t>> cuts(ns);
    std::size_t found = 0;
    // Points in segment interiors.
    for (std::uint32_t p = 0; p < ipts.size(); ++p) {
      const IntPoint& c = ipts[p];
      for (std::uint32_t s : grid[static_cast<std::size_t>(cell_y(c.y)) * g + cell_x(c.x)]) {
        if (segs[s][0] == p || segs[s][1] == p) continue;
        const IntPoint& a = ipts[segs[s][0]];
        const IntPoint& b = ipts[segs[s][1]];
        if (orient(a, b, c) == 0 && strictly_between(a, b, c)) {
          cuts[s].push_back(p);
          ++found;
        }
      }
    }
    // Proper crossings and collinear overlaps.
    for (const auto& cell : grid) {
      for (std::size_t i = 0; i < cell.size(); ++i) {
        for (std::size_t j = i + 1; j < cell.size(); ++j) {
          const std::uint32_t s = std::min(cell[i], cell[j]), t = std::max(cell[i], cell[j]);
          const IntPoint a0 = ipts[segs[s][0]], a1 = ipts[segs[s][1]];  // copies: get_id below may grow ipts
          const IntPoint b0 = ipts[segs[t][0]], b1 = ipts[segs[t][1]];
          const int o1 = orient(a0, a1, b0), o2 = orient(a0, a1, b1);
          const int o3 = orient(b0, b1, a0), o4 = orient(b0, b1, a1);
          if (o1 == 0 && o2 == 0) {
            // Collinear: they may share an endpoint, otherwise they must not overlap.
            const bool horizontalish = a0.x != a1.x;
            auto coord = [&](const IntPoint& p) { return horizontalish ? p.x : p.y; };
            const auto alo = std::min(coord(a0), coord(a1)), ahi = std::max(coord(a0), coord(a1));
            const auto blo = std::min(coord(b0), coord(b1)), bhi = std::max(coord(b0), coord(b1));
            if (std::min(ahi, bhi) > std::max(alo, blo))
              throw Error("segment voronoi: segments " + std::to_string(seg_source[s]) + " and " +
                          std::to_string(seg_source[t]) + " overlap (collinear)");
            continue;
          }
          if (o1 * o2 < 0 && o3 * o4 < 0) {
            // The rounded crossing point (computed once per pair: the pair meets in several cells).
            const long double d = static_cast<long double>(a1.x - a0.x) * (b1.y - b0.y) -
                                  static_cast<long double>(a1.y - a0.y) * (b1.x - b0.x);
            const long double u = (static_cast<long double>(b0.x - a0.x) * (b1.y - b0.y) -
                                   static_cast<long double>(b0.y - a0.y) * (b1.x - b0.x)) / d;
            const long double cx = a0.x + u * (a1.x - a0.x), cy = a0.y + u * (a1.y - a0.y);
            const IntPoint c{std::llround(cx), std::llround(cy)};
            // Only in the cell holding the crossing, so that each pair is split once.
            const std::size_t home = static_cast<std::size_t>(cell_y(static_cast<std::int64_t>(std::floor(cy)))) * g +
                                     cell_x(static_cast<std::int64_t>(std::floor(cx)));
            if (&grid[home] != &cell) continue;
            const std::uint32_t id = get_id(c, kNone);
            if (!(c == a0) && !(c == a1)) cuts[s].push_back(id);
            if (!(c == b0) && !(c == b1)) cuts[t].push_back(id);
            ++found;
          }
        }
      }
    }
    if (found == 0) break;
    if (round >= 8) throw Error("segment voronoi: segments still cross after 8 rounds of splitting at snapped crossings");
    std::vector<std::array<std::uint32_t, 2>> s2;
    std::vector<std::uint32_t> src2;
    for (std::uint32_t s = 0; s < ns; ++s) {
      if (cuts[s].empty()) {
        s2.push_back(segs[s]);
        src2.push_back(seg_source[s]);
        continue;
      }
      const IntPoint a = ipts[segs[s][0]], b = ipts[segs[s][1]];
      auto along = [&](std::uint32_t p) {
        return static_cast<long double>(ipts[p].x - a.x) * (b.x - a.x) + static_cast<long double>(ipts[p].y - a.y) * (b.y - a.y);
      };
      auto& c = cuts[s];
      std::sort(c.begin(), c.end(), [&](std::uint32_t p, std::uint32_t q) { return along(p) < along(q); });
      c.erase(std::unique(c.begin(), c.end()), c.end());
      splits_ += c.size();
      std::uint32_t prev = segs[s][0];
      for (std::uint32_t p : c) {
        if (p != prev) {
          s2.push_back({prev, p});
          src2.push_back(seg_source[s]);
        }
        prev = p;
      }
      if (prev != segs[s][1]) {
        s2.push_back({prev, segs[s][1]});
        src2.push_back(seg_source[s]);
      }
    }
    segs = std::move(s2);
    seg_source = std::move(src2);
    dedupe();
  }

  detail::SweepInput in;
  in.points.reserve(ipts.size());
  for (const auto& p : ipts) in.points.emplace_back(static_cast<double>(p.x), static_cast<double>(p.y));
  in.segments = segs;
  const detail::SweepOutput out = detail::sweep_segment_voronoi(in);

  points_.reserve(ipts.size());
  for (const auto& p : ipts) points_.push_back(Vec2d(static_cast<double>(p.x), static_cast<double>(p.y)) / scale_ + centre_);
  segments_ = std::move(segs);
  segment_source_ = std::move(seg_source);
  vertices_.reserve(out.vertices.size());
  for (const auto& v : out.vertices)
    vertices_.push_back(Vertex{Vec2d(static_cast<double>(v.x / scale_), static_cast<double>(v.y / scale_)) + centre_,
                               static_cast<double>(v.r / scale_)});
  edges_.reserve(out.edges.size());
  const auto np = static_cast<std::uint32_t>(points_.size());
  for (const auto& e : out.edges) {
    Edge f;
    f.site = e.site;
    f.vertex = e.vertex;
    f.side = e.side;
    const bool s0 = e.site[0] >= np, s1 = e.site[1] >= np;
    if (s0 != s1) {
      const std::uint32_t p = s0 ? e.site[1] : e.site[0];
      const auto& sg = segments_[(s0 ? e.site[0] : e.site[1]) - np];
      f.primary = p != sg[0] && p != sg[1];
      f.parabolic = f.primary;
    }
    edges_.push_back(f);
  }
}

std::vector<std::vector<std::uint32_t>> SegmentVoronoi::cells() const {
  std::vector<std::vector<std::uint32_t>> c(num_sites());
  for (std::uint32_t e = 0; e < edges_.size(); ++e) {
    c[edges_[e].site[0]].push_back(e);
    if (edges_[e].site[1] != edges_[e].site[0]) c[edges_[e].site[1]].push_back(e);
  }
  return c;
}

double SegmentVoronoi::site_distance(std::uint32_t site, const Vec2d& x) const {
  if (site < points_.size()) return (x - points_[site]).norm();
  const auto& s = segments_[site - points_.size()];
  return point_segment_distance(x, points_[s[0]], points_[s[1]]);
}

SegmentVoronoi::EdgeCurve SegmentVoronoi::edge_curve(std::uint32_t e) const {
  const Edge& ed = edges_.at(e);
  const auto np = static_cast<std::uint32_t>(points_.size());
  EdgeCurve c;
  const std::uint32_t a = ed.site[0], b = ed.site[1];
  auto seg_ends = [&](std::uint32_t s) {
    const auto& sg = segments_[s - np];
    return std::make_pair(points_[sg[0]], points_[sg[1]]);
  };
  if (a < np && b < np) {
    const Vec2d p0 = points_[a], p1 = points_[b];
    c.origin = 0.5 * (p0 + p1);
    c.direction = perp_cw(p1 - p0).normalized();
  } else if (a >= np && b >= np) {
    const auto [a0, a1] = seg_ends(a);
    const auto [b0, b1] = seg_ends(b);
    const Vec2d n1 = ed.side[0] * perp_cw(a1 - a0).normalized();
    const Vec2d n2 = ed.side[1] * perp_cw(b1 - b0).normalized();
    const Vec2d m = n1 - n2;
    const double rhs = n1.dot(a0) - n2.dot(b0);
    const Vec2d mid = 0.25 * (a0 + a1 + b0 + b1);
    c.origin = mid - ((m.dot(mid) - rhs) / m.squaredNorm()) * m;
    c.direction = Vec2d(-m[1], m[0]).normalized();
    if (cross(c.direction, n1) < 0) c.direction = -c.direction;
  } else {
    const std::uint32_t p = a < np ? a : b, s = a < np ? b : a;
    const auto [s0, s1] = seg_ends(s);
    const Vec2d q = points_[p];
    const Vec2d u = (s1 - s0).normalized();
    if (!ed.parabolic) {
      // A segment and its own endpoint: the perpendicular through the endpoint.
      const Vec2d other = q == s0 ? s1 : s0;
      c.origin = q;
      c.direction = Vec2d(-u[1], u[0]);
      const bool segment_right = cross(c.direction, other - q) < 0;
      if (segment_right != (a == s)) c.direction = -c.direction;
    } else {
      c.parabolic = true;
      c.focus = q;
      c.origin = s0;
      c.direction = u;
      Vec2d np_dir(-u[1], u[0]);
      if (np_dir.dot(q - s0) < 0) np_dir = -np_dir;
      const bool point_right_if_forward = cross(u, np_dir) < 0;
      if (point_right_if_forward != (a == p)) c.direction = -u;
    }
  }
  auto param = [&](std::uint32_t v) { return (vertices_[v].position - c.origin).dot(c.direction); };
  const double inf = std::numeric_limits<double>::infinity();
  c.t0 = ed.vertex[1] == kNone ? -inf : param(ed.vertex[1]);
  c.t1 = ed.vertex[0] == kNone ? inf : param(ed.vertex[0]);
  return c;
}

double SegmentVoronoi::edge_clearance(std::uint32_t e) const {
  const EdgeCurve c = edge_curve(e);
  return edge_clearance(e, c.t0, c.t1);
}

double SegmentVoronoi::edge_clearance(std::uint32_t e, double a, double b) const {
  const EdgeCurve c = edge_curve(e);
  const Edge& ed = edges_[e];
  const auto np = static_cast<std::uint32_t>(points_.size());
  // The distance to the sites along the curve is convex in the parameter, smallest at tstar.
  double tstar = 0;  // point-point and a segment with its endpoint: the origin
  if (c.parabolic) {
    tstar = (c.focus - c.origin).dot(c.direction);
  } else if (ed.site[0] >= np && ed.site[1] >= np) {
    const auto& sg = segments_[ed.site[0] - np];
    const Vec2d a0 = points_[sg[0]], a1 = points_[sg[1]];
    const Vec2d n1 = perp_cw(a1 - a0).normalized();
    const double den = n1.dot(c.direction);
    tstar = den != 0 ? -n1.dot(c.origin - a0) / den : a;
  }
  const double t = std::clamp(tstar, a, b);
  if (!std::isfinite(t)) return std::numeric_limits<double>::infinity();
  return site_distance(ed.site[0], c.point(t));
}

double SegmentVoronoi::edge_length(std::uint32_t e, double a, double b) const {
  const EdgeCurve c = edge_curve(e);
  if (!c.parabolic) return std::abs(b - a);
  const Vec2d rel = c.focus - c.origin;
  const double tp = rel.dot(c.direction);
  // The curve is y(t) = ((t - tp)^2 + H^2) / (2 H), H the focus' distance to the directrix: dy/dt = (t - tp) / H.
  const double H = std::abs(cross(c.direction, rel));
  auto F = [&](double u) { return 0.5 * u * std::sqrt(1 + (u / H) * (u / H)) + 0.5 * H * std::asinh(u / H); };
  return std::abs(F(b - tp) - F(a - tp));
}

std::vector<Vec2d> SegmentVoronoi::sample_edge(std::uint32_t e, double a, double b, double step) const {
  if (!(step > 0)) throw Error("segment voronoi: sample step must be positive");
  const EdgeCurve c = edge_curve(e);
  const double length = edge_length(e, std::min(a, b), std::max(a, b));
  const auto n = static_cast<std::size_t>(std::clamp(std::ceil(length / step), 1.0, 1e6));
  std::vector<Vec2d> out;
  out.reserve(n + 1);
  for (std::size_t k = 0; k <= n; ++k) out.push_back(c.point(a + (b - a) * static_cast<double>(k) / static_cast<double>(n)));
  return out;
}

std::vector<Vec2d> SegmentVoronoi::sample_edge(std::uint32_t e, double step, const AABB2d& box) const {
  if (!(step > 0)) throw Error("segment voronoi: sample step must be positive");
  const EdgeCurve c = edge_curve(e);
  double t0 = c.t0, t1 = c.t1;
  if (t0 > t1) std::swap(t0, t1);
  const bool unbounded = !std::isfinite(t0) || !std::isfinite(t1);
  if (unbounded) {
    // Far enough that the curve is outside the box beyond these parameters.
    double reach = 0;
    for (int k = 0; k < 4; ++k) {
      const Vec2d corner((k & 1) ? box.hi[0] : box.lo[0], (k & 2) ? box.hi[1] : box.lo[1]);
      reach = std::max(reach, (corner - c.origin).norm());
    }
    double centre_t = 0, extra = reach;
    if (c.parabolic) {
      const Vec2d rel = c.focus - c.origin;
      centre_t = rel.dot(c.direction);
      const double h = std::abs(cross(c.direction, rel));
      extra = std::sqrt(2 * h * reach) + reach;
    }
    if (!std::isfinite(t0)) t0 = std::min(centre_t, std::isfinite(t1) ? t1 : centre_t) - extra;
    if (!std::isfinite(t1)) t1 = std::max(centre_t, t0) + extra;
  }
  // Arc length estimate for the number of samples.
  double length = 0;
  const int coarse = c.parabolic ? 64 : 1;
  Vec2d prev = c.point(t0);
  for (int k = 1; k <= coarse; ++k) {
    const Vec2d q = c.point(t0 + (t1 - t0) * k / coarse);
    length += (q - prev).norm();
    prev = q;
  }
  const auto n = static_cast<std::size_t>(std::clamp(std::ceil(length / step), 1.0, 1e6));
  std::vector<Vec2d> out;
  out.reserve(n + 1);
  for (std::size_t k = 0; k <= n; ++k) {
    const Vec2d q = c.point(t0 + (t1 - t0) * static_cast<double>(k) / static_cast<double>(n));
    if (unbounded && !box.contains(q)) continue;
    out.push_back(q);
  }
  if (c.t0 > c.t1) std::reverse(out.begin(), out.end());
  return out;
}

std::vector<std::array<Vec2d, 2>> SegmentVoronoi::segment_geometry() const {
  std::vector<std::array<Vec2d, 2>> out;
  out.reserve(segments_.size());
  for (const auto& s : segments_) out.push_back({points_[s[0]], points_[s[1]]});
  return out;
}

bool SegmentVoronoi::inside(const Vec2d& x) const { return detail::EvenOddIndex(segment_geometry()).inside(x); }

std::vector<std::uint32_t> SegmentVoronoi::medial_axis() const {
  const detail::EvenOddIndex index(segment_geometry());
  std::vector<std::uint32_t> out;
  for (std::uint32_t e = 0; e < edges_.size(); ++e) {
    const Edge& ed = edges_[e];
    if (!ed.primary || ed.vertex[0] == kNone || ed.vertex[1] == kNone) continue;
    const EdgeCurve c = edge_curve(e);
    if (index.inside(c.point(0.5 * (c.t0 + c.t1)))) out.push_back(e);
  }
  return out;
}

AABB2d SegmentVoronoi::bounds() const {
  AABB2d b;
  for (const auto& p : points_) b.extend(p);
  for (const auto& v : vertices_) b.extend(v.position);
  return b;
}

SegmentVoronoiStats SegmentVoronoi::stats() const {
  SegmentVoronoiStats s;
  s.input_points = input_points_;
  s.input_segments = input_segments_;
  s.points = points_.size();
  s.segments = segments_.size();
  s.splits = splits_;
  s.vertices = vertices_.size();
  s.edges = edges_.size();
  for (const auto& e : edges_) {
    s.parabolic_edges += e.parabolic;
    s.secondary_edges += !e.primary;
    s.infinite_edges += e.vertex[0] == kNone || e.vertex[1] == kNone;
  }
  s.bytes = points_.size() * sizeof(Vec2d) + segments_.size() * sizeof(segments_[0]) +
            vertices_.size() * sizeof(Vertex) + edges_.size() * sizeof(Edge) +
            (segment_source_.size() + point_source_.size()) * sizeof(std::uint32_t);
  return s;
}

void SegmentVoronoi::validate() const {
  AABB2d b;
  for (const auto& p : points_) b.extend(p);
  const double extent = std::max(1e-300, (b.hi - b.lo).maxCoeff());
  for (std::uint32_t e = 0; e < edges_.size(); ++e) {
    const Edge& ed = edges_[e];
    for (int k = 0; k < 2; ++k) {
      if (ed.site[k] >= num_sites()) throw Error("segment voronoi: edge " + std::to_string(e) + " has a bad site");
      if (ed.vertex[k] != kNone && ed.vertex[k] >= vertices_.size())
        throw Error("segment voronoi: edge " + std::to_string(e) + " has a bad vertex");
    }
    for (int k = 0; k < 2; ++k) {
      if (ed.vertex[k] == kNone) continue;
      const Vertex& v = vertices_[ed.vertex[k]];
      for (int j = 0; j < 2; ++j) {
        const double d = site_distance(ed.site[j], v.position);
        // (|position|: far from the origin a vertex is only as exact as its coordinates' own rounding.)
        if (std::abs(d - v.clearance) >
            1e-7 * extent + 16 * std::numeric_limits<double>::epsilon() * v.position.cwiseAbs().maxCoeff())
          throw Error("segment voronoi: vertex " + std::to_string(ed.vertex[k]) + " is not equidistant to the sites of edge " +
                      std::to_string(e));
      }
    }
  }
}

}  // namespace geods::voronoi
