// Segment insertion by cavity retriangulation, and the marks kept through splits and flips.
#include "constrained_delaunay.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <utility>

#include "geods/core/error.hpp"

namespace geods::voronoi {
namespace {
constexpr std::uint32_t kNone = DelaunayCore::none;
constexpr std::uint32_t kGhost = DelaunayCore::ghost;
constexpr auto next = DelaunayCore::next;
constexpr auto prev = DelaunayCore::prev;
}  // namespace

void ConstrainedDelaunay::grow() {
  if (marks_->size() < core_->vert.size()) marks_->resize(core_->vert.size(), 0);
}

void ConstrainedDelaunay::mark(std::uint32_t e) { (*marks_)[e] = (*marks_)[core_->twin[e]] = 1; }

void ConstrainedDelaunay::note_vertex_edges(std::initializer_list<std::uint32_t> half_edges) {
  for (std::uint32_t h : half_edges)
    if (core_->vert[h] != kGhost) core_->vertex_edge[core_->vert[h]] = h;
}

void ConstrainedDelaunay::split_triangle(std::uint32_t t, std::uint32_t t1, std::uint32_t t2) {
  grow();
  auto& fixed = *marks_;
  const auto& twin = core_->twin;
  const std::uint32_t s0 = 3 * t, s1 = s0 + 1, s2 = s0 + 2, u0 = 3 * t1, w0 = 3 * t2;
  fixed[u0] = fixed[twin[u0]], fixed[w0] = fixed[twin[w0]];
  for (std::uint32_t h : {s1, s2, u0 + 1, u0 + 2, w0 + 1, w0 + 2}) fixed[h] = 0;
  note_vertex_edges({s0, s1, s2, u0, u0 + 1, u0 + 2, w0, w0 + 1, w0 + 2});
}

void ConstrainedDelaunay::split_edge(std::uint32_t e, std::uint32_t t, std::uint32_t n1t, std::uint32_t n2t) {
  grow();
  auto& fixed = *marks_;
  const auto& twin = core_->twin;
  const std::uint32_t e1 = next(e), e2 = prev(e), t1 = next(t), t2 = prev(t), n0 = 3 * n1t, m0 = 3 * n2t;
  // The two halves of a constrained edge stay constrained.
  const std::uint8_t halves = fixed[e];
  fixed[m0] = fixed[n0] = fixed[t] = halves;
  fixed[n0 + 1] = fixed[twin[n0 + 1]], fixed[m0 + 1] = fixed[twin[m0 + 1]];
  for (std::uint32_t h : {e1, n0 + 2, t1, m0 + 2}) fixed[h] = 0;
  note_vertex_edges({e, e1, e2, n0, n0 + 1, n0 + 2, t, t1, t2, m0, m0 + 1, m0 + 2});
}

void ConstrainedDelaunay::flip(std::uint32_t e, std::uint32_t f) {
  auto& fixed = *marks_;
  const auto& twin = core_->twin;
  fixed[e] = fixed[twin[e]], fixed[f] = fixed[twin[f]];
  fixed[next(e)] = fixed[next(f)] = 0;
  note_vertex_edges({e, next(e), f, next(f)});
}

std::optional<ConstrainedDelaunay::Crossing> ConstrainedDelaunay::insert_segment(std::uint32_t a, std::uint32_t b,
                                                                                 Pending& pending) {
  const DelaunayCore& core = *core_;
  const auto& vert = core.vert;
  const auto& twin = core.twin;
  const Vec2d pa = core.at(a), pb = core.at(b);
  // The triangle at a that the segment leaves a through (b lies strictly inside
  // its angle), or an edge or vertex on the segment.
  const std::uint32_t start = core.vertex_edge[a];
  std::uint32_t h = start, crossing = kNone;
  do {
    const std::uint32_t u = vert[next(h)], w = vert[prev(h)];
    if (u == b) {
      mark(h);
      return std::nullopt;
    }
    if (u != kGhost && orient2d(pa, pb, core.at(u)) == 0 && DelaunayCore::strictly_between(pa, pb, core.at(u))) {
      mark(h);  // a vertex on the segment splits it
      pending.push_back({u, b});
      return std::nullopt;
    }
    if (u != kGhost && w != kGhost && orient2d(pa, core.at(u), pb) > 0 && orient2d(pa, core.at(w), pb) < 0) {
      crossing = next(h);
      break;
    }
    h = twin[prev(h)];
  } while (h != start);
  if (crossing == kNone) throw Error("Delaunay2: internal error, segment leaves no triangle");

  // Walk along the segment, collecting the edges and triangles it crosses and
  // the vertices left and right of it.
  std::vector<std::uint32_t> crossed, cavity{crossing / 3}, left{vert[next(crossing)]}, right{vert[crossing]};
  for (;;) {
    if ((*marks_)[crossing]) return split_crossing(a, b, crossing);
    crossed.push_back(crossing);
    const std::uint32_t t = twin[crossing], x = vert[prev(t)];
    cavity.push_back(t / 3);
    if (x == b) break;
    const double side = orient2d(pa, pb, core.at(x));
    if (side == 0) {  // a vertex on the segment: two segments
      pending.push_back({x, b});
      pending.push_back({a, x});
      return std::nullopt;
    }
    if (side > 0) {
      crossing = next(t);
      left.push_back(x);
    } else {
      crossing = prev(t);
      right.push_back(x);
    }
  }
  // A vertex twice in a chain: the crossed triangles surround a vertex of that
  // side (all of its triangles are crossed), which the chains cannot describe
  // (the edges to it, constrained ones too, would be lost). Flips then.
  const auto repeats = [](std::vector<std::uint32_t> chain) {
    std::sort(chain.begin(), chain.end());
    return std::adjacent_find(chain.begin(), chain.end()) != chain.end();
  };
  if (repeats(left) || repeats(right)) {
    flip_in(a, b, crossed);
    return std::nullopt;
  }
  fill_cavity(a, b, std::move(cavity), std::move(left), std::move(right));
  return std::nullopt;
}

std::uint32_t ConstrainedDelaunay::find_edge(std::uint32_t u, std::uint32_t w) const {
  const std::uint32_t start = core_->vertex_edge[u];
  std::uint32_t h = start;
  do {
    if (core_->vert[next(h)] == w) return h;
    h = core_->twin[prev(h)];
  } while (h != start);
  return kNone;
}

void ConstrainedDelaunay::flip_in(std::uint32_t a, std::uint32_t b, const std::vector<std::uint32_t>& crossed) {
  // Sloan's recovery: flip each edge crossing a-b whose two triangles form a
  // strictly convex quadrilateral (one always does), until none crosses; then
  // Lawson's flips make the new edges Delaunay again, a-b held fixed.
  DelaunayCore& core = *core_;
  const Vec2d pa = core.at(a), pb = core.at(b);
  // Vertices u and w strictly on either side of the line pq. (Signs, not their
  // product: at 1e-300 the product of two orientations underflows to zero.)
  const auto apart = [&](const Vec2d& p, const Vec2d& q, std::uint32_t u, std::uint32_t w) {
    const double su = orient2d(p, q, core.at(u)), sw = orient2d(p, q, core.at(w));
    return (su > 0 && sw < 0) || (su < 0 && sw > 0);
  };
  const auto crosses = [&](std::uint32_t u, std::uint32_t w) {
    return u != a && u != b && w != a && w != b && apart(pa, pb, u, w) && apart(core.at(u), core.at(w), a, b);
  };
  std::deque<std::pair<std::uint32_t, std::uint32_t>> queue;
  for (std::uint32_t h : crossed) queue.push_back({core.vert[h], core.vert[next(h)]});
  std::vector<std::pair<std::uint32_t, std::uint32_t>> created;
  for (std::size_t stalled = 0; !queue.empty();) {
    const auto [u, w] = queue.front();
    queue.pop_front();
    const std::uint32_t e = find_edge(u, w);
    if (e == kNone) throw Error("Delaunay2: internal error, a crossed edge vanished");
    const std::uint32_t p = core.vert[prev(e)], x = core.vert[prev(core.twin[e])];
    if (!apart(core.at(p), core.at(x), u, w)) {  // not strictly convex: later
      if (++stalled > queue.size()) throw Error("Delaunay2: internal error, segment recovery by flips stalled");
      queue.push_back({u, w});
      continue;
    }
    stalled = 0;
    core.flip(e, *this);
    if (crosses(p, x))
      queue.push_back({p, x});
    else
      created.push_back({p, x});
  }
  const std::uint32_t segment = find_edge(a, b);
  if (segment == kNone) throw Error("Delaunay2: internal error, segment not recovered by flips");
  mark(segment);
  for (const auto& [u, w] : created)
    if (const std::uint32_t h = find_edge(u, w); h != kNone) core.restore_delaunay(h, *this);
}

void ConstrainedDelaunay::fill_cavity(std::uint32_t a, std::uint32_t b, std::vector<std::uint32_t> cavity,
                                      std::vector<std::uint32_t> left, std::vector<std::uint32_t> right) {
  DelaunayCore& core = *core_;
  auto& fixed = *marks_;
  // Remember the edges around the cavity, free its triangles, fill each side
  // with its constrained Delaunay triangulation.
  std::sort(cavity.begin(), cavity.end());
  std::vector<std::pair<std::uint64_t, std::uint32_t>> outer, open;
  std::uint32_t segment_edge = kNone;
  const auto key = [](std::uint32_t from, std::uint32_t to) { return (std::uint64_t(from) << 32) | to; };
  for (std::uint32_t t : cavity)
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e)
      if (!std::binary_search(cavity.begin(), cavity.end(), core.twin[e] / 3))
        outer.push_back({key(core.vert[e], core.vert[next(e)]), core.twin[e]});
  for (std::uint32_t t : cavity) core.free_triangle(t);
  const auto emit = [&](std::uint32_t p, std::uint32_t q, std::uint32_t r) {
    const std::uint32_t t = core.new_triangle(p, q, r);
    grow();
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t from = core.vert[e], to = core.vert[next(e)];
      fixed[e] = 0;
      const auto is_outer = std::find_if(outer.begin(), outer.end(), [&](const auto& o) { return o.first == key(from, to); });
      if (is_outer != outer.end()) {
        core.link(e, is_outer->second);
        fixed[e] = fixed[is_outer->second];
        continue;
      }
      const auto is_open = std::find_if(open.begin(), open.end(), [&](const auto& o) { return o.first == key(to, from); });
      if (is_open != open.end()) {
        core.link(e, is_open->second);
        open.erase(is_open);
        if ((from == a && to == b) || (from == b && to == a)) segment_edge = e;
      } else {
        open.push_back({key(from, to), e});
      }
    }
    note_vertex_edges({3 * t, 3 * t + 1, 3 * t + 2});
    core.last_triangle = t;
  };
  // Polygon p, q, chain... counter-clockwise: the triangle (p, q, c) with the
  // chain vertex c whose circle holds no other, then the two sub-polygons.
  struct Polygon {
    std::uint32_t p, q;
    std::vector<std::uint32_t> chain;
  };
  std::reverse(left.begin(), left.end());
  std::vector<Polygon> stack;
  stack.push_back({a, b, std::move(left)});
  stack.push_back({b, a, std::move(right)});
  while (!stack.empty()) {
    Polygon poly = std::move(stack.back());
    stack.pop_back();
    if (poly.chain.empty()) continue;
    std::size_t c = 0;
    for (std::size_t d = 1; d < poly.chain.size(); ++d)
      if (incircle(core.at(poly.p), core.at(poly.q), core.at(poly.chain[c]), core.at(poly.chain[d])) > 0) c = d;
    const std::uint32_t vc = poly.chain[c];
    emit(poly.p, poly.q, vc);
    stack.push_back({vc, poly.q, std::vector<std::uint32_t>(poly.chain.begin(), poly.chain.begin() + std::ptrdiff_t(c))});
    stack.push_back({poly.p, vc, std::vector<std::uint32_t>(poly.chain.begin() + std::ptrdiff_t(c) + 1, poly.chain.end())});
  }
  if (!open.empty() || segment_edge == kNone) throw Error("Delaunay2: internal error, cavity not closed");
  mark(segment_edge);
}

ConstrainedDelaunay::Crossing ConstrainedDelaunay::split_crossing(std::uint32_t a, std::uint32_t b,
                                                                  std::uint32_t crossing) {
  // Segment a-b crosses the constrained edge u-w at x (rounded into the edge's box).
  const DelaunayCore& core = *core_;
  const std::uint32_t u = core.vert[crossing], w = core.vert[next(crossing)];
  // The determinants are quadratic in the coordinates: they are computed on the
  // four points scaled by one power of two (exact) to a largest coordinate near
  // 1, so that they neither overflow (1e300) nor underflow (1e-300).
  const Vec2d &pu = core.at(u), &pw = core.at(w);
  double largest = 0;
  for (const Vec2d& p : {core.at(a), core.at(b), pu, pw}) largest = std::max(largest, p.cwiseAbs().maxCoeff());
  int exponent = 0;
  std::frexp(largest, &exponent);
  const Vec2d sa = DelaunayCore::scaled(core.at(a), -exponent), sb = DelaunayCore::scaled(core.at(b), -exponent);
  const Vec2d su = DelaunayCore::scaled(pu, -exponent), sw = DelaunayCore::scaled(pw, -exponent);
  const double du = orient2d(sa, sb, su), dw = orient2d(sa, sb, sw);
  Vec2d x = DelaunayCore::scaled((su * dw - sw * du) / (dw - du), exponent);
  for (int k = 0; k < 2; ++k) x[k] = std::clamp(x[k], std::min(pu[k], pw[k]), std::max(pu[k], pw[k]));
  // The edge, no longer fixed, is made Delaunay at once: x, rounded, may fall
  // outside its two triangles (beside a sliver along it), and inserting x would
  // then leave the edge in place, not Delaunay.
  (*marks_)[crossing] = (*marks_)[core.twin[crossing]] = 0;
  core_->restore_delaunay(crossing, *this);
  return {crossing, u, w, x};
}

}  // namespace geods::voronoi
