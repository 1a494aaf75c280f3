#include "geods/bsp/csg.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>

#include "geods/core/error.hpp"

namespace geods::bsp {

CsgOp parse_csg_op(std::string_view name) {
  if (name == "union") return CsgOp::union_;
  if (name == "intersection") return CsgOp::intersection;
  if (name == "difference") return CsgOp::difference;
  if (name == "xor") return CsgOp::xor_;
  throw Error("unknown boolean operation '" + std::string(name) + "' (union, intersection, difference or xor)");
}

std::string_view csg_op_name(CsgOp op) {
  switch (op) {
    case CsgOp::union_: return "union";
    case CsgOp::intersection: return "intersection";
    case CsgOp::difference: return "difference";
    case CsgOp::xor_: return "xor";
  }
  return "union";
}

double signed_volume(const Triangles& m) {
  double v = 0;
  for (const auto& t : m.triangles) v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]]));
  return v / 6;
}

bool is_closed(const Triangles& m) {
  std::unordered_map<std::uint64_t, int> count;
  count.reserve(m.triangles.size() * 3);
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t u = t[k], v = t[(k + 1) % 3];
      ++count[(u << 32) | v];
      --count[(v << 32) | u];
    }
  for (const auto& [e, c] : count)
    if (c != 0) return false;
  return true;
}

// The merge arena: the nodes of both operands, then the nodes merging creates.
class Merger {
 public:
  struct MNode {
    std::uint32_t plane = kNoIndex;
    std::uint32_t neg = kNoIndex, pos = kNoIndex;
    std::uint32_t face = kNoIndex;  // index into faces_
    Label label = Label::none;
    bool leaf() const { return plane == kNoIndex; }
  };

  Merger(const PlaneSet& planes, CsgOp op) : planes_(planes), op_(op) {}

  // Copies a tree's nodes and computes the face of each inner node; returns its root.
  std::uint32_t add_tree(const BspTree& t) {
    const auto base = static_cast<std::uint32_t>(nodes_.size());
    for (const Node& n : t.nodes()) {
      MNode m;
      m.plane = n.plane;
      m.neg = n.neg == kNoIndex ? kNoIndex : n.neg + base;
      m.pos = n.pos == kNoIndex ? kNoIndex : n.pos + base;
      m.label = n.label;
      nodes_.push_back(m);
    }
    // Faces: the node plane's universe polygon clipped by the ancestors (depth-first).
    struct Item {
      std::uint32_t node;
      std::size_t depth;
      std::uint32_t side_plane;
    };
    std::vector<std::uint32_t> path;
    std::vector<Item> stack{{t.root() + base, 0, kNoIndex}};
    while (!stack.empty()) {
      const Item it = stack.back();
      stack.pop_back();
      path.resize(it.depth);
      if (it.side_plane != kNoIndex) path.back() = it.side_plane;
      MNode& m = nodes_[it.node];
      if (m.leaf()) continue;
      Polygon f = universe_polygon(planes_, m.plane);
      for (auto h : path)
        if (!clip(planes_, f, h, -1)) throw Error("bsp: a node's plane misses its cell (internal error)");
      m.face = static_cast<std::uint32_t>(faces_.size());
      faces_.push_back(std::move(f));
      const std::uint32_t plane = m.plane, neg = m.neg, pos = m.pos;
      stack.push_back({neg, it.depth + 1, plane});
      stack.push_back({pos, it.depth + 1, plane ^ kFlip});
    }
    return t.root() + base;
  }

  std::uint32_t merge(std::uint32_t t1, std::uint32_t t2) {
    if (nodes_[t1].leaf() || nodes_[t2].leaf()) return cell_op(t1, t2);
    const std::uint32_t h = nodes_[t1].plane;
    const Polygon p = faces_[nodes_[t1].face];
    auto [n2, p2] = split_tree(t2, h, p);
    const std::uint32_t neg = merge(nodes_[t1].neg, n2);
    const std::uint32_t pos = merge(nodes_[t1].pos, p2);
    if (nodes_[neg].leaf() && nodes_[pos].leaf() && nodes_[neg].label == nodes_[pos].label) return neg;
    return make(h, nodes_[t1].face, neg, pos);
  }

  // Pushes a polygon down the tree at `root`: pieces lying on a node plane get the labels
  // of their front and back sides. keep(piece, front, back) decides what to do with them;
  // pieces that never lie on a plane get front = back = their leaf's label.
  template <typename F>
  void push(std::uint32_t root, Polygon poly, F&& keep) {
    struct Item {
      std::uint32_t node;
      Polygon poly;
      int mode;  // 0: no coplanar node yet, 1: front pass, 2: back pass
      Label front;
      std::uint32_t back_start;
    };
    std::vector<Item> stack;
    stack.push_back({root, std::move(poly), 0, Label::none, kNoIndex});
    std::vector<int> signs;
    while (!stack.empty()) {
      Item it = std::move(stack.back());
      stack.pop_back();
      for (;;) {
        const MNode& n = nodes_[it.node];
        if (n.leaf()) {
          if (it.mode == 0) {
            keep(it.poly, n.label, n.label);
            break;
          }
          if (it.mode == 1) {
            it.front = n.label;
            it.mode = 2;
            it.node = it.back_start;
            continue;
          }
          keep(it.poly, it.front, n.label);
          break;
        }
        const Side s = classify(planes_, it.poly, n.plane, &signs);
        if (s == Side::coplanar) {
          const bool same = planes_.normal_dot_sign(it.poly.support, n.plane) > 0;
          const std::uint32_t front = same ? n.pos : n.neg, back = same ? n.neg : n.pos;
          if (it.mode == 0) it.mode = 1, it.back_start = back;
          it.node = it.mode == 2 ? back : front;
        } else if (s == Side::negative) {
          it.node = n.neg;
        } else if (s == Side::positive) {
          it.node = n.pos;
        } else {
          Polygon a, b;
          split(planes_, it.poly, n.plane, signs, a, b);
          stack.push_back({n.pos, std::move(b), it.mode, it.front, it.back_start});
          it.poly = std::move(a);
          it.node = n.neg;
        }
      }
    }
  }

  std::size_t count_nodes(std::uint32_t root) const {
    std::size_t c = 0;
    std::vector<std::uint32_t> stack{root};
    while (!stack.empty()) {
      const std::uint32_t n = stack.back();
      stack.pop_back();
      ++c;
      if (!nodes_[n].leaf()) stack.push_back(nodes_[n].neg), stack.push_back(nodes_[n].pos);
    }
    return c;
  }

 private:
  std::uint32_t make(std::uint32_t plane, std::uint32_t face, std::uint32_t neg, std::uint32_t pos) {
    MNode m;
    m.plane = plane, m.face = face, m.neg = neg, m.pos = pos;
    nodes_.push_back(m);
    return static_cast<std::uint32_t>(nodes_.size() - 1);
  }
  std::uint32_t leaf(Label l) {
    MNode m;
    m.label = l;
    nodes_.push_back(m);
    return static_cast<std::uint32_t>(nodes_.size() - 1);
  }
  std::uint32_t complement(std::uint32_t t) {
    const MNode n = nodes_[t];
    if (n.leaf()) return leaf(n.label == Label::inside ? Label::outside : Label::inside);
    const std::uint32_t neg = complement(n.neg);
    const std::uint32_t pos = complement(n.pos);
    return make(n.plane, n.face, neg, pos);
  }
  bool inside(std::uint32_t t) const { return nodes_[t].label == Label::inside; }

  // The cell-op table of §3.3 (T1 a leaf), and its mirror for T2 a leaf.
  std::uint32_t cell_op(std::uint32_t t1, std::uint32_t t2) {
    if (nodes_[t1].leaf()) {
      const bool in = inside(t1);
      switch (op_) {
        case CsgOp::union_: return in ? t1 : t2;
        case CsgOp::intersection: return in ? t2 : t1;
        case CsgOp::difference: return in ? complement(t2) : t1;
        case CsgOp::xor_: return in ? complement(t2) : t2;
      }
    }
    const bool in = inside(t2);
    switch (op_) {
      case CsgOp::union_: return in ? t2 : t1;
      case CsgOp::intersection: return in ? t1 : t2;
      case CsgOp::difference: return in ? leaf(Label::outside) : t1;
      case CsgOp::xor_: return in ? complement(t1) : t1;
    }
    return t1;
  }

  // split-tree(T, H, P): P is H ∩ R(T) (positive area). Returns (T ∩ H-, T ∩ H+).
  std::pair<std::uint32_t, std::uint32_t> split_tree(std::uint32_t t, std::uint32_t h, const Polygon& p) {
    const MNode n = nodes_[t];
    if (n.leaf()) return {t, t};
    std::vector<int> signs;
    const Side s = classify(planes_, p, n.plane, &signs);
    if (s == Side::coplanar) {
      // "On": the same plane; anti-parallel swaps the children.
      if (planes_.normal_dot_sign(h, n.plane) > 0) return {n.neg, n.pos};
      return {n.pos, n.neg};
    }
    const Polygon face = faces_[n.face];  // a copy: the recursion below appends to faces_
    std::vector<int> fsigns;
    const Side fs = classify(planes_, face, h, &fsigns);
    if (s == Side::straddling) {
      // "Mixed": both children are cut.
      if (fs != Side::straddling) throw Error("bsp split-tree: inconsistent faces (internal error)");
      Polygon pn, pp, fn, fp;
      split(planes_, p, n.plane, signs, pn, pp);
      split(planes_, face, h, fsigns, fn, fp);
      const auto fni = static_cast<std::uint32_t>(faces_.size());
      faces_.push_back(std::move(fn));
      faces_.push_back(std::move(fp));
      auto [nn, np] = split_tree(n.neg, h, pn);
      auto [pn2, pp2] = split_tree(n.pos, h, pp);
      return {make(n.plane, fni, nn, pn2), make(n.plane, fni + 1, np, pp2)};
    }
    // P lies on one side of T's plane: only that child is cut; the other child's cell lies on
    // one side of H, the side of the node's face (Chin), which is not on H.
    if (fs == Side::straddling || fs == Side::coplanar) throw Error("bsp split-tree: inconsistent faces (internal error)");
    const bool other_neg = fs == Side::negative;
    if (s == Side::negative) {
      auto [a, b] = split_tree(n.neg, h, p);
      if (other_neg) return {make(n.plane, n.face, a, n.pos), b};
      return {a, make(n.plane, n.face, b, n.pos)};
    }
    auto [a, b] = split_tree(n.pos, h, p);
    if (other_neg) return {make(n.plane, n.face, n.neg, a), b};
    return {a, make(n.plane, n.face, n.neg, b)};
  }

  const PlaneSet& planes_;
  CsgOp op_;
  std::vector<MNode> nodes_;
  std::vector<Polygon> faces_;
};

namespace {

// Welds exact vertices, inserts T-junction vertices, fans the pieces.
Triangles to_mesh(const PlaneSet& planes, const Grid& grid, const std::vector<Polygon>& pieces, CsgStats& st) {
  struct V {
    Vertex v;
    std::array<double, 3> x;
    double rad;
  };
  std::vector<V> verts;
  std::vector<std::uint32_t> first(pieces.size() + 1, 0);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    first[i] = static_cast<std::uint32_t>(verts.size());
    const Polygon& f = pieces[i];
    for (std::size_t k = 0; k < f.size(); ++k) {
      V v{f.vertex(k), {}, 0};
      v.x = planes.point(v.v, &v.rad);
      verts.push_back(v);
    }
  }
  first[pieces.size()] = static_cast<std::uint32_t>(verts.size());
  auto same = [&](const V& a, const V& b) {
    if (a.v.point != kNoPoint && b.v.point != kNoPoint)
      return planes.integer_point(a.v.point) == planes.integer_point(b.v.point);
    const Vertex& t = a.v.point == kNoPoint ? a.v : b.v;  // a vertex given by its planes
    const Vertex& o = a.v.point == kNoPoint ? b.v : a.v;
    return planes.side(t.p, o) == 0 && planes.side(t.q, o) == 0 && planes.side(t.r, o) == 0;
  };
  // Weld: sweep in x with the error radii; union-find.
  std::vector<std::uint32_t> parent(verts.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::vector<std::uint32_t> order(verts.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return verts[a].x[0] - verts[a].rad < verts[b].x[0] - verts[b].rad; });
  for (std::size_t oi = 0; oi < order.size(); ++oi) {
    const V& a = verts[order[oi]];
    for (std::size_t oj = oi + 1; oj < order.size(); ++oj) {
      const V& b = verts[order[oj]];
      if (b.x[0] - b.rad > a.x[0] + a.rad) break;
      if (std::fabs(a.x[1] - b.x[1]) > a.rad + b.rad || std::fabs(a.x[2] - b.x[2]) > a.rad + b.rad) continue;
      const std::uint32_t ra = find(order[oi]), rb = find(order[oj]);
      if (ra == rb) continue;
      if (same(a, b)) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  // Welded vertices.
  std::vector<std::uint32_t> id(verts.size(), kNoIndex);
  std::vector<std::uint32_t> rep;  // welded id -> a vertex record
  for (std::uint32_t i = 0; i < verts.size(); ++i) {
    const std::uint32_t r = find(i);
    if (id[r] == kNoIndex) id[r] = static_cast<std::uint32_t>(rep.size()), rep.push_back(r);
    id[i] = id[r];
  }
  std::vector<double> wrad(rep.size(), 0);
  for (std::uint32_t i = 0; i < verts.size(); ++i) wrad[id[i]] = std::max(wrad[id[i]], verts[i].rad);
  std::vector<std::uint32_t> by_x(rep.size());
  std::iota(by_x.begin(), by_x.end(), 0u);
  std::sort(by_x.begin(), by_x.end(), [&](std::uint32_t a, std::uint32_t b) { return verts[rep[a]].x[0] < verts[rep[b]].x[0]; });
  std::vector<double> xs(by_x.size());
  double max_rad = 0;
  for (std::size_t i = 0; i < by_x.size(); ++i) xs[i] = verts[rep[by_x[i]]].x[0], max_rad = std::max(max_rad, wrad[by_x[i]]);

  Triangles out;
  out.vertices.reserve(rep.size());
  for (auto r : rep) out.vertices.push_back(grid.to_world(verts[r].x));
  std::vector<std::uint32_t> ring;
  std::vector<std::pair<double, std::uint32_t>> inserted;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Polygon& f = pieces[i];
    const std::size_t n = f.size();
    ring.clear();
    std::vector<int> side_has(n, 0);
    std::vector<std::size_t> corner_pos;
    for (std::size_t k = 0; k < n; ++k) {
      corner_pos.push_back(ring.size());
      const std::uint32_t a = first[i] + static_cast<std::uint32_t>(k);
      const std::uint32_t b = first[i] + static_cast<std::uint32_t>((k + 1) % n);
      ring.push_back(id[a]);
      const auto& pa = verts[a].x;
      const auto& pb = verts[b].x;
      const double r = std::max(verts[a].rad, verts[b].rad) + max_rad;
      const double x0 = std::min(pa[0], pb[0]) - r, x1 = std::max(pa[0], pb[0]) + r;
      inserted.clear();
      auto it = std::lower_bound(xs.begin(), xs.end(), x0);
      const double d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
      for (; it != xs.end() && *it <= x1; ++it) {
        const std::uint32_t w = by_x[static_cast<std::size_t>(it - xs.begin())];
        if (w == id[a] || w == id[b]) continue;
        const V& c = verts[rep[w]];
        bool in_box = true;
        for (int ax = 1; ax < 3; ++ax)
          in_box &= c.x[ax] >= std::min(pa[ax], pb[ax]) - r && c.x[ax] <= std::max(pa[ax], pb[ax]) + r;
        if (!in_box) continue;
        if (planes.side(f.support, c.v) != 0 || planes.side(f.edges[k], c.v) != 0) continue;
        if (planes.side(f.prev_edge(k), c.v) >= 0 || planes.side(f.edges[(k + 1) % n], c.v) >= 0) continue;
        const double t = (c.x[0] - pa[0]) * d[0] + (c.x[1] - pa[1]) * d[1] + (c.x[2] - pa[2]) * d[2];
        inserted.push_back({t, w});
      }
      if (!inserted.empty()) {
        std::sort(inserted.begin(), inserted.end());
        for (const auto& [t, w] : inserted) ring.push_back(w);
        st.t_junctions += inserted.size();
        side_has[k] = 1;
      }
    }
    std::size_t apex = n;
    for (std::size_t k = 0; k < n && apex == n; ++k)
      if (!side_has[k] && !side_has[(k + n - 1) % n]) apex = k;
    const std::size_t m = ring.size();
    if (apex < n) {
      const std::size_t s = corner_pos[apex];
      for (std::size_t j = 1; j + 1 < m; ++j)
        out.triangles.push_back({ring[s], ring[(s + j) % m], ring[(s + j + 1) % m]});
    } else {
      std::array<double, 3> c{0, 0, 0};
      for (std::size_t k = 0; k < n; ++k)
        for (int ax = 0; ax < 3; ++ax) c[ax] += verts[first[i] + k].x[ax] / static_cast<double>(n);
      const auto ci = static_cast<std::uint32_t>(out.vertices.size());
      out.vertices.push_back(grid.to_world(c));
      for (std::size_t j = 0; j < m; ++j) out.triangles.push_back({ci, ring[j], ring[(j + 1) % m]});
    }
  }
  return out;
}

}  // namespace

CsgResult csg(const Triangles& a, const Triangles& b, CsgOp op, const BuildOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  check_mesh(a.vertices, a.triangles, "csg: first mesh");
  check_mesh(b.vertices, b.triangles, "csg: second mesh");
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Triangles* m : {&a, &b})
    for (const auto& t : m->triangles)
      for (auto v : t) lo = lo.cwiseMin(m->vertices[v]), hi = hi.cwiseMax(m->vertices[v]);
  const Grid grid = Grid::fit(lo, hi);
  auto planes = std::make_shared<PlaneSet>();
  const BspTree ta(planes, grid, a.vertices, a.triangles, options);
  const BspTree tb(planes, grid, b.vertices, b.triangles, options);
  Merger m(*planes, op);
  const std::uint32_t ra = m.add_tree(ta);
  const std::uint32_t rb = m.add_tree(tb);
  const std::uint32_t root = m.merge(ra, rb);

  CsgResult res;
  std::vector<Polygon> pieces;
  auto emit = [&](const Polygon& p, Label front, Label back) {
    if (front == Label::outside && back == Label::inside) {
      pieces.push_back(p);
    } else if (front == Label::inside && back == Label::outside) {
      pieces.push_back(p.reversed());
    }
  };
  for (const auto& f : ta.fragments()) m.push(root, f, emit);
  for (const auto& f : tb.fragments())
    m.push(ra, f, [&](const Polygon& p, Label front, Label back) {
      if (front == back) m.push(root, p, emit);  // not on A's boundary (there A's fragments decide)
    });
  res.stats.volume_a = signed_volume(ta.fragment_mesh());
  res.stats.volume_b = signed_volume(tb.fragment_mesh());
  res.stats.bsp_nodes = m.count_nodes(root);
  res.stats.pieces = pieces.size();
  res.mesh = to_mesh(*planes, grid, pieces, res.stats);
  res.stats.vertices = res.mesh.vertices.size();
  res.stats.triangles = res.mesh.triangles.size();
  res.stats.closed = is_closed(res.mesh);
  res.stats.volume = signed_volume(res.mesh);
  res.stats.compute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace geods::bsp
