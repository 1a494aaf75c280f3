// Incremental Delaunay triangulation with Lawson flips over a triangulation
// closed by a ghost vertex (see delaunay2.hpp).
#include "geods/voronoi/delaunay2.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/predicates.hpp"
#include "geods/core/rng.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = Delaunay2::no_edge;

void require_finite(const Vec2d& p, std::size_t i, const char* who) {
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]))
    throw Error(std::string(who) + ": point " + std::to_string(i) + " has a NaN or infinite coordinate");
}

std::uint32_t interleave_bits(std::uint32_t x) {
  x = (x | (x << 8)) & 0x00FF00FF;
  x = (x | (x << 4)) & 0x0F0F0F0F;
  x = (x | (x << 2)) & 0x33333333;
  x = (x | (x << 1)) & 0x55555555;
  return x;
}

// Index of (x, y) along the Hilbert curve of a 2^16 x 2^16 grid, without
// branches: the orientation of each level is a prefix scan over the bits
// (after Fabian Giesen's and rawrunprotected's formulation). Equal to the
// classic loop over the 16 levels.
std::uint32_t hilbert_index(std::uint32_t x, std::uint32_t y) {
  std::uint32_t A, B, C, D;
  {
    const std::uint32_t a = x ^ y, b = 0xFFFF ^ a, c = 0xFFFF ^ (x | y), d = x & (y ^ 0xFFFF);
    A = a | (b >> 1);
    B = (a >> 1) ^ a;
    C = ((c >> 1) ^ (b & (d >> 1))) ^ c;
    D = ((a & (c >> 1)) ^ (d >> 1)) ^ d;
  }
  for (int shift = 2; shift <= 4; shift *= 2) {
    const std::uint32_t a = A, b = B, c = C, d = D;
    A = (a & (a >> shift)) ^ (b & (b >> shift));
    B = (a & (b >> shift)) ^ (b & ((a ^ b) >> shift));
    C ^= (a & (c >> shift)) ^ (b & (d >> shift));
    D ^= (b & (c >> shift)) ^ ((a ^ b) & (d >> shift));
  }
  {
    const std::uint32_t a = A, b = B, c = C, d = D;
    C ^= (a & (c >> 8)) ^ (b & (d >> 8));
    D ^= (b & (c >> 8)) ^ ((a ^ b) & (d >> 8));
  }
  const std::uint32_t a = C ^ (C >> 1), b = D ^ (D >> 1);
  const std::uint32_t i0 = x ^ y, i1 = b | (0xFFFF ^ (i0 | a));
  return (interleave_bits(i1) << 1) | interleave_bits(i0);
}

// Sorts `items` by their bits [first_bit, first_bit + bits), stably (LSD radix sort, 11 bits a pass).
void radix_sort(std::vector<std::uint64_t>& items, int first_bit, int bits) {
  constexpr int kDigit = 11;
  constexpr std::uint64_t kMask = (1u << kDigit) - 1;
  std::vector<std::uint64_t> buffer(items.size());
  std::vector<std::size_t> count(kMask + 2);
  for (int shift = first_bit; shift < first_bit + bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (std::uint64_t item : items) ++count[((item >> shift) & kMask) + 1];
    for (std::size_t i = 0; i <= kMask; ++i) count[i + 1] += count[i];
    for (std::uint64_t item : items) buffer[count[(item >> shift) & kMask]++] = item;
    items.swap(buffer);
  }
}

// p strictly between a and b, for p on the line through a != b.
bool strictly_between(const Vec2d& a, const Vec2d& b, const Vec2d& p) {
  if (a[0] != b[0]) return (a[0] < p[0] && p[0] < b[0]) || (b[0] < p[0] && p[0] < a[0]);
  return (a[1] < p[1] && p[1] < b[1]) || (b[1] < p[1] && p[1] < a[1]);
}

}  // namespace

Delaunay2::Delaunay2(std::span<const Vec2d> points, Options options) { init(points, {}, options); }

Delaunay2::Delaunay2(std::span<const Vec2d> points, std::span<const Segment> segments, Options options) {
  init(points, segments, options);
}

Delaunay2 Delaunay2::from_segment_ends(std::span<const Vec2d> points, std::span<const std::array<Vec2d, 2>> segments,
                                       Options options) {
  std::vector<Vec2d> all(points.begin(), points.end());
  std::vector<Segment> indices;
  for (const auto& [a, b] : segments) {
    indices.push_back({std::uint32_t(all.size()), std::uint32_t(all.size() + 1)});
    all.push_back(a);
    all.push_back(b);
  }
  return Delaunay2(all, indices, options);
}

void Delaunay2::init(std::span<const Vec2d> points, std::span<const Segment> segments, Options options) {
  if (points.size() >= (std::size_t(1) << 30))
    throw Error("Delaunay2: " + std::to_string(points.size()) + " points, at most 2^30 - 1 are supported");
  for (std::size_t i = 0; i < points.size(); ++i) require_finite(points[i], i, "Delaunay2");
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const Segment& s = segments[k];
    if (s[0] >= points.size() || s[1] >= points.size())
      throw Error("Delaunay2: segment " + std::to_string(k) + " refers to point " +
                  std::to_string(std::max(s[0], s[1])) + ", but there are " + std::to_string(points.size()) + " points");
    if (s[0] == s[1])
      throw Error("Delaunay2: segment " + std::to_string(k) + " joins point " + std::to_string(s[0]) + " to itself");
  }
  points_.assign(points.begin(), points.end());
  segments_.assign(segments.begin(), segments.end());
  rep_.resize(points_.size());
  std::iota(rep_.begin(), rep_.end(), 0u);
  options_ = options;
  build(options);
}

// ------------------------------------------------------------------ building

std::vector<std::uint32_t> Delaunay2::insertion_order(std::uint64_t seed) const {
  std::vector<std::uint32_t> active;
  active.reserve(points_.size());
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (rep_[i] != kNone) active.push_back(i);
  const std::size_t n = active.size();
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (std::uint32_t i : active)
    for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], points_[i][a]), hi[a] = std::max(hi[a], points_[i][a]);
  // Halves keep the extent finite for coordinates near the double range.
  double scale[2];
  for (int a = 0; a < 2; ++a) {
    const double extent = hi[a] * 0.5 - lo[a] * 0.5;
    scale[a] = extent > 0 ? 16383.0 / extent : 0.0;
  }
  // BRIO rounds: a point lands in the last round with probability 1/2, the one
  // before with 1/4, ...; odd rounds run the Hilbert curve backwards so that
  // consecutive rounds meet where they end. The key packs round (6 bits),
  // Hilbert index on a 2^14 grid (28 bits) and point index (30 bits).
  const int last_round = int(std::bit_width(n));
  std::vector<std::uint64_t> keys(n);
  Rng rng(seed);
  std::vector<std::uint64_t> random(n);
  for (auto& r : random) r = rng();
  parallel_for(0, n, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Vec2d& p = points_[active[k]];
      const auto cell = [&](int a) {
        const double t = (p[a] * 0.5 - lo[a] * 0.5) * scale[a];
        return std::uint32_t(std::clamp(t, 0.0, 16383.0));
      };
      const int round = std::max(0, last_round - std::countr_zero(random[k] | (std::uint64_t(1) << 63)));
      std::uint32_t h = hilbert_index(cell(0), cell(1));
      if (round % 2) h = ~h & 0xFFFFFFF;
      keys[k] = (std::uint64_t(round) << 58) | (std::uint64_t(h) << 30) | active[k];
    }
  });
  radix_sort(keys, 30, 34);
  std::vector<std::uint32_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = std::uint32_t(keys[k] & 0x3FFFFFFF);
  return order;
}

void Delaunay2::build(Options options) {
  vert_.clear();
  twin_.clear();
  free_triangles_.clear();
  has_constraints_ = false;
  fixed_.clear();
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (rep_[i] != kNone) rep_[i] = i;
  original_of_ = insertion_order(options.seed);
  if (options.location == Delaunay2Location::history_dag) {  // a random order instead: the DAG needs no locality
    Rng rng(options.seed);
    for (std::size_t k = original_of_.size(); k > 1; --k) std::swap(original_of_[k - 1], original_of_[rng.below(k)]);
  }
  const std::uint32_t m = std::uint32_t(original_of_.size());
  coords_.resize(m);
  internal_of_.assign(points_.size(), kNone);
  for (std::uint32_t k = 0; k < m; ++k) {
    coords_[k] = points_[original_of_[k]];
    internal_of_[original_of_[k]] = k;
  }
  if (!make_first_triangle()) {
    build_degenerate();
    return;
  }
  vert_.reserve(6 * std::size_t(m) + 12);
  twin_.reserve(6 * std::size_t(m) + 12);
  const std::uint32_t a = vert_[0], b = vert_[1], c = vert_[2];
  history_center_ = (at(a) + at(b) + at(c)) / 3;
  history_ = options.location == Delaunay2Location::history_dag && orient2d(at(a), at(b), history_center_) > 0 &&
             orient2d(at(b), at(c), history_center_) > 0 && orient2d(at(c), at(a), history_center_) > 0;
  if (history_) {
    history_nodes_.reserve(9 * std::size_t(m) + 4);
    for (std::uint32_t t = 0; t < 4; ++t) add_history_node(t);
  }
  for (std::uint32_t k = 0; k < m; ++k)
    if (k != a && k != b && k != c) insert_vertex(k, history_ ? history_locate(at(k)) : last_triangle_);
  // The DAG serves construction only (updates may shrink the hull, which its cones assume never happens).
  dag_nodes_ = history_nodes_.size();
  history_ = false;
  history_nodes_ = {};
  triangle_node_ = {};
  // A point renamed to an earlier duplicate leaves a chain of representatives.
  for (std::uint32_t i = 0; i < rep_.size(); ++i) {
    std::uint32_t r = rep_[i];
    if (r == kNone) continue;
    while (rep_[r] != r) r = rep_[r];
    rep_[i] = r;
  }
  publish();
  if (!segments_.empty()) insert_constraints();
}

bool Delaunay2::make_first_triangle() {
  const std::uint32_t m = std::uint32_t(coords_.size());
  if (m == 0) return false;
  const std::uint32_t a = 0;
  std::uint32_t b = 1;
  while (b < m && at(b) == at(a)) ++b;
  if (b == m) return false;
  std::uint32_t c = b + 1;
  double side = 0;
  while (c < m && (side = orient2d(at(a), at(b), at(c))) == 0) ++c;
  if (c == m) return false;
  std::uint32_t b2 = b;
  if (side < 0) std::swap(b2, c);
  // The finite triangle (a, b2, c) and a ghost triangle behind each of its edges.
  vert_ = {a, b2, c, b2, a, kGhost, c, b2, kGhost, a, c, kGhost};
  twin_.assign(12, kNone);
  link(0, 3);
  link(1, 6);
  link(2, 9);
  link(4, 11);
  link(7, 5);
  link(10, 8);
  last_triangle_ = 0;
  return true;
}

void Delaunay2::build_degenerate() {
  vert_.clear();
  twin_.clear();
  free_triangles_.clear();
  std::vector<std::uint32_t> active;
  for (std::uint32_t i = 0; i < points_.size(); ++i)
    if (rep_[i] != kNone) active.push_back(i);
  const auto& p = points_;
  std::sort(active.begin(), active.end(), [&](std::uint32_t i, std::uint32_t j) {
    if (p[i][0] != p[j][0]) return p[i][0] < p[j][0];
    if (p[i][1] != p[j][1]) return p[i][1] < p[j][1];
    return i < j;
  });
  hull_.clear();
  for (std::uint32_t i : active) {
    if (!hull_.empty() && p[hull_.back()] == p[i]) {
      rep_[i] = hull_.back();
    } else {
      rep_[i] = i;
      hull_.push_back(i);
    }
  }
  triangles_.clear();
  halfedges_.clear();
  public_triangle_.clear();
  internal_triangle_.clear();
  coords_.clear();
  original_of_.clear();
  internal_of_.clear();
  vertex_edge_.clear();
}

// ------------------------------------------------------------------ insertion

bool Delaunay2::in_conflict(std::uint32_t t, const Vec2d& p) const {
  const std::uint32_t a = vert_[3 * t], b = vert_[3 * t + 1], c = vert_[3 * t + 2];
  if (((a | b | c) & kGhostBit) == 0) [[likely]]
    return incircle(at(a), at(b), at(c), p) > 0;
  // The circle of a ghost triangle (x, y, ghost) is the open half-plane left of
  // x -> y plus the open segment between them.
  const std::uint32_t x = a == kGhost ? b : b == kGhost ? c : a;
  const std::uint32_t y = a == kGhost ? c : b == kGhost ? a : b;
  const double side = orient2d(at(x), at(y), p);
  return side > 0 || (side == 0 && strictly_between(at(x), at(y), p));
}

std::uint32_t Delaunay2::new_triangle() {
  if (!free_triangles_.empty()) {
    const std::uint32_t t = free_triangles_.back();
    free_triangles_.pop_back();
    return t;
  }
  const std::uint32_t t = std::uint32_t(vert_.size() / 3);
  vert_.resize(vert_.size() + 3);
  twin_.resize(twin_.size() + 3);
  if (has_constraints_) fixed_.resize(vert_.size(), 0);
  if (history_) triangle_node_.resize(t + 1, kNone);
  return t;
}

std::uint32_t Delaunay2::finite_triangle_near(std::uint32_t t) const {
  if (!is_ghost_triangle(t)) return t;
  for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e)
    if (vert_[e] != kGhost && vert_[next(e)] != kGhost) return twin_[e] / 3;
  return t;  // not reached in a non-degenerate triangulation
}

Delaunay2::Location Delaunay2::walk(const Vec2d& p, std::uint32_t t, std::size_t* steps) const {
  t = finite_triangle_near(t);
  std::uint32_t from = kNone;  // the half-edge we entered t through: p lies strictly inside it
  std::uint32_t random = 2463534242u;
  std::size_t count = 0;
  for (;;) {
    ++count;
    // A random first edge makes the walk terminate on any triangulation (stochastic walk).
    random ^= random << 13, random ^= random >> 17, random ^= random << 5;
    const std::uint32_t first = random % 3;
    std::uint32_t zero[2], zeros = 0;
    bool moved = false;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t e = 3 * t + (first + k) % 3;
      if (e == from) continue;
      const double side = orient2d(at(vert_[e]), at(vert_[next(e)]), p);
      if (side < 0) {
        const std::uint32_t f = twin_[e];
        if (is_ghost_triangle(f / 3)) {
          if (steps) *steps += count;
          return {Where::outside, f};
        }
        from = f;
        t = f / 3;
        moved = true;
        break;
      }
      if (side == 0) zero[zeros++] = e;
    }
    if (moved) continue;
    if (steps) *steps += count;
    if (zeros == 0) return {Where::inside, 3 * t};
    if (zeros == 1) return {Where::on_edge, zero[0]};
    // p is the vertex shared by the two edges.
    return {Where::on_vertex, next(zero[0]) == zero[1] ? zero[1] : zero[0]};
  }
}

void Delaunay2::insert_vertex(std::uint32_t i, std::uint32_t start) {
  const Location loc = walk(at(i), start, &walk_steps_);
  switch (loc.where) {
    case Where::on_vertex: {
      // The first occurrence stands for all equal points.
      const std::uint32_t j = vert_[loc.edge], point = original_of_[i], existing = original_of_[j];
      if (point < existing) {
        original_of_[j] = point;
        rep_[existing] = point;
        rep_[point] = point;
      } else {
        rep_[point] = existing;
      }
      internal_of_[point] = j;
      last_triangle_ = loc.edge / 3;
      return;
    }
    case Where::on_edge:
      split_edge(loc.edge, i);
      break;
    case Where::inside:
    case Where::outside:
      split_triangle(loc.edge / 3, i);
      break;
  }
  legalize(i);
}

void Delaunay2::split_triangle(std::uint32_t t, std::uint32_t p) {
  const std::uint32_t t1 = new_triangle(), t2 = new_triangle();
  const std::uint32_t s0 = 3 * t, s1 = s0 + 1, s2 = s0 + 2, u0 = 3 * t1, w0 = 3 * t2;
  const std::uint32_t a = vert_[s0], b = vert_[s1], c = vert_[s2];
  const std::uint32_t o1 = twin_[s1], o2 = twin_[s2];
  const std::uint32_t parent = history_ ? triangle_node_[t] : kNone;
  // t = (a, b, p), t1 = (b, c, p), t2 = (c, a, p)
  vert_[s2] = p;
  vert_[u0] = b, vert_[u0 + 1] = c, vert_[u0 + 2] = p;
  vert_[w0] = c, vert_[w0 + 1] = a, vert_[w0 + 2] = p;
  link(u0, o1);
  link(w0, o2);
  link(s1, u0 + 2);
  link(u0 + 1, w0 + 2);
  link(w0 + 1, s2);
  if (has_constraints_) {
    fixed_[u0] = fixed_[o1], fixed_[w0] = fixed_[o2];
    for (std::uint32_t h : {s1, s2, u0 + 1, u0 + 2, w0 + 1, w0 + 2}) fixed_[h] = 0;
    note_vertex_edges({s0, s1, s2, u0, u0 + 1, u0 + 2, w0, w0 + 1, w0 + 2});
  }
  if (history_) {
    const std::uint32_t children[3] = {add_history_node(t), add_history_node(t1), add_history_node(t2)};
    std::copy(children, children + 3, history_nodes_[parent].child);
  }
  flip_stack_.push_back(s0);
  flip_stack_.push_back(u0);
  flip_stack_.push_back(w0);
  last_triangle_ = t;
}

void Delaunay2::split_edge(std::uint32_t e, std::uint32_t p) {
  const std::uint32_t n1t = new_triangle(), n2t = new_triangle();
  const std::uint32_t e1 = next(e), e2 = prev(e);
  const std::uint32_t t = twin_[e], t1 = next(t), t2 = prev(t);
  const std::uint32_t a = vert_[e], b = vert_[e1], c = vert_[e2], d = vert_[t2];
  const std::uint32_t o_e1 = twin_[e1], o_t1 = twin_[t1];
  const std::uint32_t n0 = 3 * n1t, m0 = 3 * n2t;
  const std::uint32_t parent_e = history_ ? triangle_node_[e / 3] : kNone, parent_t = history_ ? triangle_node_[t / 3] : kNone;
  // (a, b, c) -> (a, p, c) + (p, b, c); (b, a, d) -> (b, p, d) + (p, a, d)
  vert_[e1] = p;
  vert_[t1] = p;
  vert_[n0] = p, vert_[n0 + 1] = b, vert_[n0 + 2] = c;
  vert_[m0] = p, vert_[m0 + 1] = a, vert_[m0 + 2] = d;
  link(e, m0);
  link(n0, t);
  link(e1, n0 + 2);
  link(t1, m0 + 2);
  link(n0 + 1, o_e1);
  link(m0 + 1, o_t1);
  if (has_constraints_) {  // the two halves of a constrained edge stay constrained
    const std::uint8_t halves = fixed_[e];
    fixed_[m0] = fixed_[n0] = fixed_[t] = halves;
    fixed_[n0 + 1] = fixed_[o_e1], fixed_[m0 + 1] = fixed_[o_t1];
    for (std::uint32_t h : {e1, n0 + 2, t1, m0 + 2}) fixed_[h] = 0;
    note_vertex_edges({e, e1, e2, n0, n0 + 1, n0 + 2, t, t1, t2, m0, m0 + 1, m0 + 2});
  }
  if (history_) {
    const std::uint32_t c0 = add_history_node(e / 3), c1 = add_history_node(n1t);
    history_nodes_[parent_e].child[0] = c0, history_nodes_[parent_e].child[1] = c1;
    const std::uint32_t c2 = add_history_node(t / 3), c3 = add_history_node(n2t);
    history_nodes_[parent_t].child[0] = c2, history_nodes_[parent_t].child[1] = c3;
  }
  flip_stack_.push_back(e2);
  flip_stack_.push_back(n0 + 1);
  flip_stack_.push_back(t2);
  flip_stack_.push_back(m0 + 1);
  last_triangle_ = e / 3;
}

void Delaunay2::flip(std::uint32_t e) {
  // e = u -> w in (u, w, p), f = w -> u in (w, u, x)  ==>  (u, x, p) and (w, p, x)
  const std::uint32_t e1 = next(e), f = twin_[e], f1 = next(f), f2 = prev(f);
  const std::uint32_t outer_e1 = twin_[e1], outer_f1 = twin_[f1];
  const std::uint32_t p = vert_[prev(e)], x = vert_[f2];
  const std::uint32_t parent_e = history_ ? triangle_node_[e / 3] : kNone, parent_f = history_ ? triangle_node_[f / 3] : kNone;
  vert_[e1] = x;
  vert_[f1] = p;
  if (history_) {
    const std::uint32_t c0 = add_history_node(e / 3), c1 = add_history_node(f / 3);
    for (std::uint32_t parent : {parent_e, parent_f})
      history_nodes_[parent].child[0] = c0, history_nodes_[parent].child[1] = c1;
  }
  link(e, outer_f1);
  link(f, outer_e1);
  link(e1, f1);
  if (has_constraints_) {
    fixed_[e] = fixed_[outer_f1], fixed_[f] = fixed_[outer_e1];
    fixed_[e1] = fixed_[f1] = 0;
    note_vertex_edges({e, e1, f, f1});
  }
  ++flips_;
}

void Delaunay2::legalize(std::uint32_t p) {
  const Vec2d point = at(p);
  while (!flip_stack_.empty()) {
    const std::uint32_t e = flip_stack_.back();  // opposite p in its triangle
    flip_stack_.pop_back();
    const std::uint32_t f = twin_[e];
    if ((has_constraints_ && fixed_[e]) || !in_conflict(f / 3, point)) continue;
    const std::uint32_t f2 = prev(f);
    flip(e);
    flip_stack_.push_back(e);
    flip_stack_.push_back(f2);
  }
}

// ------------------------------------------------------------------ history DAG

std::uint32_t Delaunay2::add_history_node(std::uint32_t t) {
  const std::uint32_t id = std::uint32_t(history_nodes_.size());
  history_nodes_.push_back({{vert_[3 * t], vert_[3 * t + 1], vert_[3 * t + 2]}, {kNone, kNone, kNone}, t});
  if (triangle_node_.size() <= t) triangle_node_.resize(t + 1, kNone);
  triangle_node_[t] = id;
  return id;
}

bool Delaunay2::history_contains(std::uint32_t node, const Vec2d& q) const {
  const std::uint32_t* v = history_nodes_[node].vertex;
  if (((v[0] | v[1] | v[2]) & kGhostBit) == 0)
    return orient2d(at(v[0]), at(v[1]), q) >= 0 && orient2d(at(v[1]), at(v[2]), q) >= 0 &&
           orient2d(at(v[2]), at(v[0]), q) >= 0;
  // Ghost triangle (x, y, ghost), hull edge y -> x: the part of the cone from
  // the centre between the rays through y and x that lies beyond the edge.
  const int g = v[0] == kGhost ? 0 : v[1] == kGhost ? 1 : 2;
  const Vec2d &x = at(v[(g + 1) % 3]), &y = at(v[(g + 2) % 3]);
  return orient2d(x, y, q) >= 0 && orient2d(history_center_, y, q) >= 0 && orient2d(history_center_, x, q) <= 0;
}

std::uint32_t Delaunay2::history_locate(const Vec2d& q) const {
  std::uint32_t node = kNone;
  for (std::uint32_t root = 0; root < 4 && node == kNone; ++root)
    if (history_contains(root, q)) node = root;
  if (node == kNone) return last_triangle_;
  for (;;) {
    const HistoryNode& h = history_nodes_[node];
    if (h.child[0] == kNone) return h.triangle;  // a leaf: the walk finishes from here in O(1)
    std::uint32_t next_node = kNone;
    for (std::uint32_t c : h.child)
      if (c != kNone && history_contains(c, q)) {
        next_node = c;
        break;
      }
    if (next_node == kNone) return last_triangle_;  // not reached: the children cover their parent
    node = next_node;
  }
}

// ------------------------------------------------------------------ constraints

void Delaunay2::note_vertex_edges(std::initializer_list<std::uint32_t> half_edges) {
  for (std::uint32_t h : half_edges)
    if (vert_[h] != kGhost) vertex_edge_[vert_[h]] = h;
}

void Delaunay2::insert_constraints() {
  has_constraints_ = true;
  fixed_.assign(vert_.size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pending;
  for (auto it = segments_.rbegin(); it != segments_.rend(); ++it)
    pending.push_back({internal_of_[rep_[(*it)[0]]], internal_of_[rep_[(*it)[1]]]});
  while (!pending.empty()) {
    const auto [a, b] = pending.back();
    pending.pop_back();
    if (a != b) insert_segment(a, b, pending);
  }
  publish();
}

void Delaunay2::mark_fixed(std::uint32_t e) {
  fixed_[e] = fixed_[twin_[e]] = 1;
}

void Delaunay2::insert_segment(std::uint32_t a, std::uint32_t b,
                               std::vector<std::pair<std::uint32_t, std::uint32_t>>& pending) {
  const Vec2d pa = at(a), pb = at(b);
  // The triangle at a that the segment leaves a through (b lies strictly inside
  // its angle), or an edge or vertex on the segment.
  const std::uint32_t start = vertex_edge_[a];
  std::uint32_t h = start, crossing = kNone;
  do {
    const std::uint32_t u = vert_[next(h)], w = vert_[prev(h)];
    if (u == b) {
      mark_fixed(h);
      return;
    }
    if (u != kGhost && orient2d(pa, pb, at(u)) == 0 && strictly_between(pa, pb, at(u))) {
      mark_fixed(h);  // a vertex on the segment splits it
      pending.push_back({u, b});
      return;
    }
    if (u != kGhost && w != kGhost && orient2d(pa, at(u), pb) > 0 && orient2d(pa, at(w), pb) < 0) {
      crossing = next(h);
      break;
    }
    h = twin_[prev(h)];
  } while (h != start);
  if (crossing == kNone) throw Error("Delaunay2: internal error, segment leaves no triangle");

  // Walk along the segment, collecting the triangles it crosses and the
  // vertices left and right of it.
  std::vector<std::uint32_t> cavity{crossing / 3}, left{vert_[next(crossing)]}, right{vert_[crossing]};
  for (;;) {
    if (fixed_[crossing]) {
      split_crossing(a, b, crossing, pending);
      return;
    }
    const std::uint32_t t = twin_[crossing], x = vert_[prev(t)];
    cavity.push_back(t / 3);
    if (x == b) break;
    const double side = orient2d(pa, pb, at(x));
    if (side == 0) {  // a vertex on the segment: two segments
      pending.push_back({x, b});
      pending.push_back({a, x});
      return;
    }
    if (side > 0) {
      crossing = next(t);
      left.push_back(x);
    } else {
      crossing = prev(t);
      right.push_back(x);
    }
  }

  // Remember the edges around the cavity, free its triangles, fill each side
  // with its constrained Delaunay triangulation (Anglada's algorithm).
  std::sort(cavity.begin(), cavity.end());
  std::vector<std::pair<std::uint64_t, std::uint32_t>> outer, open;
  std::uint32_t segment_edge = kNone;
  const auto key = [](std::uint32_t from, std::uint32_t to) { return (std::uint64_t(from) << 32) | to; };
  for (std::uint32_t t : cavity)
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e)
      if (!std::binary_search(cavity.begin(), cavity.end(), twin_[e] / 3))
        outer.push_back({key(vert_[e], vert_[next(e)]), twin_[e]});
  for (std::uint32_t t : cavity) {
    vert_[3 * t] = vert_[3 * t + 1] = vert_[3 * t + 2] = kNone;
    free_triangles_.push_back(t);
  }
  const auto emit = [&](std::uint32_t p, std::uint32_t q, std::uint32_t r) {
    const std::uint32_t t = new_triangle();
    vert_[3 * t] = p, vert_[3 * t + 1] = q, vert_[3 * t + 2] = r;
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t from = vert_[e], to = vert_[next(e)];
      fixed_[e] = 0;
      const auto is_outer = std::find_if(outer.begin(), outer.end(), [&](const auto& o) { return o.first == key(from, to); });
      if (is_outer != outer.end()) {
        link(e, is_outer->second);
        fixed_[e] = fixed_[is_outer->second];
        continue;
      }
      const auto is_open = std::find_if(open.begin(), open.end(), [&](const auto& o) { return o.first == key(to, from); });
      if (is_open != open.end()) {
        link(e, is_open->second);
        open.erase(is_open);
        if ((from == a && to == b) || (from == b && to == a)) segment_edge = e;
      } else {
        open.push_back({key(from, to), e});
      }
    }
    note_vertex_edges({3 * t, 3 * t + 1, 3 * t + 2});
    last_triangle_ = t;
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
      if (incircle(at(poly.p), at(poly.q), at(poly.chain[c]), at(poly.chain[d])) > 0) c = d;
    const std::uint32_t vc = poly.chain[c];
    emit(poly.p, poly.q, vc);
    stack.push_back({vc, poly.q, std::vector<std::uint32_t>(poly.chain.begin(), poly.chain.begin() + std::ptrdiff_t(c))});
    stack.push_back({poly.p, vc, std::vector<std::uint32_t>(poly.chain.begin() + std::ptrdiff_t(c) + 1, poly.chain.end())});
  }
  if (!open.empty() || segment_edge == kNone) throw Error("Delaunay2: internal error, cavity not closed");
  mark_fixed(segment_edge);
}

void Delaunay2::split_crossing(std::uint32_t a, std::uint32_t b, std::uint32_t crossing,
                               std::vector<std::pair<std::uint32_t, std::uint32_t>>& pending) {
  // Segment a-b crosses the constrained edge u-w: both are split at their
  // intersection point, a new vertex (rounded to doubles; the four pieces are
  // then inserted as segments of their own).
  const std::uint32_t u = vert_[crossing], w = vert_[next(crossing)];
  const Vec2d &pu = at(u), &pw = at(w);
  const double du = orient2d(at(a), at(b), pu), dw = orient2d(at(a), at(b), pw);
  Vec2d x = (pu * dw - pw * du) / (dw - du);
  for (int k = 0; k < 2; ++k) x[k] = std::clamp(x[k], std::min(pu[k], pw[k]), std::max(pu[k], pw[k]));
  fixed_[crossing] = fixed_[twin_[crossing]] = 0;
  const std::uint32_t i = std::uint32_t(points_.size());
  if (i + 1 >= (std::uint32_t(1) << 30)) throw Error("Delaunay2: too many points");
  points_.push_back(x);
  rep_.push_back(i);
  const std::uint32_t k = std::uint32_t(coords_.size());
  coords_.push_back(x);
  original_of_.push_back(i);
  internal_of_.push_back(k);
  vertex_edge_.push_back(kNone);
  insert_vertex(k, crossing / 3);
  intersections_.push_back(i);
  const std::uint32_t vx = internal_of_[i];
  for (auto piece : {std::pair{u, vx}, std::pair{vx, w}, std::pair{vx, b}, std::pair{a, vx}}) pending.push_back(piece);
}

// ------------------------------------------------------------------ public view

void Delaunay2::publish() {
  const std::uint32_t internal = std::uint32_t(vert_.size() / 3);
  public_triangle_.assign(internal, kNone);
  internal_triangle_.clear();
  for (std::uint32_t t = 0; t < internal; ++t) {
    if (vert_[3 * t] == kNone || is_ghost_triangle(t)) continue;
    public_triangle_[t] = std::uint32_t(internal_triangle_.size());
    internal_triangle_.push_back(t);
  }
  const std::size_t m = internal_triangle_.size();
  triangles_.resize(3 * m);
  halfedges_.resize(3 * m);
  for (std::size_t k = 0; k < m; ++k) {
    const std::uint32_t t = internal_triangle_[k];
    for (std::uint32_t s = 0; s < 3; ++s) {
      triangles_[3 * k + s] = original_of_[vert_[3 * t + s]];
      const std::uint32_t f = twin_[3 * t + s], other = public_triangle_[f / 3];
      halfedges_[3 * k + s] = other == kNone ? kNone : 3 * other + f % 3;
    }
  }
  constrained_.assign(has_constraints_ ? 3 * m : 0, 0);
  if (has_constraints_)
    for (std::size_t k = 0; k < m; ++k)
      for (std::uint32_t s = 0; s < 3; ++s) constrained_[3 * k + s] = fixed_[3 * internal_triangle_[k] + s];
  vertex_edge_.assign(coords_.size(), kNone);
  for (std::uint32_t h = 0; h < vert_.size(); ++h)
    if (vert_[h] != kGhost && vert_[h] != kNone) vertex_edge_[vert_[h]] = h;
  hull_.clear();
  if (m == 0) return;
  // Walk the ghost triangles (x, y, ghost) around the hull: the hull edge of
  // each is y -> x, and the next one shares x.
  std::uint32_t start = kNone;
  for (std::uint32_t h = 0; h < vert_.size() && start == kNone; ++h)
    if (vert_[h] == kGhost) start = h;
  std::uint32_t g = start;
  do {
    hull_.push_back(original_of_[vert_[prev(g)]]);
    g = next(twin_[g]);  // x -> ghost, then ghost -> z in the next ghost triangle
    if (hull_.size() > points_.size()) throw Error("Delaunay2: corrupt hull");
  } while (g != start);
}

// ------------------------------------------------------------------ queries

std::uint32_t Delaunay2::representative(std::uint32_t i) const {
  if (i >= rep_.size()) throw Error("Delaunay2::representative: point " + std::to_string(i) + " does not exist");
  return rep_[i];
}

std::size_t Delaunay2::duplicate_count() const {
  std::size_t count = 0;
  for (std::uint32_t i = 0; i < rep_.size(); ++i) count += rep_[i] != kNone && rep_[i] != i;
  return count;
}

std::uint32_t Delaunay2::locate(const Vec2d& q, std::uint32_t hint) const {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) throw Error("Delaunay2::locate: query is not finite");
  if (internal_triangle_.empty()) return kNone;
  if (hint != kNone && hint >= internal_triangle_.size())
    throw Error("Delaunay2::locate: hint " + std::to_string(hint) + " is not a triangle");
  const std::uint32_t start = internal_triangle_[hint != kNone ? hint : internal_triangle_.size() / 2];
  const Location loc = walk(q, start, nullptr);
  return loc.where == Where::outside ? kNone : public_triangle_[loc.edge / 3];
}

std::vector<std::uint32_t> Delaunay2::neighbors(std::uint32_t v) const {
  if (v >= points_.size()) throw Error("Delaunay2::neighbors: point " + std::to_string(v) + " does not exist");
  std::vector<std::uint32_t> result;
  if (internal_triangle_.empty()) {  // the sorted points of a degenerate set form a path
    const auto it = std::find(hull_.begin(), hull_.end(), v);
    if (it != hull_.end()) {
      if (it != hull_.begin()) result.push_back(*(it - 1));
      if (it + 1 != hull_.end()) result.push_back(*(it + 1));
    }
    return result;
  }
  if (rep_[v] != v) return result;
  const std::uint32_t e = vertex_edge_[internal_of_[v]];
  std::uint32_t h = e;
  std::size_t after_ghost = 0;
  do {
    if (vert_[next(h)] != kGhost)
      result.push_back(original_of_[vert_[next(h)]]);
    else
      after_ghost = result.size();
    h = twin_[prev(h)];
  } while (h != e);
  std::rotate(result.begin(), result.begin() + std::ptrdiff_t(after_ghost), result.end());
  return result;
}

std::uint32_t Delaunay2::nearest(const Vec2d& q) const {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1])) throw Error("Delaunay2::nearest: query is not finite");
  if (internal_triangle_.empty()) {
    std::uint32_t best = kNone;
    for (std::uint32_t v : hull_)
      if (best == kNone || (points_[v] - q).squaredNorm() < (points_[best] - q).squaredNorm()) best = v;
    return best;
  }
  const auto distance = [&](std::uint32_t v) { return (at(v) - q).squaredNorm(); };
  const Location loc = walk(q, internal_triangle_[internal_triangle_.size() / 2], nullptr);
  std::uint32_t best = kNone;
  for (std::uint32_t h = loc.edge / 3 * 3; h < loc.edge / 3 * 3 + 3; ++h)
    if (vert_[h] != kGhost && (best == kNone || distance(vert_[h]) < distance(best))) best = vert_[h];
  // Greedy: a vertex with no closer Delaunay neighbour is a nearest one (q
  // lies in its Voronoi cell).
  double best_distance = distance(best);
  for (bool improved = true; improved;) {
    improved = false;
    const std::uint32_t e = vertex_edge_[best];
    std::uint32_t h = e;
    do {
      const std::uint32_t w = vert_[next(h)];
      if (w != kGhost) {
        const double d = distance(w);
        if (d < best_distance) {
          best = w, best_distance = d, improved = true;
          break;
        }
      }
      h = twin_[prev(h)];
    } while (h != e);
  }
  return original_of_[best];
}

// ------------------------------------------------------------------ updates

std::uint32_t Delaunay2::insert(const Vec2d& p) {
  require_finite(p, points_.size(), "Delaunay2::insert");
  if (points_.size() + 1 >= (std::size_t(1) << 30)) throw Error("Delaunay2::insert: too many points");
  const std::uint32_t i = std::uint32_t(points_.size());
  points_.push_back(p);
  rep_.push_back(i);
  if (internal_triangle_.empty()) {
    build(options_);
  } else {
    const std::uint32_t k = std::uint32_t(coords_.size());
    coords_.push_back(p);
    original_of_.push_back(i);
    internal_of_.push_back(k);
    vertex_edge_.push_back(kNone);
    insert_vertex(k, last_triangle_);
    publish();
  }
  return i;
}

bool Delaunay2::remove_by_flips(std::uint32_t v) {
  std::uint32_t e = vertex_edge_[v];
  std::vector<std::uint32_t> star, link_vertices;
  // Ear (a, b, c) of the star polygon: is its circle free of the other link
  // vertices? A ghost in the ear makes it a half-plane, as in in_conflict.
  const auto ear_conflicts = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t x) {
    if (a != kGhost && b != kGhost && c != kGhost) return incircle(at(a), at(b), at(c), at(x)) > 0;
    const std::uint32_t s = a == kGhost ? b : b == kGhost ? c : a;
    const std::uint32_t t = a == kGhost ? c : b == kGhost ? a : b;
    const double side = orient2d(at(s), at(t), at(x));
    return side > 0 || (side == 0 && strictly_between(at(s), at(t), at(x)));
  };
  for (;;) {
    star.clear();
    link_vertices.clear();
    std::uint32_t h = e;
    do {
      star.push_back(h);
      link_vertices.push_back(vert_[next(h)]);
      h = twin_[prev(h)];
    } while (h != e);
    const std::size_t degree = star.size();
    if (degree == 3) break;
    bool flipped = false;
    for (std::size_t i = 0; i < degree && !flipped; ++i) {
      const std::uint32_t a = link_vertices[(i + degree - 1) % degree], b = link_vertices[i],
                          c = link_vertices[(i + 1) % degree];
      if (b == kGhost) continue;
      // The flip of v-b must be a flip of a convex quadrilateral.
      bool valid;
      if (a == kGhost)
        valid = orient2d(at(v), at(c), at(b)) < 0;
      else if (c == kGhost)
        valid = orient2d(at(a), at(v), at(b)) < 0;
      else
        valid = orient2d(at(a), at(b), at(c)) > 0 && orient2d(at(v), at(a), at(c)) > 0;
      if (!valid) continue;
      bool empty = true;
      for (std::size_t j = 0; j < degree && empty; ++j) {
        const std::uint32_t x = link_vertices[j];
        if (x == kGhost || x == a || x == b || x == c) continue;
        empty = !ear_conflicts(a, b, c, x);
      }
      if (!empty) continue;
      flip(star[i]);  // star[i] = v -> b becomes v -> a
      e = star[i];
      flipped = true;
    }
    if (!flipped) return false;
  }
  // Degree 3: (v, w0, w1), (v, w1, w2), (v, w2, w0) become (w2, w0, w1).
  const std::uint32_t h0 = star[0], h1 = star[1], h2 = star[2];
  const std::uint32_t outer1 = twin_[next(h1)], outer2 = twin_[next(h2)];
  vert_[h0] = link_vertices[2];
  link(h0, outer2);
  link(prev(h0), outer1);
  for (std::uint32_t t : {h1 / 3, h2 / 3}) {
    vert_[3 * t] = vert_[3 * t + 1] = vert_[3 * t + 2] = kNone;
    free_triangles_.push_back(t);
  }
  last_triangle_ = h0 / 3;
  return true;
}

void Delaunay2::remove(std::uint32_t v) {
  if (v >= points_.size() || rep_[v] == kNone)
    throw Error("Delaunay2::remove: point " + std::to_string(v) + " is not in the triangulation");
  if (!segments_.empty()) throw Error("Delaunay2::remove: not supported on a constrained triangulation");
  if (rep_[v] != v) {  // an alias: the triangulation does not change
    rep_[v] = kNone;
    return;
  }
  std::uint32_t alias = kNone;
  for (std::uint32_t i = v + 1; i < rep_.size() && alias == kNone; ++i)
    if (rep_[i] == v) alias = i;
  if (alias != kNone) {  // the next equal point takes v's place
    for (std::uint32_t i = v + 1; i < rep_.size(); ++i)
      if (rep_[i] == v) rep_[i] = alias;
    rep_[v] = kNone;
    if (internal_triangle_.empty()) {
      build_degenerate();
    } else {
      original_of_[internal_of_[v]] = alias;
      internal_of_[v] = kNone;
      publish();
    }
    return;
  }
  rep_[v] = kNone;
  const std::uint32_t internal = internal_of_[v];
  internal_of_[v] = kNone;
  if (internal_triangle_.empty() || !remove_by_flips(internal)) {
    build(options_);
    return;
  }
  publish();
  if (internal_triangle_.empty()) build(options_);  // what is left is collinear
}

std::vector<std::uint8_t> Delaunay2::inside() const {
  // Even-odd: a breadth-first search from the hull, the parity flipping across
  // each constrained edge.
  const std::size_t m = triangle_count();
  std::vector<std::uint8_t> parity(m, 2);
  std::vector<std::uint32_t> queue;
  for (std::uint32_t e = 0; e < 3 * m; ++e)
    if (halfedges_[e] == kNone && parity[e / 3] == 2) {
      parity[e / 3] = constrained_.empty() ? 0 : constrained_[e];
      queue.push_back(e / 3);
    }
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const std::uint32_t t = queue[k];
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t f = halfedges_[e];
      if (f == kNone || parity[f / 3] != 2) continue;
      parity[f / 3] = std::uint8_t(parity[t] ^ (constrained_.empty() ? 0 : constrained_[e]));
      queue.push_back(f / 3);
    }
  }
  return parity;
}

std::vector<Delaunay2::Segment> Delaunay2::constrained_edges() const {
  std::vector<Segment> edges;
  for (std::uint32_t e = 0; e < constrained_.size(); ++e)
    if (constrained_[e] && (halfedges_[e] == kNone || e < halfedges_[e]))
      edges.push_back({triangles_[e], triangles_[next(e)]});
  return edges;
}

// ------------------------------------------------------------------ inspection

Delaunay2Stats Delaunay2::stats() const {
  Delaunay2Stats s;
  s.points = points_.size();
  for (std::uint32_t i = 0; i < rep_.size(); ++i) {
    s.vertices += rep_[i] == i;
    s.duplicates += rep_[i] != kNone && rep_[i] != i;
    s.removed += rep_[i] == kNone;
  }
  s.triangles = triangle_count();
  s.hull = hull_.size();
  s.flips = flips_;
  s.walk_steps = walk_steps_;
  s.dag_nodes = dag_nodes_;
  s.bytes = (points_.capacity() + coords_.capacity()) * sizeof(Vec2d) +
            sizeof(std::uint32_t) * (rep_.capacity() + original_of_.capacity() + internal_of_.capacity() + vert_.capacity() + twin_.capacity() +
                                     free_triangles_.capacity() + vertex_edge_.capacity() + triangles_.capacity() +
                                     halfedges_.capacity() + hull_.capacity() + public_triangle_.capacity() +
                                     internal_triangle_.capacity());
  return s;
}

void Delaunay2::validate() const {
  const auto fail = [](const std::string& what) { throw Error("Delaunay2::validate: " + what); };
  const std::size_t n = points_.size();
  if (rep_.size() != n) fail("one representative per point expected");
  std::size_t vertices = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t r = rep_[i];
    if (r == kNone) continue;
    if (r > i || rep_[r] != r) fail("point " + std::to_string(i) + " has a bad representative");
    if (points_[r] != points_[i]) fail("point " + std::to_string(i) + " differs from its representative");
    vertices += r == i;
  }
  if (internal_triangle_.empty()) {
    const auto at = [&](std::uint32_t i) { return points_[i]; };
    if (!triangles_.empty() || !halfedges_.empty()) fail("degenerate set with triangles");
    if (hull_.size() != vertices) fail("degenerate hull does not list every distinct point");
    for (std::size_t k = 0; k < hull_.size(); ++k) {
      if (rep_[hull_[k]] != hull_[k]) fail("degenerate hull lists a non-representative");
      if (k > 0 && !(at(hull_[k - 1])[0] < at(hull_[k])[0] ||
                     (at(hull_[k - 1])[0] == at(hull_[k])[0] && at(hull_[k - 1])[1] < at(hull_[k])[1])))
        fail("degenerate hull is not sorted");
      if (k > 1 && orient2d(at(hull_[0]), at(hull_[1]), at(hull_[k])) != 0)
        fail("degenerate set is not collinear");
    }
    return;
  }
  // The closed triangulation.
  const std::uint32_t half_edges = std::uint32_t(vert_.size());
  if (twin_.size() != half_edges || half_edges % 3) fail("array sizes");
  std::size_t live = 0, ghosts = 0;
  std::vector<char> present(n, 0);
  for (std::uint32_t t = 0; t < half_edges / 3; ++t) {
    if (vert_[3 * t] == kNone) continue;
    ++live;
    const bool ghost = is_ghost_triangle(t);
    ghosts += ghost;
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e) {
      const std::uint32_t v = vert_[e], f = twin_[e];
      if (v != kGhost) {
        const std::uint32_t o = v < coords_.size() ? original_of_[v] : kNone;
        if (o >= n || rep_[o] != o || internal_of_[o] != v || points_[o] != coords_[v])
          fail("triangle " + std::to_string(t) + " uses a vertex that is not a representative");
        present[o] = 1;
      }
      if (f >= half_edges || twin_[f] != e || vert_[f] == kNone) fail("twin of half-edge " + std::to_string(e));
      if (vert_[f] != vert_[next(e)] || vert_[next(f)] != v) fail("twins of half-edge " + std::to_string(e) + " do not share their end points");
    }
    if (!ghost && !(orient2d(at(vert_[3 * t]), at(vert_[3 * t + 1]), at(vert_[3 * t + 2])) > 0))
      fail("triangle " + std::to_string(t) + " is not counter-clockwise");
  }
  for (std::uint32_t i = 0; i < n; ++i)
    if (rep_[i] == i && !present[i]) fail("point " + std::to_string(i) + " is in no triangle");
  // Locally Delaunay: the vertex opposite each edge is not inside the circle
  // (half-plane for a ghost triangle) of the triangle on the other side. With
  // ghost triangles this also says that the hull is convex.
  for (std::uint32_t e = 0; e < half_edges; ++e) {
    if (vert_[e] == kNone) continue;
    const std::uint32_t opposite = vert_[prev(twin_[e])];
    if (opposite == kGhost || (has_constraints_ && fixed_[e])) continue;
    if (in_conflict(e / 3, at(opposite)))
      fail("edge " + std::to_string(vert_[e]) + "-" + std::to_string(vert_[next(e)]) + " is not locally Delaunay");
  }
  if (has_constraints_) {
    if (fixed_.size() != half_edges) fail("constraint flags have the wrong size");
    for (std::uint32_t e = 0; e < half_edges; ++e)
      if (vert_[e] != kNone && fixed_[e] != fixed_[twin_[e]]) fail("constraint flags of twins differ");
    // Every input segment is a path of constrained edges through vertices on
    // it or through intersection points (rounded, so slightly off it).
    std::vector<std::uint32_t> crossings = intersections_;
    std::sort(crossings.begin(), crossings.end());
    for (const Segment& seg : segments_) {
      const std::uint32_t a = internal_of_[rep_[seg[0]]], b = internal_of_[rep_[seg[1]]];
      if (a == kNone || b == kNone) fail("a segment end point is not a vertex");
      std::vector<std::uint32_t> queue{a};
      std::vector<char> seen(coords_.size(), 0);
      seen[a] = 1;
      for (std::size_t k = 0; k < queue.size() && !seen[b]; ++k) {
        const std::uint32_t start = vertex_edge_[queue[k]];
        std::uint32_t h = start;
        do {
          const std::uint32_t w = vert_[next(h)];
          if (fixed_[h] && w != kGhost && !seen[w] &&
              (w == b || std::binary_search(crossings.begin(), crossings.end(), original_of_[w]) ||
               (orient2d(at(a), at(b), at(w)) == 0 && strictly_between(at(a), at(b), at(w))))) {
            seen[w] = 1;
            queue.push_back(w);
          }
          h = twin_[prev(h)];
        } while (h != start);
      }
      if (!seen[b]) fail("segment " + std::to_string(seg[0]) + "-" + std::to_string(seg[1]) + " is not present");
    }
  }
  // Euler on the sphere (ghost vertex included): t = 2 (n + 1) - 4; hull size = ghost triangles.
  const std::size_t finite = live - ghosts;
  if (live != 2 * (vertices + 1) - 4) fail("Euler's formula fails for the closed triangulation");
  if (finite != 2 * vertices - hull_.size() - 2) fail("t = 2n - h - 2 fails");
  if (hull_.size() != ghosts) fail("hull size differs from the number of hull edges");
  // The public arrays.
  if (triangles_.size() != 3 * finite || halfedges_.size() != triangles_.size()) fail("public arrays have the wrong size");
  for (std::size_t k = 0; k < finite; ++k) {
    const std::uint32_t t = internal_triangle_[k];
    for (std::uint32_t s = 0; s < 3; ++s) {
      const std::uint32_t e = std::uint32_t(3 * k + s);
      if (triangles_[e] != original_of_[vert_[3 * t + s]]) fail("public triangle " + std::to_string(k) + " differs");
      const std::uint32_t h = halfedges_[e];
      if (h == kNone) {
        if (!is_ghost_triangle(twin_[3 * t + s] / 3)) fail("public hull edge inside the triangulation");
      } else if (h >= halfedges_.size() || halfedges_[h] != e) {
        fail("public halfedges are not symmetric");
      }
    }
  }
}

}  // namespace geods::voronoi
