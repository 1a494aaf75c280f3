// Voronoi diagrams under L1 and L-infinity, cells cut out by bisector pieces;
// under L2, Voronoi2 clipped to the box.
#include "geods/voronoi/metric_voronoi.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/polygon_clip.hpp"
#include "geods/voronoi/voronoi2.hpp"
#include "generalized_common.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kFrameSide = 0xffffffffu;  // a piece of the frame, not of a bisector
constexpr double kTieBreak = 1e-9;
constexpr double kResolution = 1e-6;  // L1 and L-infinity: the closest distinct sites, relative to the frame

// A piece of a cell's boundary; `inward` is its unit normal into the cell.
struct Piece {
  Vec2d a, b;
  std::uint32_t neighbor;
  Vec2d inward;
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

// The bisector of p and q under the distance w |dx| + |dy| (w >= 1): the L1
// bisector with x stretched by w.
std::vector<std::pair<Vec2d, Vec2d>> stretched_l1_bisector(const Vec2d& p, const Vec2d& q, double w, double far) {
  const Vec2d d = q - p;
  auto pieces = l1_bisector(Vec2d::Zero(), Vec2d(w * d[0], d[1]), w * far);
  for (auto& [a, b] : pieces) a = p + Vec2d(a[0] / w, a[1]), b = p + Vec2d(b[0] / w, b[1]);
  return pieces;
}

class CellBuilder {
 public:
  CellBuilder(std::span<const Vec2d> points, Metric metric, const AABB2d& frame)
      : points_(points), metric_(metric), frame_(frame),
        far_(4 * (frame.hi - frame.lo).norm()), scale_((frame.hi - frame.lo).norm()) {}

  // The whole frame: the cell of a site before any other site is considered.
  std::vector<Piece> frame_pieces() const {
    std::vector<Piece> out;
    for (int k = 0; k < 4; ++k) out.push_back({corner(k), corner(k + 1), kFrameSide, left_normal(corner(k), corner(k + 1))});
    return out;
  }

  // Cuts site q's part out of the cell of p given by its boundary pieces and the
  // sites that made it (`active`): the pieces keep what is not nearer to q, and
  // the bisector of p and q adds what is not nearer to an active site.
  //
  // Where a piece runs along the bisector of the site and another (three
  // sites tie on a line, as lattice sites do under L-infinity), the line
  // itself goes to one of them by the tie-break and its two sides to the
  // others: deciding on the line kept a zero-width spike in one cell and
  // dropped the boundary of the other two. There it is decided a tiny step
  // off the piece, inside the cell (allowed()).
  void cut(std::uint32_t p, std::uint32_t q, std::span<const std::uint32_t> active, std::vector<Piece>& pieces) const {
    const Vec2d &site = points_[p], &other = points_[q];
    std::vector<Piece> kept;
    const auto keep = [&](const Piece& piece, const Intervals& intervals) {
      for (int k = 0; k < intervals.size; ++k) {
        const Vec2d d = piece.b - piece.a;
        const Vec2d a = piece.a + intervals.v[k][0] * d, b = piece.a + intervals.v[k][1] * d;
        // (Shorter pieces are the tie-break's slivers, or rounding's.)
        if ((b - a).norm() > std::max(1e-12 * scale_, 4 * kTieBreak * (a - site).norm()))
          kept.push_back({a, b, piece.neighbor, piece.inward});
      }
    };
    for (const Piece& piece : pieces) keep(piece, allowed(piece, site, other));
    for (const auto& [a, b] : bisector(site, other)) {
      const auto clipped = clip_segment_to_box(a, b, frame_);
      if (!clipped || clipped->first == clipped->second) continue;
      Piece piece{clipped->first, clipped->second, q, left_normal(clipped->first, clipped->second)};
      // The cell's side: where the site is the nearer of the two.
      const Vec2d m = (piece.a + piece.b) / 2, step = probe_step(m, site, other) * piece.inward;
      if (farther(m + step, site, other) > farther(m - step, site, other))
        piece.inward = -piece.inward;
      Intervals intervals;
      intervals.add(0, 1);
      for (std::uint32_t r : active) {
        intervals = intersect(intervals, allowed(piece, site, points_[r]));
        if (intervals.size == 0) break;
      }
      keep(piece, intervals);
    }
    pieces = std::move(kept);
  }

  // After the last cut: where pieces overlap on one line (the bisectors of
  // the site and two others can share a line, and a piece kept from an early
  // cut then runs along a later one), the overlap is kept once, with the
  // neighbour nearer just outside it.
  void settle(std::vector<Piece>& pieces) const {
    const auto resolve_one = [&] {
      for (std::size_t i = 0; i < pieces.size(); ++i)
        for (std::size_t j = i + 1; j < pieces.size(); ++j) {
          const Piece x = pieces[i], y = pieces[j];
          if (x.neighbor == kFrameSide || y.neighbor == kFrameSide) continue;
          const Vec2d d = x.b - x.a;
          const double length2 = d.squaredNorm();
          const auto off_line = [&](const Vec2d& v) {
            return std::abs(cross(d, v - x.a)) > 1e-12 * scale_ * std::sqrt(length2);
          };
          if (off_line(y.a) || off_line(y.b)) continue;
          const double ta = d.dot(y.a - x.a) / length2, tb = d.dot(y.b - x.a) / length2;
          const double y0 = std::min(ta, tb), y1 = std::max(ta, tb), lo = std::max(0.0, y0), hi = std::min(1.0, y1);
          if (!((hi - lo) * std::sqrt(length2) > 1e-12 * scale_)) continue;  // apart, or touching
          pieces.erase(pieces.begin() + std::ptrdiff_t(j));
          pieces.erase(pieces.begin() + std::ptrdiff_t(i));
          const auto add = [&](const Piece& like, double t0, double t1) {
            if ((t1 - t0) * std::sqrt(length2) > 1e-12 * scale_)
              pieces.push_back({x.a + t0 * d, x.a + t1 * d, like.neighbor, like.inward});
          };
          if (x.neighbor == y.neighbor) {
            add(x, std::min(0.0, y0), std::max(1.0, y1));
            return true;
          }
          const Vec2d middle = x.a + (lo + hi) / 2 * d;
          const Vec2d out = middle - probe_step(middle, points_[x.neighbor], points_[y.neighbor]) * x.inward;
          const bool x_nearer = farther(out, points_[x.neighbor], points_[y.neighbor]) <= 0;
          const Piece &kept = x_nearer ? x : y, &cut = x_nearer ? y : x;
          const double c0 = x_nearer ? y0 : 0.0, c1 = x_nearer ? y1 : 1.0;
          add(kept, x_nearer ? 0.0 : y0, x_nearer ? 1.0 : y1);
          add(cut, c0, lo);
          add(cut, hi, c1);
          return true;
        }
      return false;
    };
    while (resolve_one()) {
    }
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
      const double turn_sense = cross(s.a - site, s.b - site);
      // Pieces on a ray from the site (possible at the degenerate quadrants) have no
      // turning sense: they start where the previous piece ended.
      if (out.empty() ? turn_sense < 0
                      : (turn_sense < 0 || (turn_sense == 0 && (s.b - out.back()).norm() < (s.a - out.back()).norm())))
        std::swap(s.a, s.b);
      for (const Vec2d& v : {s.a, s.b})
        if (out.empty() || (v - out.back()).norm() > 1e-12 * scale_) out.push_back(v);
    }
    while (out.size() > 1 && (out.front() - out.back()).norm() <= 1e-12 * scale_) out.pop_back();
    return out;
  }

  double distance(const Vec2d& x, const Vec2d& p) const { return metric_distance(metric_, x, p); }

  // Whether site r takes part of the cell `polygon` of site p (its boundary,
  // or just inside it: the cell is on the left of its counter-clockwise edges).
  bool takes_part(const std::vector<Vec2d>& polygon, const Vec2d& p, const Vec2d& r) const {
    if (point_in_polygon(r, polygon)) return true;
    for (std::size_t k = 0; k < polygon.size(); ++k) {
      const Vec2d &a = polygon[k], &b = polygon[(k + 1) % polygon.size()];
      if (!allowed({a, b, kFrameSide, left_normal(a, b)}, p, r).whole()) return true;
    }
    return false;
  }

 private:
  // The unit normal to the left of a -> b.
  static Vec2d left_normal(const Vec2d& a, const Vec2d& b) {
    const Vec2d d = b - a;
    const double length = d.norm();
    return length > 0 ? Vec2d(Vec2d(-d[1], d[0]) / length) : Vec2d(Vec2d::Zero());
  }
  // How far off a piece at x membership is decided where p and r tie along
  // it: far enough that their distances differ by more than the tie-break
  // there, and no farther (boundaries move by about that much).
  double probe_step(const Vec2d& x, const Vec2d& p, const Vec2d& r) const {
    return 16 * kTieBreak * ((x - p).cwiseAbs().sum() + (x - r).cwiseAbs().sum()) + 0x1p-40 * scale_;
  }

  Vec2d corner(int k) const {
    switch (k % 4) {
      case 0: return frame_.lo;
      case 1: return {frame_.hi[0], frame_.lo[1]};
      case 2: return frame_.hi;
      default: return {frame_.lo[0], frame_.hi[1]};
    }
  }

  // The bisectors of the distances farther() compares, tie-break included
  // (so that they agree where two sites nearly tie too).
  std::vector<std::pair<Vec2d, Vec2d>> bisector(const Vec2d& p, const Vec2d& q) const {
    if (metric_ == Metric::l1) return stretched_l1_bisector(p, q, 1 + kTieBreak, far_);
    // L-infinity, turned about p: turning absolute coordinates would round a
    // small offset in y to the resolution of a large x (and the other way).
    auto pieces = stretched_l1_bisector(Vec2d::Zero(), turn(q - p), 1 + 2 * kTieBreak, 2 * far_);
    for (auto& [a, b] : pieces) a = p + unturn(a), b = p + unturn(b);
    return pieces;
  }

  // The distance of x from p as the diagram sees it, minus that from r: > 0
  // where r is nearer, with a tie-breaking term, the main terms' difference
  // taken first (in a tie it is 0, and the tie-break's difference survives
  // the rounding).
  // With the tie-break L1 is the L1 distance with x stretched by
  // 1 + kTieBreak, and L-infinity half the L1 distance of the turned
  // coordinates (x + y, x - y) with x + y stretched by 1 + 2 kTieBreak:
  // bisector() builds theirs.
  double farther(const Vec2d& x, const Vec2d& p, const Vec2d& r) const {
    const Vec2d d = x - p, e = x - r;
    if (metric_ == Metric::l1)
      return (std::abs(d[0]) - std::abs(e[0])) + (std::abs(d[1]) - std::abs(e[1])) +
             kTieBreak * (std::abs(d[0]) - std::abs(e[0]));
    return (std::max(std::abs(d[0]), std::abs(d[1])) - std::max(std::abs(e[0]), std::abs(e[1]))) +
           kTieBreak * (std::abs(d[0] + d[1]) - std::abs(e[0] + e[1]));
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
    for (const Vec2d* s : {&p, &r}) {
      const Vec2d o = *s - piece.a;
      const double crossings[4][2] = {{o[0], d[0]}, {o[1], d[1]}, {o[0] + o[1], d[0] + d[1]}, {o[0] - o[1], d[0] - d[1]}};
      for (const auto& [num, den] : crossings)
        if (den != 0 && num / den > 0 && num / den < 1) ts[count++] = num / den;
    }
    for (std::size_t i = 1; i < count; ++i)  // insertion sort of at most 10 values
      for (std::size_t j = i; j > 0 && ts[j] < ts[j - 1]; --j) std::swap(ts[j], ts[j - 1]);
    Intervals out;
    const auto f = [&](double t) {
      const Vec2d x = piece.a + t * d;
      return farther(x, p, r);
    };
    // |f| within the tie-break and rounding: the piece is on the bisector of
    // p and r there (bisectors under L1 and L-infinity can share lines).
    const auto on_bisector = [&](double t, double ft) {
      const Vec2d x = piece.a + t * d;
      return std::abs(ft) <= 4 * kTieBreak * ((x - p).cwiseAbs().sum() + (x - r).cwiseAbs().sum()) + 0x1p-46 * scale_;
    };
    const auto add = [&](double t0, double t1) { out.add(t0, t1); };
    double f0 = f(ts[0]);
    for (std::size_t k = 0; k + 1 < count; ++k) {
      const double t0 = ts[k], t1 = ts[k + 1];
      if (t1 <= t0) continue;
      const double f1 = f(t1);
      const Vec2d middle = piece.a + (t0 + t1) / 2 * d;
      const double step = probe_step(middle, p, r);
      // (Only along: a short stretch near 0 at both ends crosses a bisector.)
      if (on_bisector(t0, f0) && on_bisector(t1, f1) && (t1 - t0) * d.norm() > 4 * step) {
        if (farther(middle + step * piece.inward, p, r) <= 0) add(t0, t1);
      } else if (f0 <= 0 && f1 <= 0) {
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
  // The points first (finite, within the range where distances stay finite),
  // then the box: a box made around points at 1e308 is infinite.
  detail::check_sites_and_box(points, box, "MetricVoronoi");
  const std::size_t n = points.size();
  if (metric == Metric::l2) {
    // The library's Euclidean diagram: the dual of the Delaunay triangulation,
    // whose exact predicates keep cells of sites 1e-12 apart right, where
    // cutting cells by bisectors in floating point fails near 1e-8.
    const Voronoi2 diagram(points_);
    cells_ = diagram.cell_polygons(box_);
    representative_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      representative_[i] = diagram.representative(i);
      if (representative_[i] == i) max_candidates_ = std::max(max_candidates_, diagram.neighbors(i).size());
    }
    for (std::uint32_t e = 0; e < diagram.edges().size(); ++e) {
      const std::uint32_t a = diagram.edges()[e].site, b = diagram.opposite_site(e);
      if (a > b) continue;  // the twin gives this edge
      if (const auto clipped = diagram.clipped_edge(e, box_); clipped && clipped->first != clipped->second)
        edges_.push_back({a, b, clipped->first, clipped->second});
    }
    return;
  }
  // The frame holds every site strictly inside, so every cell is star-shaped within it.
  AABB2d frame = box;
  for (const Vec2d& p : points) frame.extend(p);
  const double margin = 0.05 * std::max(frame.hi[0] - frame.lo[0], frame.hi[1] - frame.lo[1]);
  frame.lo.array() -= margin;
  frame.hi.array() += margin;
  // The cells are computed relative to `origin`: on each axis the frame's
  // centre where the frame lies far from 0 (else 0). There the subtraction is
  // exact (Sterbenz), and the arithmetic rounds at the frame's size rather than
  // at its distance from 0 (sites 1e-7 apart at 2e7 got cells with spikes).
  Vec2d origin = Vec2d::Zero();
  for (int a = 0; a < 2; ++a) {
    const double centre = frame.lo[a] / 2 + frame.hi[a] / 2;
    if (std::abs(centre) >= 2 * (frame.hi[a] - frame.lo[a])) origin[a] = centre;
  }
  const AABB2d local_frame(frame.lo - origin, frame.hi - origin), local_box(box.lo - origin, box.hi - origin);

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
  for (std::size_t k = 0; k < sites.size(); ++k) site_points[k] = points[sites[k]] - origin;

  const spatial::KdTree<double, 2> tree{spatial::PointView<double>(std::span<const Vec2d>(site_points))};
  // Sites nearer than this are beyond the construction's resolution (a
  // fuzz of lattice subsets: 0 of 150 wrong 3e-7 of the frame apart, up to
  // 6 of 150 from 1e-7 to 1e-8): refused rather than given wrong cells.
  const double resolution = kResolution * std::max(frame.hi[0] - frame.lo[0], frame.hi[1] - frame.lo[1]);
  for (std::size_t k = 0; k < sites.size() && sites.size() > 1; ++k) {
    const auto nearest = tree.query(site_points[k], 2);
    const auto& other = nearest[0].index == k ? nearest[1] : nearest[0];
    if ((site_points[other.index] - site_points[k]).norm() < resolution)
      throw Error("MetricVoronoi: points " + std::to_string(sites[k]) + " and " + std::to_string(sites[other.index]) +
                  " are closer than " + format_number(resolution) + " (1e-6 of the box and points' extent), which " +
                  metric_name(metric) + " cells cannot resolve (l2 can)");
  }
  const CellBuilder builder(site_points, metric, local_frame);

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
    AABB2d bounds = local_frame;
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
    builder.settle(pieces);
    polygon = builder.polygon(p, pieces);
    consulted[s] = active.size();
    site_pieces[s] = std::move(pieces);
    site_cells[s] = clip_polygon_to_box(polygon, local_box);
    for (Vec2d& v : site_cells[s]) v += origin;
  });

  cells_.resize(n);
  for (std::size_t s = 0; s < sites.size(); ++s) {
    max_candidates_ = std::max(max_candidates_, consulted[s]);
    for (const Piece& piece : site_pieces[s]) {
      if (piece.neighbor == kFrameSide || sites[piece.neighbor] < sites[s]) continue;
      if (const auto clipped = clip_segment_to_box(piece.a, piece.b, local_box); clipped && clipped->first != clipped->second)
        edges_.push_back({sites[s], sites[piece.neighbor], clipped->first + origin, clipped->second + origin});
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
  // Vertices are rounded to their coordinates' precision: by up to u |v|.
  constexpr double u = std::numeric_limits<double>::epsilon() / 2;
  const auto reach = [](std::initializer_list<Vec2d> vs) {
    double r = 0;
    for (const Vec2d& v : vs) r = std::max(r, v.cwiseAbs().maxCoeff());
    return r;
  };
  // Under L1 and L-infinity the tie-break moves a boundary by up to 1e-9 of
  // its distance to the sites, and neighbours may round it either way.
  const double tie_break = metric_ == Metric::l2 ? 0.0 : 4 * kTieBreak;
  double covered = 0, slack = 0;  // the distinct sites' cells tile the box
  for (std::uint32_t i = 0; i < cells_.size(); ++i) {
    const std::vector<Vec2d>& cell = cells_[i];
    if (cell.empty()) continue;
    // A cell thinner than that resolution may round to zero area, not below.
    double perimeter = 0, far = 0, from_site = 0;
    for (std::size_t k = 0; k < cell.size(); ++k) {
      perimeter += (cell[(k + 1) % cell.size()] - cell[k]).norm();
      far = std::max(far, reach({cell[k]}));
      from_site = std::max(from_site, metric_distance(metric_, cell[k], points_[i]));
    }
    const double area = polygon_area(cell);
    if (area <= -4 * u * far * perimeter)
      throw Error("MetricVoronoi::validate: cell " + std::to_string(i) + " is not counter-clockwise");
    for (const Vec2d& v : cell)
      if (!grown.contains(v)) throw Error("MetricVoronoi::validate: cell " + std::to_string(i) + " leaves the box");
    if (representative_[i] != i) continue;
    covered += area, slack += (4 * u * far + tie_break * from_site) * perimeter;
    // A site strictly inside the box lies inside its cell (its boundary is
    // about half the distance to the nearest other site away), or within the
    // rounding of the cell's corners: cells of sites an ulp apart are an ulp wide.
    const Vec2d& p = points_[i];
    if (!(p.array() > box_.lo.array()).all() || !(p.array() < box_.hi.array()).all() || point_in_polygon(p, cell))
      continue;
    double gap = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < cell.size(); ++k)
      gap = std::min(gap, point_segment_distance(p, cell[k], cell[(k + 1) % cell.size()]));
    if (!(gap <= 8 * u * std::max(far, reach({p}))))
      throw Error("MetricVoronoi::validate: site " + std::to_string(i) + " is not inside its cell");
  }
  const double box_area = (box_.hi[0] - box_.lo[0]) * (box_.hi[1] - box_.lo[1]);
  if (std::abs(covered - box_area) > 1e-9 * box_area + slack)
    throw Error("MetricVoronoi::validate: the cells cover " + format_number(covered) + " of the box's area " +
                format_number(box_area));
  for (const Edge& e : edges_)
    for (const Vec2d& x : {e.p0, e.p1}) {
      const double da = metric_distance(metric_, x, points_[e.a]), db = metric_distance(metric_, x, points_[e.b]);
      if (std::abs(da - db) > 1e-6 * (da + db) + 1e-12 * scale + 8 * u * reach({x, points_[e.a], points_[e.b]}))
        throw Error("MetricVoronoi::validate: an edge of sites " + std::to_string(e.a) + " and " + std::to_string(e.b) +
                    " is not on their bisector");
    }
}

}  // namespace geods::voronoi
