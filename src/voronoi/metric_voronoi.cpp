// Voronoi diagrams under L1, L-infinity and L2: cells cut out by bisector pieces.
#include "geods/voronoi/metric_voronoi.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/polygon_clip.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kFrameSide = 0xffffffffu;  // a piece of the frame, not of a bisector
constexpr double kTieBreak = 1e-9;

struct Piece {
  Vec2d a, b;
  std::uint32_t neighbor;
};

// Disjoint increasing parameter intervals of a piece, without allocation.
struct Intervals {
  static constexpr int kCapacity = 32;
  std::array<std::array<double, 2>, kCapacity> v;
  int size = 0;

  void add(double t0, double t1) {
    if (size > 0 && v[size - 1][1] >= t0) {
      v[size - 1][1] = std::max(v[size - 1][1], t1);
      return;
    }
    if (size == kCapacity) throw Error("MetricVoronoi: a bisector piece split into more than 32 parts");
    v[size++] = {t0, t1};
  }
  bool whole() const { return size == 1 && v[0][0] <= 0 && v[0][1] >= 1; }
};

Intervals intersect(const Intervals& a, const Intervals& b) {
  Intervals out;
  for (int i = 0, j = 0; i < a.size && j < b.size;) {
    const double lo = std::max(a.v[i][0], b.v[j][0]), hi = std::min(a.v[i][1], b.v[j][1]);
    if (lo < hi) out.add(lo, hi);
    (a.v[i][1] < b.v[j][1] ? i : j)++;
  }
  return out;
}

// (x, y) -> (x + y, x - y): L-infinity distances become half the L1 distances of the images.
Vec2d turn(const Vec2d& v) { return {v[0] + v[1], v[0] - v[1]}; }
Vec2d unturn(const Vec2d& v) { return {(v[0] + v[1]) / 2, (v[0] - v[1]) / 2}; }

// The L1 bisector of p and q as up to three segments (rays cut at length `far`).
std::vector<std::pair<Vec2d, Vec2d>> l1_bisector(const Vec2d& p, const Vec2d& q, double far) {
  const Vec2d d = q - p;
  const double sx = d[0] >= 0 ? 1 : -1, sy = d[1] >= 0 ? 1 : -1;
  const bool swap = std::abs(d[1]) > std::abs(d[0]);
  const double a = swap ? std::abs(d[1]) : std::abs(d[0]), b = swap ? std::abs(d[0]) : std::abs(d[1]);
  // In a frame where p = (0, 0) and q = (a, b) with a >= b >= 0: a vertical ray up
  // from ((a - b) / 2, b), the diagonal down to ((a + b) / 2, 0), a vertical ray down.
  const auto place = [&](double u, double v) {
    if (swap) std::swap(u, v);
    return Vec2d(p[0] + sx * u, p[1] + sy * v);
  };
  const Vec2d top = place((a - b) / 2, b), bottom = place((a + b) / 2, 0);
  std::vector<std::pair<Vec2d, Vec2d>> out;
  out.push_back({top, place((a - b) / 2, b + far)});
  if (b > 0) out.push_back({top, bottom});
  out.push_back({bottom, place((a + b) / 2, -far)});
  return out;
}

class CellBuilder {
 public:
  CellBuilder(std::span<const Vec2d> points, Metric metric, const AABB2d& frame)
      : points_(points), metric_(metric), frame_(frame),
        far_(4 * (frame.hi - frame.lo).norm()), scale_((frame.hi - frame.lo).norm()) {}

  // The whole frame: the cell of a site before any other site is considered.
  std::vector<Piece> frame_pieces() const {
    std::vector<Piece> out;
    for (int k = 0; k < 4; ++k) out.push_back({corner(k), corner(k + 1), kFrameSide});
    return out;
  }

  // Cuts site q's part out of the cell of p given by its boundary pieces and the
  // sites that made it (`active`): the pieces keep what is not nearer to q, and
  // the bisector of p and q adds what is not nearer to an active site.
  void cut(std::uint32_t p, std::uint32_t q, std::span<const std::uint32_t> active, std::vector<Piece>& pieces) const {
    std::vector<Piece> kept;
    const auto keep = [&](const Piece& piece, const Intervals& intervals) {
      for (int k = 0; k < intervals.size; ++k) {
        const Vec2d d = piece.b - piece.a;
        const Vec2d a = piece.a + intervals.v[k][0] * d, b = piece.a + intervals.v[k][1] * d;
        if ((b - a).norm() > 1e-12 * scale_) kept.push_back({a, b, piece.neighbor});
      }
    };
    for (const Piece& piece : pieces) keep(piece, allowed(piece, points_[p], points_[q]));
    for (const auto& [a, b] : bisector(points_[p], points_[q])) {
      const auto clipped = clip_segment_to_box(a, b, frame_);
      if (!clipped || clipped->first == clipped->second) continue;
      const Piece piece{clipped->first, clipped->second, q};
      Intervals intervals;
      intervals.add(0, 1);
      for (std::uint32_t r : active) {
        intervals = intersect(intervals, allowed(piece, points_[p], points_[r]));
        if (intervals.size == 0) break;
      }
      keep(piece, intervals);
    }
    pieces = std::move(kept);
  }

  // Joins the pieces around the site into a counter-clockwise polygon.
  std::vector<Vec2d> polygon(const Vec2d& site, std::vector<Piece>& pieces) const {
    const auto angle = [&](const Piece& s) {
      const Vec2d m = (s.a + s.b) / 2 - site;
      return std::atan2(m[1], m[0]);
    };
    std::sort(pieces.begin(), pieces.end(), [&](const Piece& x, const Piece& y) { return angle(x) < angle(y); });
    std::vector<Vec2d> out;
    for (Piece& s : pieces) {
      const double cross = (s.a - site)[0] * (s.b - site)[1] - (s.a - site)[1] * (s.b - site)[0];
      // Pieces on a ray from the site (possible at the degenerate quadrants) have no
      // turning sense: they start where the previous piece ended.
      if (out.empty() ? cross < 0 : (cross < 0 || (cross == 0 && (s.b - out.back()).norm() < (s.a - out.back()).norm())))
        std::swap(s.a, s.b);
      for (const Vec2d& v : {s.a, s.b})
        if (out.empty() || (v - out.back()).norm() > 1e-12 * scale_) out.push_back(v);
    }
    while (out.size() > 1 && (out.front() - out.back()).norm() <= 1e-12 * scale_) out.pop_back();
    return out;
  }

  double distance(const Vec2d& x, const Vec2d& p) const { return metric_distance(metric_, x, p); }

  // Whether site r takes part of the cell `polygon` of site p.
  bool takes_part(const std::vector<Vec2d>& polygon, const Vec2d& p, const Vec2d& r) const {
    if (point_in_polygon(r, polygon)) return true;
    for (std::size_t k = 0; k < polygon.size(); ++k) {
      if (!allowed({polygon[k], polygon[(k + 1) % polygon.size()], kFrameSide}, p, r).whole()) return true;
    }
    return false;
  }

 private:
  Vec2d corner(int k) const {
    switch (k % 4) {
      case 0: return frame_.lo;
      case 1: return {frame_.hi[0], frame_.lo[1]};
      case 2: return frame_.hi;
      default: return {frame_.lo[0], frame_.hi[1]};
    }
  }

  std::vector<std::pair<Vec2d, Vec2d>> bisector(const Vec2d& p, const Vec2d& q) const {
    switch (metric_) {
      case Metric::l1: return l1_bisector(p, q, far_);
      case Metric::linf: {
        auto pieces = l1_bisector(turn(p), turn(q), 2 * far_);
        for (auto& [a, b] : pieces) a = unturn(a), b = unturn(b);
        return pieces;
      }
      default: {
        const Vec2d m = (p + q) / 2, d = q - p;
        const Vec2d u = Vec2d(-d[1], d[0]).normalized() * far_;
        return {{m - u, m + u}};
      }
    }
  }

  // The distance of x from p as the diagram sees it: L2 squared (so that the
  // difference of two is linear), L1 and L-infinity with the tie-breaking term.
  double biased(const Vec2d& x, const Vec2d& p) const {
    const Vec2d d = x - p;
    switch (metric_) {
      case Metric::l1: return std::abs(d[0]) + std::abs(d[1]) + kTieBreak * std::abs(d[0]);
      case Metric::linf: return std::max(std::abs(d[0]), std::abs(d[1])) + kTieBreak * std::abs(d[0] + d[1]);
      default: return d.squaredNorm();
    }
  }

  // The parameters t in [0, 1] where piece.a + t (piece.b - piece.a) is not nearer to r than to p.
  Intervals allowed(const Piece& piece, const Vec2d& p, const Vec2d& r) const {
    // Both distances are linear between the crossings with the axis-parallel and
    // diagonal lines through p and r.
    std::array<double, 10> ts;
    std::size_t count = 0;
    ts[count++] = 0;
    ts[count++] = 1;
    const Vec2d d = piece.b - piece.a;
    if (metric_ != Metric::l2) {
      for (const Vec2d* s : {&p, &r}) {
        const Vec2d o = *s - piece.a;
        const double crossings[4][2] = {{o[0], d[0]}, {o[1], d[1]}, {o[0] + o[1], d[0] + d[1]}, {o[0] - o[1], d[0] - d[1]}};
        for (const auto& [num, den] : crossings)
          if (den != 0 && num / den > 0 && num / den < 1) ts[count++] = num / den;
      }
    }
    for (std::size_t i = 1; i < count; ++i)  // insertion sort of at most 10 values
      for (std::size_t j = i; j > 0 && ts[j] < ts[j - 1]; --j) std::swap(ts[j], ts[j - 1]);
    Intervals out;
    const auto f = [&](double t) {
      const Vec2d x = piece.a + t * d;
      return biased(x, p) - biased(x, r);
    };
    const auto add = [&](double t0, double t1) { out.add(t0, t1); };
    double f0 = f(ts[0]);
    for (std::size_t k = 0; k + 1 < count; ++k) {
      const double t0 = ts[k], t1 = ts[k + 1];
      if (t1 <= t0) continue;
      const double f1 = f(t1);
      if (f0 <= 0 && f1 <= 0) {
        add(t0, t1);
      } else if (f0 <= 0 || f1 <= 0) {
        const double root = std::clamp(t0 + (t1 - t0) * f0 / (f0 - f1), t0, t1);
        f0 <= 0 ? add(t0, root) : add(root, t1);
      }
      f0 = f1;
    }
    return out;
  }

  std::span<const Vec2d> points_;
  Metric metric_;
  AABB2d frame_;
  double far_, scale_;
};

}  // namespace

std::string metric_name(Metric metric) {
  switch (metric) {
    case Metric::l1: return "l1";
    case Metric::linf: return "linf";
    default: return "l2";
  }
}

Metric parse_metric(const std::string& name) {
  if (name == "l2" || name == "euclidean") return Metric::l2;
  if (name == "l1" || name == "manhattan") return Metric::l1;
  if (name == "linf" || name == "chebyshev") return Metric::linf;
  throw Error("unknown metric '" + name + "' (expected l2, l1 or linf)");
}

double metric_distance(Metric metric, const Vec2d& a, const Vec2d& b) {
  const Vec2d d = (a - b).cwiseAbs();
  switch (metric) {
    case Metric::l1: return d[0] + d[1];
    case Metric::linf: return std::max(d[0], d[1]);
    default: return d.norm();
  }
}

MetricVoronoi::MetricVoronoi(std::span<const Vec2d> points, Metric metric, const AABB2d& box)
    : points_(points.begin(), points.end()), metric_(metric), box_(box) {
  const std::size_t n = points.size();
  if (n == 0) throw Error("MetricVoronoi: no points");
  if (n >= kFrameSide) throw Error("MetricVoronoi: 2^32 - 1 points or more");
  if (box.empty() || !box.lo.allFinite() || !box.hi.allFinite() || box.lo[0] == box.hi[0] || box.lo[1] == box.hi[1])
    throw Error("MetricVoronoi: the box must be finite with positive width and height");
  AABB2d frame = box;
  for (std::size_t i = 0; i < n; ++i) {
    if (!points[i].allFinite()) throw Error("MetricVoronoi: non-finite coordinates at point " + std::to_string(i));
    frame.extend(points[i]);
  }
  // The frame holds every site strictly inside, so every cell is star-shaped within it.
  const double margin = 0.05 * std::max(frame.hi[0] - frame.lo[0], frame.hi[1] - frame.lo[1]);
  frame.lo.array() -= margin;
  frame.hi.array() += margin;

  // Duplicates: the first occurrence of equal points.
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  const auto key = [&](std::uint32_t i) { return std::tuple(points[i][0], points[i][1], i); };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  representative_.resize(n);
  for (std::size_t k = 0; k < n; ++k)
    representative_[order[k]] = k > 0 && points[order[k]] == points[order[k - 1]] ? representative_[order[k - 1]] : order[k];
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < n; ++i)
    if (representative_[i] == i) sites.push_back(i);
  std::vector<Vec2d> site_points(sites.size());
  for (std::size_t k = 0; k < sites.size(); ++k) site_points[k] = points[sites[k]];

  const spatial::KdTree<double, 2> tree{spatial::PointView<double>(std::span<const Vec2d>(site_points))};
  const CellBuilder builder(site_points, metric, frame);

  std::vector<std::vector<Vec2d>> site_cells(sites.size());
  std::vector<std::vector<Piece>> site_pieces(sites.size());
  std::vector<std::size_t> consulted(sites.size());
  parallel_for_each_index(0, sites.size(), [&](std::size_t s) {
    const Vec2d& p = site_points[s];
    // Start from the nearest sites, then offer the others nearest first: a site
    // joins only if it takes part of the current cell (it lies in it, or some
    // boundary point is nearer to it, which catches every site whose region meets
    // the cell because that region is star-shaped around its site). Sites beyond
    // twice the cell's reach cannot take anything.
    std::vector<std::uint32_t> active;
    std::vector<Piece> pieces = builder.frame_pieces();
    std::vector<Vec2d> polygon = builder.polygon(p, pieces);
    double reach = std::numeric_limits<double>::infinity();
    AABB2d bounds = frame;
    // A site farther from the cell's bounding box than the cell's reach cannot take any of it.
    const auto near_cell = [&](std::uint32_t q) {
      const Vec2d gap = (bounds.lo - site_points[q]).cwiseMax(site_points[q] - bounds.hi).cwiseMax(0.0);
      return metric_distance(metric, gap, Vec2d::Zero()) < reach;
    };
    const auto offer = [&](std::uint32_t q) {
      if (!near_cell(q) || !builder.takes_part(polygon, p, site_points[q])) return;
      builder.cut(std::uint32_t(s), q, active, pieces);
      active.push_back(q);
      polygon = builder.polygon(p, pieces);
      reach = 0;
      bounds = AABB2d();
      for (const Vec2d& v : polygon) reach = std::max(reach, builder.distance(v, p)), bounds.extend(v);
    };
    // The nearest few first; then, if the cell still reaches far, every site
    // within its reach of the cell's bounding box, nearest first.
    const auto nearest = tree.query(p, std::min<std::size_t>(17, sites.size()));
    for (const auto& nb : nearest)
      if (nb.index != s) offer(nb.index);
    if (nearest.size() < sites.size()) {
      AABB2d around = bounds;
      around.lo.array() -= reach;
      around.hi.array() += reach;
      std::vector<std::pair<double, std::uint32_t>> more;  // squared distance, site
      for (std::uint32_t q : tree.query_box(around))
        if (q != s && near_cell(q)) more.push_back({(site_points[q] - p).squaredNorm(), q});
      std::sort(more.begin(), more.end());
      for (const auto& [d, q] : more)
        if (std::find(active.begin(), active.end(), q) == active.end()) offer(q);
    }
    consulted[s] = active.size();
    site_pieces[s] = std::move(pieces);
    site_cells[s] = clip_polygon_to_box(polygon, box);
  });

  cells_.resize(n);
  for (std::size_t s = 0; s < sites.size(); ++s) {
    max_candidates_ = std::max(max_candidates_, consulted[s]);
    for (const Piece& piece : site_pieces[s]) {
      if (piece.neighbor == kFrameSide || sites[piece.neighbor] < sites[s]) continue;
      if (const auto clipped = clip_segment_to_box(piece.a, piece.b, box); clipped && clipped->first != clipped->second)
        edges_.push_back({sites[s], sites[piece.neighbor], clipped->first, clipped->second});
    }
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto at = std::lower_bound(sites.begin(), sites.end(), representative_[i]);
    cells_[i] = site_cells[std::size_t(at - sites.begin())];
  }
}

MetricVoronoiStats MetricVoronoi::stats() const {
  MetricVoronoiStats s;
  s.sites = points_.size();
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    if (representative_[i] != i) continue;
    ++s.distinct;
    s.cell_vertices += cells_[i].size();
  }
  s.edges = edges_.size();
  s.max_candidates = max_candidates_;
  return s;
}

void MetricVoronoi::validate() const {
  const double scale = (box_.hi - box_.lo).norm();
  AABB2d grown = box_;
  grown.lo.array() -= 1e-9 * scale;
  grown.hi.array() += 1e-9 * scale;
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    if (cells_[i].empty()) continue;
    if (polygon_area(cells_[i]) <= 0) throw Error("MetricVoronoi::validate: cell " + std::to_string(i) + " is not counter-clockwise");
    for (const Vec2d& v : cells_[i])
      if (!grown.contains(v)) throw Error("MetricVoronoi::validate: cell " + std::to_string(i) + " leaves the box");
  }
  for (const Edge& e : edges_)
    for (const Vec2d& x : {e.p0, e.p1}) {
      const double da = metric_distance(metric_, x, points_[e.a]), db = metric_distance(metric_, x, points_[e.b]);
      if (std::abs(da - db) > 1e-6 * (da + db) + 1e-12 * scale)
        throw Error("MetricVoronoi::validate: an edge of sites " + std::to_string(e.a) + " and " + std::to_string(e.b) +
                    " is not on their bisector");
    }
}

}  // namespace geods::voronoi
