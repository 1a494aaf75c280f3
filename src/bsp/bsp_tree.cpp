#include "geods/bsp/bsp_tree.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"

namespace geods::bsp {

Heuristic parse_heuristic(std::string_view name) {
  if (name == "cost") return Heuristic::cost;
  if (name == "random") return Heuristic::random;
  if (name == "balanced") return Heuristic::balanced;
  if (name == "custom") return Heuristic::custom;
  throw Error("unknown BSP heuristic '" + std::string(name) + "' (cost, random, balanced or custom)");
}

std::string_view heuristic_name(Heuristic h) {
  switch (h) {
    case Heuristic::cost: return "cost";
    case Heuristic::random: return "random";
    case Heuristic::balanced: return "balanced";
    case Heuristic::custom: return "custom";
  }
  return "cost";
}

// ---------------------------------------------------------------- Grid

Grid Grid::fit(const Vec3d& lo, const Vec3d& hi) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(lo[i]) || !std::isfinite(hi[i]) || lo[i] > hi[i]) throw Error("bsp: empty or non-finite bounds");
  double half = 0;
  for (int i = 0; i < 3; ++i) half = std::max(half, (hi[i] - lo[i]) / 2);
  Grid g;
  // Largest shift with half * 2^shift + 1 <= 2^kGridBits.
  if (half == 0) half = std::max({std::fabs(lo[0]), std::fabs(lo[1]), std::fabs(lo[2]), 1.0});
  int e = 0;
  std::frexp(half, &e);  // half < 2^e
  g.shift = kGridBits - 1 - e;
  const double limit = std::ldexp(1.0, 62);
  for (int i = 0; i < 3; ++i) {
    const double mid = std::ldexp(std::nearbyint(std::ldexp(lo[i], g.shift - 1) + std::ldexp(hi[i], g.shift - 1)), 0);
    const double far = std::max(std::fabs(std::ldexp(lo[i], g.shift)), std::fabs(std::ldexp(hi[i], g.shift)));
    if (!(far < limit) || !(std::fabs(mid) < limit))
      throw Error("bsp: coordinates too far from the origin for their extent (scale or translate the input)");
    g.center[i] = static_cast<std::int64_t>(mid);
  }
  return g;
}

std::array<std::int64_t, 3> Grid::snap(const Vec3d& p) const {
  std::array<std::int64_t, 3> q;
  for (int i = 0; i < 3; ++i) {
    const double s = std::nearbyint(std::ldexp(p[i], shift));
    q[i] = static_cast<std::int64_t>(s) - center[i];
    if (q[i] > (std::int64_t{1} << kGridBits) || q[i] < -(std::int64_t{1} << kGridBits))
      throw Error("bsp: a vertex outside the grid's box (internal error)");
  }
  return q;
}

Vec3d Grid::to_grid(const Vec3d& p) const {
  return {std::ldexp(p[0], shift) - static_cast<double>(center[0]), std::ldexp(p[1], shift) - static_cast<double>(center[1]),
          std::ldexp(p[2], shift) - static_cast<double>(center[2])};
}

Vec3d Grid::to_world(const std::array<double, 3>& g) const {
  return {std::ldexp(g[0] + static_cast<double>(center[0]), -shift), std::ldexp(g[1] + static_cast<double>(center[1]), -shift),
          std::ldexp(g[2] + static_cast<double>(center[2]), -shift)};
}

double Grid::step() const { return std::ldexp(1.0, -shift); }

void check_mesh(const std::vector<Vec3d>& vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                const char* what) {
  for (std::size_t i = 0; i < vertices.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(vertices[i][c]))
        throw Error(std::string(what) + ": vertex " + std::to_string(i) + " is not finite");
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int c = 0; c < 3; ++c)
      if (triangles[t][c] >= vertices.size())
        throw Error(std::string(what) + ": triangle " + std::to_string(t) + " has a corner out of range");
  if (triangles.empty()) throw Error(std::string(what) + ": empty mesh");
}

Triangles from_tri_mesh(const TriMesh& m) {
  Triangles t;
  t.vertices.reserve(m.vertices.size());
  for (const auto& v : m.vertices) t.vertices.push_back(v.cast<double>());
  t.triangles = m.triangles;
  return t;
}

TriMesh to_tri_mesh(const Triangles& m) {
  TriMesh t;
  t.vertices.reserve(m.vertices.size());
  for (const auto& v : m.vertices) t.vertices.push_back(v.cast<float>());
  t.triangles = m.triangles;
  return t;
}

// ---------------------------------------------------------------- construction

namespace {

struct Frag {
  Polygon poly;
  double area = 0;
  double density = 0;  // custom: score per unit area (of the input polygon it comes from)
  std::array<double, 3> centroid{};
};

Frag make_frag(const PlaneSet& planes, Polygon&& p) {
  Frag f;
  f.poly = std::move(p);
  f.area = approx_area(planes, f.poly);
  f.centroid = approx_centroid(planes, f.poly);
  return f;
}

}  // namespace

BspTree::BspTree(const std::vector<Vec3d>& vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                 const BuildOptions& options) {
  check_mesh(vertices, triangles, "bsp");
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& t : triangles)
    for (auto v : t) lo = lo.cwiseMin(vertices[v]), hi = hi.cwiseMax(vertices[v]);
  planes_ = std::make_shared<PlaneSet>();
  grid_ = Grid::fit(lo, hi);
  build(vertices, triangles, options);
}

BspTree::BspTree(std::shared_ptr<PlaneSet> planes, const Grid& grid, const std::vector<Vec3d>& vertices,
                 const std::vector<std::array<std::uint32_t, 3>>& triangles, const BuildOptions& options)
    : planes_(std::move(planes)), grid_(grid) {
  check_mesh(vertices, triangles, "bsp");
  build(vertices, triangles, options);
}

void BspTree::build(const std::vector<Vec3d>& vertices, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                    const BuildOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!(options.alpha > 0) || !std::isfinite(options.alpha) || !(options.beta >= 0) || !std::isfinite(options.beta))
    throw Error("bsp: alpha must be > 0 and beta >= 0");
  if (options.k == 0) throw Error("bsp: k must be at least 1");
  if (options.heuristic == Heuristic::custom) {
    const RayQuery& r = options.rays;
    if (r.directions.empty()) throw Error("bsp: the custom heuristic needs a sample of rays");
    if (r.origins.size() != r.directions.size()) throw Error("bsp: the ray sample has as many origins as directions");
    for (std::size_t i = 0; i < r.directions.size(); ++i) {
      const double len = r.directions[i].norm();
      if (!std::isfinite(len) || !(len > 0) || !r.origins[i].allFinite())
        throw Error("bsp: a sample ray is not finite or has a zero direction");
    }
  }
  PlaneSet& planes = *planes_;
  std::vector<std::array<std::int64_t, 3>> snapped(vertices.size());
  std::vector<std::uint32_t> point_id(vertices.size(), kNoPoint);
  for (const auto& t : triangles)
    for (auto v : t)
      if (point_id[v] == kNoPoint) snapped[v] = grid_.snap(vertices[v]), point_id[v] = planes.add_point(snapped[v]);

  std::vector<Frag> pool;
  pool.reserve(triangles.size() * 2);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& p0 = snapped[triangles[t][0]];
    const auto& p1 = snapped[triangles[t][1]];
    const auto& p2 = snapped[triangles[t][2]];
    const Plane s = PlaneSet::through(p0, p1, p2);
    if (s.a == 0 && s.b == 0 && s.c == 0) continue;  // degenerate after snapping
    const std::int64_t an[3] = {std::abs(s.a), std::abs(s.b), std::abs(s.c)};
    const int axis = an[0] >= an[1] && an[0] >= an[2] ? 0 : (an[1] >= an[2] ? 1 : 2);
    Polygon poly;
    poly.source = static_cast<std::uint32_t>(t);
    poly.support = planes.add(s);
    poly.edges = {planes.add(edge_plane(p0, p1, p2, axis)), planes.add(edge_plane(p1, p2, p0, axis)),
                  planes.add(edge_plane(p2, p0, p1, axis))};
    poly.points = {point_id[triangles[t][0]], point_id[triangles[t][1]], point_id[triangles[t][2]]};
    pool.push_back(make_frag(planes, std::move(poly)));
  }
  if (pool.empty()) throw Error("bsp: every triangle is degenerate (at the grid's resolution)");
  if (options.heuristic == Heuristic::custom) {
    // §3.4.3: w(S, p, l) = sin^2(angle of ray l and p's plane) Area(p) / Area(S), summed over
    // the sample rays l that can hit p (their line meets p's bounding sphere on the ray's
    // side). density = the sum per unit area, the same for every fragment of p.
    std::vector<Vec3d> o, d;
    for (std::size_t i = 0; i < options.rays.origins.size(); ++i) {
      o.push_back(grid_.to_grid(options.rays.origins[i]));
      d.push_back(options.rays.directions[i].normalized());
    }
    for (Frag& f : pool) {
      const Plane& h = planes[f.poly.support];
      const Vec3d n = Vec3d(static_cast<double>(h.a), static_cast<double>(h.b), static_cast<double>(h.c)).normalized();
      const Vec3d c(f.centroid[0], f.centroid[1], f.centroid[2]);
      double r2 = 0;
      for (auto q : f.poly.points) {
        const auto& x = planes.integer_point(q);
        r2 = std::max(r2, (Vec3d(static_cast<double>(x[0]), static_cast<double>(x[1]), static_cast<double>(x[2])) - c).squaredNorm());
      }
      double sum = 0;
      for (std::size_t i = 0; i < o.size(); ++i) {
        const Vec3d v = c - o[i];
        const double t = v.dot(d[i]);
        if (t * std::fabs(t) < -r2 || (v - t * d[i]).squaredNorm() > r2) continue;
        const double cs = n.dot(d[i]);
        sum += cs * cs;
      }
      f.density = sum / static_cast<double>(o.size());
    }
  }
  stats_ = BspStats{};
  stats_.polygons = pool.size();

  struct Task {
    std::uint32_t node;
    std::vector<std::uint32_t> frags;
  };
  std::mt19937_64 rng(options.seed);
  std::vector<Node> nodes;
  fragments_.clear();
  nodes.emplace_back();
  root_ = 0;
  std::vector<Task> stack;
  {
    Task t{0, {}};
    t.frags.resize(pool.size());
    std::iota(t.frags.begin(), t.frags.end(), 0u);
    stack.push_back(std::move(t));
  }
  std::vector<int> signs;
  std::vector<std::uint32_t> order, scored;
  std::vector<std::pair<double, std::uint32_t>> ranked;

  // Sides of fragment f against plane h: -1 neg, +1 pos, 0 coplanar, 2 straddling.
  auto side_of = [&](std::uint32_t f, std::uint32_t h) {
    switch (bsp::classify(planes, pool[f].poly, h)) {
      case Side::negative: return -1;
      case Side::positive: return 1;
      case Side::coplanar: return 0;
      default: return 2;
    }
  };

  while (!stack.empty()) {
    Task task = std::move(stack.back());
    stack.pop_back();
    auto& frags = task.frags;
    // Fragments scored for a candidate: all, or a random sample.
    scored.clear();
    if (options.heuristic != Heuristic::custom) scored = frags;  // (custom scores no splits)
    if (scored.size() > options.sample) {
      for (std::size_t i = 0; i < options.sample; ++i)
        std::swap(scored[i], scored[i + rng() % (scored.size() - i)]);
      scored.resize(options.sample);
    }
    const double scale = static_cast<double>(frags.size()) / static_cast<double>(std::max<std::size_t>(1, scored.size()));

    std::uint32_t plane = kNoIndex;
    if (options.heuristic == Heuristic::balanced && frags.size() > 1) {
      // Median of the centroids along the axis of largest spread, moved into the widest gap
      // near the median; accepted if polygons lie strictly on both sides.
      int axis = 0;
      double best = -1;
      for (int a = 0; a < 3; ++a) {
        double mn = std::numeric_limits<double>::infinity(), mx = -mn;
        for (auto f : scored) mn = std::min(mn, pool[f].centroid[a]), mx = std::max(mx, pool[f].centroid[a]);
        if (mx - mn > best) best = mx - mn, axis = a;
      }
      std::vector<double> v;
      v.reserve(scored.size());
      for (auto f : scored) v.push_back(pool[f].centroid[axis]);
      std::sort(v.begin(), v.end());
      const std::size_t lo = v.size() * 2 / 5, hi = std::max(lo + 1, v.size() * 3 / 5);
      std::size_t gi = lo;
      for (std::size_t i = lo; i < hi && i + 1 < v.size(); ++i)
        if (v[i + 1] - v[i] > v[gi + 1 < v.size() ? gi + 1 : gi] - v[gi]) gi = i;
      const double m = gi + 1 < v.size() ? (v[gi] + v[gi + 1]) / 2 : v[gi];
      Plane p;
      (axis == 0 ? p.a : axis == 1 ? p.b : p.c) = 1;
      p.d = -static_cast<std::int64_t>(std::nearbyint(m));
      const std::uint32_t h = planes.add(p);
      // Accepted if both sides get fewer polygons than the node has (straddling ones count on both).
      std::size_t neg = 0, pos = 0;
      for (auto f : frags) {
        const int s = side_of(f, h);
        neg += s == -1 || s == 2;
        pos += s == 1 || s == 2;
      }
      if (neg > 0 && pos > 0 && neg < frags.size() && pos < frags.size()) plane = h;
    }
    if (options.heuristic == Heuristic::custom) {
      // §3.4.3: score(p) = Area(p) * density (Area(S) is the same for every candidate of the
      // node); the plane of a random one of the k best.
      const std::size_t k = std::min<std::size_t>(options.k, frags.size());
      ranked.clear();
      for (auto f : frags) ranked.emplace_back(pool[f].density * pool[f].area, f);
      std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(k), ranked.end(),
                        [](const auto& a, const auto& b) { return a.first > b.first; });
      plane = pool[ranked[rng() % k].second].poly.support;
    }
    if (plane == kNoIndex) {
      // Candidates: the k largest fragments (cost) or k random ones (random).
      order = frags;
      const std::size_t k = std::min<std::size_t>(options.k, order.size());
      if (options.heuristic == Heuristic::random) {
        for (std::size_t i = 0; i < k; ++i) std::swap(order[i], order[i + rng() % (order.size() - i)]);
      } else {
        std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(),
                          [&](std::uint32_t a, std::uint32_t b) { return pool[a].area > pool[b].area; });
      }
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < k; ++i) {
        const std::uint32_t h = pool[order[i]].poly.support;
        double neg = 0, pos = 0, split = 0;
        if (k > 1)
          for (auto f : scored) {
            const int s = side_of(f, h);
            neg += s == -1 || s == 2;
            pos += s == 1 || s == 2;
            split += s == 2;
          }
        const double cost = options.heuristic == Heuristic::random
                                ? split
                                : 1 + std::pow(neg * scale, options.alpha) + std::pow(pos * scale, options.alpha) +
                                      options.beta * split * scale;
        if (cost < best) best = cost, plane = h;
      }
    }

    // Distribute the fragments.
    Task negt{kNoIndex, {}}, post{kNoIndex, {}};
    const std::uint32_t node = task.node;
    const std::uint32_t first = static_cast<std::uint32_t>(fragments_.size());
    for (auto f : frags) {
      const Side s = bsp::classify(planes, pool[f].poly, plane, &signs);
      if (s == Side::coplanar) {
        fragments_.push_back(pool[f].poly);
      } else if (s == Side::negative) {
        negt.frags.push_back(f);
      } else if (s == Side::positive) {
        post.frags.push_back(f);
      } else {
        Polygon a, b;
        split(planes, pool[f].poly, plane, signs, a, b);
        negt.frags.push_back(static_cast<std::uint32_t>(pool.size()));
        const double density = pool[f].density;
        pool.push_back(make_frag(planes, std::move(a)));
        pool.back().density = density;
        post.frags.push_back(static_cast<std::uint32_t>(pool.size()));
        pool.push_back(make_frag(planes, std::move(b)));
        pool.back().density = density;
      }
    }
    frags.clear();
    frags.shrink_to_fit();
    nodes[node].plane = plane;
    nodes[node].first = first;
    nodes[node].count = static_cast<std::uint32_t>(fragments_.size() - first);
    for (int side : {-1, 1}) {
      Task& t = side < 0 ? negt : post;
      const auto child = static_cast<std::uint32_t>(nodes.size());
      nodes.emplace_back();
      (side < 0 ? nodes[node].neg : nodes[node].pos) = child;
      if (t.frags.empty()) {
        // Only at auto-partition nodes (balanced planes separate): behind a polygon is inside.
        nodes[child].label = side < 0 ? Label::inside : Label::outside;
      } else {
        t.node = child;
        stack.push_back(std::move(t));
      }
    }
  }
  nodes_ = std::move(nodes);
  stats_.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  compute_stats();
}

void BspTree::compute_stats() {
  const double build_s = stats_.build_s;
  const std::size_t polygons = stats_.polygons;
  stats_ = BspStats{};
  stats_.build_s = build_s;
  stats_.polygons = polygons;
  stats_.nodes = nodes_.size();
  stats_.fragments = fragments_.size();
  if (root_ == kNoIndex) return;
  std::vector<std::pair<std::uint32_t, std::size_t>> stack{{root_, 0}};
  while (!stack.empty()) {
    auto [n, d] = stack.back();
    stack.pop_back();
    if (nodes_[n].leaf()) {
      ++stats_.leaves;
      stats_.depth = std::max(stats_.depth, d);
      continue;
    }
    stack.push_back({nodes_[n].neg, d + 1});
    stack.push_back({nodes_[n].pos, d + 1});
  }
  // Equation (4) with P(child) = Vol(child) / Vol(node) inside the box of the fragments,
  // estimated by the mean path length of 4096 random points (C(leaf) = 1).
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const auto& f : fragments_)
    for (std::size_t k = 0; k < f.size(); ++k) {
      const auto p = planes_->point(f.vertex(k));
      for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
    }
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(0, 1);
  const int samples = 4096;
  double total = 0;
  for (int s = 0; s < samples; ++s) {
    double p[3];
    for (int i = 0; i < 3; ++i) p[i] = lo[i] + (hi[i] - lo[i]) * u(rng);
    std::uint32_t n = root_;
    std::size_t visited = 1;
    while (!nodes_[n].leaf()) {
      n = planes_->side(nodes_[n].plane, p) < 0 ? nodes_[n].neg : nodes_[n].pos;
      ++visited;
    }
    total += static_cast<double>(visited);
  }
  stats_.expected_cost = total / samples;
}

// ---------------------------------------------------------------- queries

int BspTree::classify(const Vec3d& p) const {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(p[i])) throw Error("bsp classify: point is not finite");
  if (root_ == kNoIndex) return 1;
  const Vec3d g = grid_.to_grid(p);
  // Descent; on a plane, both sides (the point is on the boundary unless they agree).
  std::vector<std::uint32_t> stack{root_};
  int result = 2;
  while (!stack.empty()) {
    std::uint32_t n = stack.back();
    stack.pop_back();
    while (!nodes_[n].leaf()) {
      const int s = planes_->side(nodes_[n].plane, g.data());
      if (s == 0) {
        stack.push_back(nodes_[n].pos);
        n = nodes_[n].neg;
      } else {
        n = s < 0 ? nodes_[n].neg : nodes_[n].pos;
      }
    }
    const int c = nodes_[n].label == Label::inside ? -1 : 1;
    if (result == 2)
      result = c;
    else if (result != c)
      return 0;
  }
  return result;
}

std::vector<std::uint32_t> BspTree::visibility_order(const Vec3d& eye, bool back_to_front,
                                                     const std::vector<Vec3d>& frustum) const {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(eye[i])) throw Error("bsp visibility_order: eye is not finite");
  std::vector<std::uint32_t> out;
  if (root_ == kNoIndex) return out;
  const Vec3d g = grid_.to_grid(eye);
  std::vector<Vec3d> fg;
  for (const auto& f : frustum) fg.push_back(grid_.to_grid(f));
  // Stack entries: node index, or node | top bit = "emit the node's fragments".
  constexpr std::uint32_t kEmit = 0x80000000u;
  std::vector<std::uint32_t> stack{root_};
  while (!stack.empty()) {
    const std::uint32_t e = stack.back();
    stack.pop_back();
    if (e & kEmit) {
      const Node& nd = nodes_[e & ~kEmit];
      for (std::uint32_t i = 0; i < nd.count; ++i) out.push_back(nd.first + i);
      continue;
    }
    const Node& nd = nodes_[e];
    if (nd.leaf()) continue;
    if (!fg.empty()) {
      bool all_neg = true, all_pos = true;
      for (const auto& f : fg) {
        const int s = planes_->side(nd.plane, f.data());
        all_neg &= s < 0;
        all_pos &= s > 0;
      }
      if (all_neg) {
        stack.push_back(nd.neg);
        continue;
      }
      if (all_pos) {
        stack.push_back(nd.pos);
        continue;
      }
    }
    const int s = planes_->side(nd.plane, g.data());
    const std::uint32_t near = s < 0 ? nd.neg : nd.pos;
    const std::uint32_t far = s < 0 ? nd.pos : nd.neg;
    // Back to front: far, node, near (the stack pops in reverse order).
    const std::uint32_t first = back_to_front ? far : near, last = back_to_front ? near : far;
    stack.push_back(last);
    stack.push_back(e | kEmit);
    stack.push_back(first);
  }
  return out;
}

BspTree::Hit BspTree::first_hit(const Vec3d& origin, const Vec3d& dir, double t_max, std::size_t* nodes,
                                std::size_t* tests) const {
  std::size_t visited = 0, tested = 0;
  struct Count {  // adds the work to the caller's counters on every return
    std::size_t &visited, &tested, *nodes, *tests;
    ~Count() {
      if (nodes) *nodes += visited;
      if (tests) *tests += tested;
    }
  } count{visited, tested, nodes, tests};
  Hit hit;
  if (root_ == kNoIndex) return hit;
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(origin[i]) || !std::isfinite(dir[i])) throw Error("bsp first_hit: ray is not finite");
  const Vec3d o = grid_.to_grid(origin);
  const Vec3d d = dir * std::ldexp(1.0, grid_.shift);
  const PlaneSet& P = *planes_;
  auto eval = [&](std::uint32_t ref, const Vec3d& x) {
    const Plane& p = P[ref];
    const double v = static_cast<double>(p.a) * x[0] + static_cast<double>(p.b) * x[1] + static_cast<double>(p.c) * x[2] +
                     static_cast<double>(p.d);
    return (ref & kFlip) ? -v : v;
  };
  auto dot = [&](std::uint32_t ref, const Vec3d& x) {
    const Plane& p = P[ref];
    const double v = static_cast<double>(p.a) * x[0] + static_cast<double>(p.b) * x[1] + static_cast<double>(p.c) * x[2];
    return (ref & kFlip) ? -v : v;
  };
  struct Item {
    std::uint32_t node;
    double t0, t1;
  };
  std::vector<Item> stack{{root_, 0.0, t_max}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    if (it.t0 > hit.t) continue;
    ++visited;
    const Node& nd = nodes_[it.node];
    if (nd.leaf()) continue;
    const double so = eval(nd.plane, o), dn = dot(nd.plane, d);
    const std::uint32_t near = (so < 0 || (so == 0 && dn > 0)) ? nd.neg : nd.pos;
    const std::uint32_t far = near == nd.neg ? nd.pos : nd.neg;
    const double t = dn != 0 ? -so / dn : std::numeric_limits<double>::infinity();
    if (!(t >= it.t0 && t <= it.t1)) {
      stack.push_back({t < it.t0 && t >= 0 ? far : near, it.t0, it.t1});
      continue;
    }
    // Near side first: push far, the node's polygons (via a check now, cheap), then near.
    stack.push_back({far, t, it.t1});
    const Vec3d x = o + t * d;
    for (std::uint32_t i = 0; i < nd.count && t < hit.t; ++i) {
      const Polygon& f = fragments_[nd.first + i];
      ++tested;
      bool inside = true;
      for (auto e : f.edges) inside &= eval(e, x) <= 1e-9 * std::max(1.0, std::fabs(dot(e, x)));
      if (inside) hit = {t, f.source};
    }
    stack.push_back({near, it.t0, t});
  }
  return hit;
}

RayQueryResult BspTree::first_hits(const RayQuery& q) const {
  if (q.origins.size() != q.directions.size())
    throw Error("bsp first_hits: " + std::to_string(q.origins.size()) + " origins but " +
                std::to_string(q.directions.size()) + " directions");
  if (std::isnan(q.t_max)) throw Error("bsp first_hits: t_max is NaN");
  const auto t0 = std::chrono::steady_clock::now();
  RayQueryResult r;
  r.t.resize(q.origins.size());
  r.triangle.resize(q.origins.size());
  std::size_t nodes = 0, tests = 0;
  for (std::size_t i = 0; i < q.origins.size(); ++i) {
    const Hit h = first_hit(q.origins[i], q.directions[i], q.t_max, &nodes, &tests);
    r.t[i] = h.t;
    r.triangle[i] = h.triangle;
    r.stats.hits += h.triangle != kNoIndex;
  }
  r.stats.query_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.stats.rays = q.origins.size();
  const double n = static_cast<double>(std::max<std::size_t>(1, r.stats.rays));
  r.stats.nodes_per_ray = static_cast<double>(nodes) / n;
  r.stats.tests_per_ray = static_cast<double>(tests) / n;
  return r;
}

void BspTree::validate() const {
  if (root_ == kNoIndex) return;
  const PlaneSet& P = *planes_;
  std::vector<std::uint32_t> path;  // ancestors' plane refs oriented toward the node's side
  struct Item {
    std::uint32_t node;
    std::size_t depth;
    std::uint32_t side_plane;  // plane ref whose negative side contains the node (or kNoIndex)
  };
  std::vector<Item> stack{{root_, 0, kNoIndex}};
  std::size_t seen = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (++seen > nodes_.size()) throw Error("bsp validate: the nodes do not form a tree");
    if (it.node >= nodes_.size()) throw Error("bsp validate: child index out of range");
    path.resize(it.depth);
    if (it.side_plane != kNoIndex) path.back() = it.side_plane;
    const Node& nd = nodes_[it.node];
    if (nd.leaf()) {
      if (nd.count) throw Error("bsp validate: a leaf stores fragments");
      continue;
    }
    if (plane_index(nd.plane) >= P.size()) throw Error("bsp validate: plane index out of range");
    if (std::size_t{nd.first} + nd.count > fragments_.size()) throw Error("bsp validate: fragment range out of range");
    for (std::uint32_t i = 0; i < nd.count; ++i) {
      const Polygon& f = fragments_[nd.first + i];
      if (f.size() < 3) throw Error("bsp validate: a fragment with fewer than 3 edges");
      if (bsp::classify(P, f, nd.plane) != Side::coplanar) throw Error("bsp validate: a fragment off its node's plane");
      for (auto h : path)
        if (bsp::classify(P, f, h) == Side::positive || bsp::classify(P, f, h) == Side::straddling)
          throw Error("bsp validate: a fragment outside its node's cell");
    }
    path.resize(it.depth + 1);
    stack.push_back({nd.neg, it.depth + 1, nd.plane});
    stack.push_back({nd.pos, it.depth + 1, nd.plane ^ kFlip});
  }
}

// ---------------------------------------------------------------- save, load

void BspTree::save(const std::filesystem::path& path) const {
  if (root_ == kNoIndex) throw Error("bsp save: an empty tree");
  ArchiveWriter out(kArchiveKind, kArchiveVersion);
  out.add_value("grid_shift", std::int32_t(grid_.shift));
  out.add("grid_center", std::span<const std::int64_t>(grid_.center));
  std::vector<Plane> planes(planes_->size());
  for (std::size_t i = 0; i < planes.size(); ++i) planes[i] = (*planes_)[static_cast<std::uint32_t>(i)];
  out.add("planes", planes);
  // The fragments: support, source and plane lists (offsets into edges and points).
  std::vector<std::uint32_t> support, source, offsets{0}, edges, points;
  std::uint32_t point_count = 0;
  for (const Polygon& f : fragments_) {
    support.push_back(f.support);
    source.push_back(f.source);
    edges.insert(edges.end(), f.edges.begin(), f.edges.end());
    points.insert(points.end(), f.points.begin(), f.points.end());
    offsets.push_back(static_cast<std::uint32_t>(edges.size()));
    for (auto q : f.points)
      if (q != kNoPoint) point_count = std::max(point_count, q + 1);
  }
  std::vector<std::array<std::int64_t, 3>> coords(point_count);
  for (std::uint32_t i = 0; i < point_count; ++i) coords[i] = planes_->integer_point(i);
  out.add("points", coords);
  out.add("nodes", nodes_);
  out.add_value("root", root_);
  out.add("fragment_support", support);
  out.add("fragment_source", source);
  out.add("fragment_offsets", offsets);
  out.add("fragment_edges", edges);
  out.add("fragment_points", points);
  out.add_value("polygons", std::uint64_t(stats_.polygons));
  out.add_value("build_s", stats_.build_s);
  out.write(path);
}

BspTree BspTree::load(const std::filesystem::path& path) {
  const Archive in = Archive::open(path, kArchiveKind, kArchiveVersion);
  BspTree t;
  t.grid_.shift = in.value<std::int32_t>("grid_shift");
  const FlatArray<std::int64_t> center = in.array<std::int64_t>("grid_center", 3);
  for (int i = 0; i < 3; ++i) t.grid_.center[std::size_t(i)] = center[std::size_t(i)];
  if (t.grid_.shift < -1074 || t.grid_.shift > 1074) throw in.error("grid shift out of range");
  const FlatArray<Plane> planes = in.array<Plane>("planes");
  t.planes_ = std::make_shared<PlaneSet>();
  if (planes.size() < t.planes_->size()) throw in.error("fewer planes than the universe box's");
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const Plane& p = planes[i];
    if (i < t.planes_->size()) {
      const Plane& q = (*t.planes_)[static_cast<std::uint32_t>(i)];
      if (p.a != q.a || p.b != q.b || p.c != q.c || p.d != q.d) throw in.error("the universe box's planes differ");
      continue;
    }
    if (p.a == 0 && p.b == 0 && p.c == 0) throw in.error("plane " + std::to_string(i) + " has a zero normal");
    t.planes_->add(p);
  }
  const FlatArray<std::array<std::int64_t, 3>> points = in.array<std::array<std::int64_t, 3>>("points");
  for (const auto& q : points) {
    for (auto c : q)
      if (c > (std::int64_t{1} << kGridBits) || c < -(std::int64_t{1} << kGridBits))
        throw in.error("a point outside the grid");
    t.planes_->add_point(q);
  }
  const FlatArray<std::uint32_t> support = in.array<std::uint32_t>("fragment_support");
  const std::size_t nf = support.size();
  const FlatArray<std::uint32_t> source = in.array<std::uint32_t>("fragment_source", nf);
  const FlatArray<std::uint32_t> offsets = in.array<std::uint32_t>("fragment_offsets", nf + 1);
  const FlatArray<std::uint32_t> edges = in.array<std::uint32_t>("fragment_edges");
  const FlatArray<std::uint32_t> fpoints = in.array<std::uint32_t>("fragment_points", edges.size());
  const std::size_t np = planes.size();
  auto plane_ok = [&](std::uint32_t ref) { return plane_index(ref) < np; };
  if (offsets[0] != 0 || offsets[nf] != edges.size()) throw in.error("fragment offsets do not span the plane lists");
  t.fragments_.resize(nf);
  for (std::size_t i = 0; i < nf; ++i) {
    if (offsets[i + 1] < offsets[i] + 3) throw in.error("fragment " + std::to_string(i) + " has fewer than 3 edges");
    Polygon& f = t.fragments_[i];
    f.support = support[i];
    f.source = source[i];
    f.edges.assign(edges.begin() + offsets[i], edges.begin() + offsets[i + 1]);
    f.points.assign(fpoints.begin() + offsets[i], fpoints.begin() + offsets[i + 1]);
    if (!plane_ok(f.support)) throw in.error("fragment " + std::to_string(i) + ": plane index out of range");
    for (auto e : f.edges)
      if (!plane_ok(e)) throw in.error("fragment " + std::to_string(i) + ": plane index out of range");
    for (auto q : f.points)
      if (q != kNoPoint && q >= points.size()) throw in.error("fragment " + std::to_string(i) + ": point out of range");
  }
  t.nodes_ = in.array<Node>("nodes");
  t.root_ = in.value<std::uint32_t>("root");
  // Indices in range and a tree: every node reached once from the root.
  if (t.root_ >= t.nodes_.size()) throw in.error("root out of range");
  std::vector<std::uint8_t> seen(t.nodes_.size(), 0);
  std::vector<std::uint32_t> stack{t.root_};
  while (!stack.empty()) {
    const std::uint32_t n = stack.back();
    stack.pop_back();
    if (n >= t.nodes_.size() || seen[n]) throw in.error("the nodes do not form a tree");
    seen[n] = 1;
    const Node& nd = t.nodes_[n];
    if (static_cast<unsigned>(nd.label) > static_cast<unsigned>(Label::outside)) throw in.error("a node label out of range");
    if (std::uint64_t{nd.first} + nd.count > nf) throw in.error("a node's fragment range out of range");
    if (nd.leaf()) {
      if (nd.count != 0) throw in.error("a leaf stores fragments");
      continue;
    }
    if (!plane_ok(nd.plane)) throw in.error("a node's plane out of range");
    stack.push_back(nd.neg);
    stack.push_back(nd.pos);
  }
  t.stats_.polygons = in.value<std::uint64_t>("polygons");
  t.stats_.build_s = in.value<double>("build_s");
  t.compute_stats();
  return t;
}

Triangles BspTree::fragment_mesh() const {
  Triangles m;
  for (const auto& f : fragments_) {
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (std::size_t k = 0; k < f.size(); ++k) m.vertices.push_back(grid_.to_world(planes_->point(f.vertex(k))));
    for (std::uint32_t k = 1; k + 1 < f.size(); ++k) m.triangles.push_back({base, base + k, base + k + 1});
  }
  return m;
}

}  // namespace geods::bsp
