#include "geods/bsp/csg.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
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

CsgMethod parse_csg_method(std::string_view name) {
  if (name == "local") return CsgMethod::local;
  if (name == "bsp_merge") return CsgMethod::bsp_merge;
  throw Error("unknown boolean method '" + std::string(name) + "' (local or bsp_merge)");
}

std::string_view csg_method_name(CsgMethod m) { return m == CsgMethod::local ? "local" : "bsp_merge"; }

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
  // At every vertex, the multiset of the ends of its outgoing edges equals that of the
  // starts of its incoming ones.
  std::uint32_t nv = 0;
  for (const auto& t : m.triangles) nv = std::max({nv, t[0] + 1, t[1] + 1, t[2] + 1});
  std::vector<std::uint32_t> out_start(nv + 1, 0), in_start(nv + 1, 0);
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++out_start[t[k] + 1], ++in_start[t[(k + 1) % 3] + 1];
  for (std::uint32_t v = 0; v < nv; ++v) {
    if (out_start[v + 1] != in_start[v + 1]) return false;
    out_start[v + 1] += out_start[v], in_start[v + 1] += in_start[v];
  }
  std::vector<std::uint32_t> outs(out_start[nv]), ins(in_start[nv]);
  {
    std::vector<std::uint32_t> fo(out_start.begin(), out_start.end() - 1), fi(in_start.begin(), in_start.end() - 1);
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t u = t[k], v = t[(k + 1) % 3];
        outs[fo[u]++] = v;
        ins[fi[v]++] = u;
      }
  }
  for (std::uint32_t v = 0; v < nv; ++v) {
    std::sort(outs.begin() + out_start[v], outs.begin() + out_start[v + 1]);
    std::sort(ins.begin() + in_start[v], ins.begin() + in_start[v + 1]);
  }
  return outs == ins;
}

// Pushes a polygon down the tree at `root` (nodes with plane, neg, pos, label, leaf()):
// pieces lying on a node plane get the labels of their front and back sides.
// keep(piece, front, back) decides what to do with them; pieces that never lie on a plane
// get front = back = their leaf's label.
template <typename Nodes, typename F>
void push_polygon(const PlaneSet& planes, const Nodes& nodes, std::uint32_t root, Polygon poly, F&& keep) {
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
      const auto& n = nodes[it.node];
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
      const Side s = classify(planes, it.poly, n.plane, &signs);
      if (s == Side::coplanar) {
        const bool same = planes.normal_dot_sign(it.poly.support, n.plane) > 0;
        const std::uint32_t front = same ? n.pos : n.neg, back = same ? n.neg : n.pos;
        if (it.mode == 0) it.mode = 1, it.back_start = back;
        it.node = it.mode == 2 ? back : front;
      } else if (s == Side::negative) {
        it.node = n.neg;
      } else if (s == Side::positive) {
        it.node = n.pos;
      } else {
        Polygon a, b;
        split(planes, it.poly, n.plane, signs, a, b);
        stack.push_back({n.pos, std::move(b), it.mode, it.front, it.back_start});
        it.poly = std::move(a);
        it.node = n.neg;
      }
    }
  }
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

  template <typename F>
  void push(std::uint32_t root, Polygon poly, F&& keep) {
    push_polygon(planes_, nodes_, root, std::move(poly), keep);
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

// Welds exact vertices, inserts T-junction vertices, fans the pieces and the whole
// triangles (snapped point ids, in output orientation). The corners of whole triangles lie
// inside no other piece's side (for inputs without T-junctions or self-intersections), so
// they are not searched for on the sides; a whole triangle's planes are made only if a
// vertex may lie on one of its sides.
Triangles to_mesh(PlaneSet& planes, const Grid& grid, const std::vector<Polygon>& pieces, CsgStats& st,
                  const std::vector<std::array<std::uint32_t, 3>>& wholes = {}) {
  struct V {
    Vertex v;
    std::array<double, 3> x;
    double rad;
  };
  std::vector<V> verts;
  const std::size_t np = pieces.size(), total = np + wholes.size();
  std::vector<std::uint32_t> first(total + 1, 0);
  verts.reserve(3 * total);
  for (std::size_t i = 0; i < total; ++i) {
    first[i] = static_cast<std::uint32_t>(verts.size());
    if (i < np) {
      const Polygon& f = pieces[i];
      for (std::size_t k = 0; k < f.size(); ++k) {
        V v{f.vertex(k), {}, 0};
        v.x = planes.point(v.v, &v.rad);
        verts.push_back(v);
      }
    } else {
      for (auto p : wholes[i - np]) {
        V v{Vertex{0, 0, 0, p}, {}, 0};
        v.x = planes.point(v.v, &v.rad);
        verts.push_back(v);
      }
    }
  }
  first[total] = static_cast<std::uint32_t>(verts.size());
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
  // Snapped input points (and vertices given by planes whose box of error holds one
  // integer point, at most 8 candidates when the error radius is below 1/2): by their
  // integer coordinates. The other vertices given by planes: a sweep in x among themselves.
  auto key_of = [](const std::array<std::int64_t, 3>& q) {
    return (static_cast<std::uint64_t>(q[0] + kUniverse) << 42) | (static_cast<std::uint64_t>(q[1] + kUniverse) << 21) |
           static_cast<std::uint64_t>(q[2] + kUniverse);
  };
  std::unordered_map<std::uint64_t, std::uint32_t> at_point;
  at_point.reserve(verts.size() / 4);
  std::vector<std::uint32_t> order;
  bool wide = false;
  std::vector<std::uint32_t> rec_of_point(planes.point_count(), kNoIndex);  // a record of each point id
  for (std::uint32_t i = 0; i < verts.size(); ++i) {
    if (verts[i].v.point != kNoPoint) {
      std::uint32_t& r = rec_of_point[verts[i].v.point];
      if (r == kNoIndex) r = at_point.try_emplace(key_of(planes.integer_point(verts[i].v.point)), i).first->second;
      if (r != i) parent[i] = find(r);
    } else {
      order.push_back(i);
      wide |= !(verts[i].rad < 0.5);
    }
  }
  if (wide) {  // a vertex of large rounding error: the sweep over every vertex
    order.resize(verts.size());
    std::iota(order.begin(), order.end(), 0u);
  } else {
    for (auto i : order) {
      const V& a = verts[i];
      std::array<std::int64_t, 3> lo, hi;
      for (int ax = 0; ax < 3; ++ax)
        lo[ax] = static_cast<std::int64_t>(std::ceil(a.x[ax] - a.rad)), hi[ax] = static_cast<std::int64_t>(std::floor(a.x[ax] + a.rad));
      for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
            if (std::max({std::abs(x), std::abs(y), std::abs(z)}) > kUniverse) continue;
            auto it = at_point.find(key_of({x, y, z}));
            if (it == at_point.end()) continue;
            const std::uint32_t ra = find(i), rb = find(it->second);
            if (ra != rb && same(a, verts[it->second])) parent[std::max(ra, rb)] = std::min(ra, rb);
          }
    }
  }
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
  // The welded vertices in a uniform grid (cells about an average piece edge wide) for
  // the T-junction search.
  double max_rad = 0;
  for (double r : wrad) max_rad = std::max(max_rad, r);
  std::array<double, 3> glo{0, 0, 0}, ghi{0, 0, 0};
  if (!rep.empty()) glo = ghi = verts[rep[0]].x;
  for (auto r : rep)
    for (int ax = 0; ax < 3; ++ax) glo[ax] = std::min(glo[ax], verts[r].x[ax]), ghi[ax] = std::max(ghi[ax], verts[r].x[ax]);
  double edge_sum = 0;
  for (std::size_t i = 0; i < total; ++i)
    for (std::uint32_t k = first[i]; k < first[i + 1]; ++k) {
      const auto& pa = verts[k].x;
      const auto& pb = verts[k + 1 < first[i + 1] ? k + 1 : first[i]].x;
      edge_sum += std::max({std::fabs(pa[0] - pb[0]), std::fabs(pa[1] - pb[1]), std::fabs(pa[2] - pb[2])});
    }
  double cell = std::max(1.0, edge_sum / std::max<double>(1.0, static_cast<double>(verts.size())));
  std::array<std::size_t, 3> gn{1, 1, 1};
  for (;;) {
    for (int ax = 0; ax < 3; ++ax) gn[ax] = static_cast<std::size_t>((ghi[ax] - glo[ax]) / cell) + 1;
    if (gn[0] * gn[1] * gn[2] <= 2 * rep.size() + 8) break;
    cell *= 1.5;
  }
  auto cell_of = [&](double x, int ax) {
    const double c = std::floor((x - glo[ax]) / cell);
    return static_cast<std::size_t>(std::clamp(c, 0.0, static_cast<double>(gn[ax] - 1)));
  };
  std::vector<std::uint32_t> cstart(gn[0] * gn[1] * gn[2] + 1, 0), citems(rep.size());
  auto cell_index = [&](const std::array<double, 3>& x) {
    return (cell_of(x[2], 2) * gn[1] + cell_of(x[1], 1)) * gn[0] + cell_of(x[0], 0);
  };
  std::vector<char> candidate(rep.size(), 0);
  for (std::uint32_t k = 0; k < first[np]; ++k) candidate[id[k]] = 1;
  for (std::uint32_t w = 0; w < rep.size(); ++w)
    if (candidate[w]) ++cstart[cell_index(verts[rep[w]].x) + 1];
  for (std::size_t c = 1; c < cstart.size(); ++c) cstart[c] += cstart[c - 1];
  {
    std::vector<std::uint32_t> fill(cstart.begin(), cstart.end() - 1);
    for (std::uint32_t w = 0; w < rep.size(); ++w)
      if (candidate[w]) citems[fill[cell_index(verts[rep[w]].x)]++] = w;
  }

  Triangles out;
  out.vertices.reserve(rep.size());
  for (auto r : rep) out.vertices.push_back(grid.to_world(verts[r].x));
  std::vector<std::uint32_t> ring;
  std::vector<std::pair<double, std::uint32_t>> inserted;
  std::vector<int> side_has;
  std::vector<std::size_t> corner_pos;
  Polygon tri;  // a whole triangle's planes, when needed
  for (std::size_t i = 0; i < total; ++i) {
    const bool whole = i >= np;
    bool made = false;
    const Polygon& f = whole ? tri : pieces[i];
    const std::size_t n = first[i + 1] - first[i];
    ring.clear();
    side_has.assign(n, 0);
    corner_pos.clear();
    for (std::size_t k = 0; k < n; ++k) {
      corner_pos.push_back(ring.size());
      const std::uint32_t a = first[i] + static_cast<std::uint32_t>(k);
      const std::uint32_t b = first[i] + static_cast<std::uint32_t>((k + 1) % n);
      ring.push_back(id[a]);
      const auto& pa = verts[a].x;
      const auto& pb = verts[b].x;
      const double r = std::max(verts[a].rad, verts[b].rad) + max_rad;
      inserted.clear();
      const double d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
      std::array<double, 3> elo, ehi;
      std::array<std::size_t, 3> c0, c1;
      for (int ax = 0; ax < 3; ++ax) {
        elo[ax] = std::min(pa[ax], pb[ax]) - r, ehi[ax] = std::max(pa[ax], pb[ax]) + r;
        c0[ax] = cell_of(elo[ax], ax), c1[ax] = cell_of(ehi[ax], ax);
      }
      for (std::size_t cz = c0[2]; cz <= c1[2]; ++cz)
        for (std::size_t cy = c0[1]; cy <= c1[1]; ++cy)
          for (std::size_t cx = c0[0]; cx <= c1[0]; ++cx) {
            const std::size_t ci = (cz * gn[1] + cy) * gn[0] + cx;
            for (std::uint32_t e = cstart[ci]; e < cstart[ci + 1]; ++e) {
              const std::uint32_t w = citems[e];
              if (w == id[a] || w == id[b]) continue;
              const V& c = verts[rep[w]];
              bool in_box = true;
              for (int ax = 0; ax < 3; ++ax) in_box &= c.x[ax] >= elo[ax] && c.x[ax] <= ehi[ax];
              if (!in_box) continue;
              if (whole && !made) {
                const auto& ids = wholes[i - np];
                triangle_polygon(planes, planes.integer_point(ids[0]), planes.integer_point(ids[1]),
                                 planes.integer_point(ids[2]), ids, tri);
                made = true;
              }
              if (planes.side(f.support, c.v) != 0 || planes.side(f.edges[k], c.v) != 0) continue;
              if (planes.side(f.prev_edge(k), c.v) >= 0 || planes.side(f.edges[(k + 1) % n], c.v) >= 0) continue;
              const double t = (c.x[0] - pa[0]) * d[0] + (c.x[1] - pa[1]) * d[1] + (c.x[2] - pa[2]) * d[2];
              inserted.push_back({t, w});
            }
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

namespace {

bool member(CsgOp op, bool a, bool b) {
  switch (op) {
    case CsgOp::union_: return a || b;
    case CsgOp::intersection: return a && b;
    case CsgOp::difference: return a && !b;
    case CsgOp::xor_: return a != b;
  }
  return false;
}

// Snapped point `i` of the plane set in world coordinates (exact: grid points are doubles).
Vec3d world_point(const PlaneSet& planes, const Grid& grid, std::uint32_t i) {
  const auto& q = planes.integer_point(i);
  return grid.to_world({static_cast<double>(q[0]), static_cast<double>(q[1]), static_cast<double>(q[2])});
}

// One operand snapped: its non-degenerate triangles as polygons, their integer boxes and
// their corners' point ids (points with equal coordinates share one id).
struct Operand {
  std::vector<Polygon> tri;  // made when first needed (polygon())
  std::vector<std::array<std::int64_t, 3>> lo, hi;
  std::vector<std::array<std::uint32_t, 3>> corner;

  const Polygon& polygon(PlaneSet& planes, std::uint32_t t) {
    Polygon& p = tri[t];
    if (p.edges.empty()) {
      const auto& c = corner[t];
      triangle_polygon(planes, planes.integer_point(c[0]), planes.integer_point(c[1]), planes.integer_point(c[2]), c, p);
    }
    return p;
  }
};

Operand snap_operand(PlaneSet& planes, const Grid& grid, const Triangles& m,
                     std::unordered_map<std::uint64_t, std::uint32_t>& point_of) {
  Operand op;
  op.tri.reserve(m.triangles.size()), op.lo.reserve(m.triangles.size()), op.hi.reserve(m.triangles.size());
  op.corner.reserve(m.triangles.size());
  std::vector<std::uint32_t> id(m.vertices.size(), kNoPoint);
  auto point = [&](std::uint32_t v) {
    if (id[v] == kNoPoint) {
      const auto q = grid.snap(m.vertices[v]);
      const std::uint64_t key = (static_cast<std::uint64_t>(q[0] + kUniverse) << 42) |
                                (static_cast<std::uint64_t>(q[1] + kUniverse) << 21) |
                                static_cast<std::uint64_t>(q[2] + kUniverse);
      auto [it, fresh] = point_of.try_emplace(key, 0u);
      if (fresh) it->second = planes.add_point(q);
      id[v] = it->second;
    }
    return id[v];
  };
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const std::array<std::uint32_t, 3> c = {point(m.triangles[t][0]), point(m.triangles[t][1]), point(m.triangles[t][2])};
    const auto& p0 = planes.integer_point(c[0]);
    const auto& p1 = planes.integer_point(c[1]);
    const auto& p2 = planes.integer_point(c[2]);
    const Plane support = PlaneSet::through(p0, p1, p2);
    if (support.a == 0 && support.b == 0 && support.c == 0) continue;  // degenerate after snapping
    std::array<std::int64_t, 3> lo, hi;
    for (int k = 0; k < 3; ++k) lo[k] = std::min({p0[k], p1[k], p2[k]}), hi[k] = std::max({p0[k], p1[k], p2[k]});
    op.tri.emplace_back();
    op.tri.back().source = static_cast<std::uint32_t>(t);
    op.lo.push_back(lo);
    op.hi.push_back(hi);
    op.corner.push_back(c);
  }
  if (op.tri.empty()) throw Error("csg: every triangle of an operand is degenerate (at the grid's resolution)");
  // Pairs of opposite triangles on the same points (a part thinner than the grid's step,
  // flattened by the snapping) bound no volume: both go (their edges cancel).
  // Keys: the corners rotated to start at the smallest point id; a triangle and its
  // opposite have keys (a, b, c) and (a, c, b).
  struct Key {
    std::uint64_t ab;
    std::uint32_t c, t;
    bool operator<(const Key& o) const { return ab != o.ab ? ab < o.ab : (c != o.c ? c < o.c : t < o.t); }
  };
  auto key = [](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t t) {
    if (b < a && b < c) return Key{(std::uint64_t{b} << 32) | c, a, t};
    if (c < a && c < b) return Key{(std::uint64_t{c} << 32) | a, b, t};
    return Key{(std::uint64_t{a} << 32) | b, c, t};
  };
  std::vector<Key> keys(op.tri.size());
  for (std::uint32_t t = 0; t < op.tri.size(); ++t) keys[t] = key(op.corner[t][0], op.corner[t][1], op.corner[t][2], t);
  std::sort(keys.begin(), keys.end());
  std::vector<char> drop(op.tri.size(), 0);
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j].ab == keys[i].ab && keys[j].c == keys[i].c) ++j;
    const auto a = static_cast<std::uint32_t>(keys[i].ab >> 32), b = static_cast<std::uint32_t>(keys[i].ab), c = keys[i].c;
    if (b < c) {  // each pair of opposite groups once
      const Key r{(std::uint64_t{a} << 32) | c, b, 0};
      auto k = std::lower_bound(keys.begin(), keys.end(), r);
      for (std::size_t m = i; m < j && k != keys.end() && k->ab == r.ab && k->c == r.c; ++m, ++k)
        drop[keys[m].t] = drop[k->t] = 1, dropped += 2;
    }
    i = j;
  }
  if (dropped > 0) {
    Operand kept;
    for (std::size_t t = 0; t < op.tri.size(); ++t)
      if (!drop[t]) {
        kept.tri.push_back(std::move(op.tri[t]));
        kept.lo.push_back(op.lo[t]), kept.hi.push_back(op.hi[t]), kept.corner.push_back(op.corner[t]);
      }
    op = std::move(kept);
  }
  return op;
}

// A uniform grid over integer boxes: which boxes may meet a query box.
class BoxGrid {
 public:
  explicit BoxGrid(const Operand& o) : o_(o) {
    if (o.lo.empty()) return;  // n_ = 0: every query is empty
    lo_ = o.lo[0];
    std::array<std::int64_t, 3> hi = o.hi[0];
    double ext = 0;
    for (std::size_t t = 0; t < o.lo.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        lo_[k] = std::min(lo_[k], o.lo[t][k]), hi[k] = std::max(hi[k], o.hi[t][k]);
        ext += static_cast<double>(o.hi[t][k] - o.lo[t][k]);
      }
    ext /= 3.0 * static_cast<double>(o.lo.size());
    cell_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(2 * ext));
    for (int k = 0; k < 3; ++k)
      while ((hi[k] - lo_[k]) / cell_ + 1 > 256) cell_ *= 2;
    for (int k = 0; k < 3; ++k) n_[k] = static_cast<int>((hi[k] - lo_[k]) / cell_ + 1);
    start_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2] + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (std::uint32_t t = 0; t < o.lo.size(); ++t) {
        std::array<int, 3> a, b;
        if (!range(o.lo[t], o.hi[t], a, b)) continue;
        for (int z = a[2]; z <= b[2]; ++z)
          for (int y = a[1]; y <= b[1]; ++y)
            for (int x = a[0]; x <= b[0]; ++x) {
              const std::size_t c = cell(x, y, z);
              if (pass == 0) ++start_[c + 1];
              else items_[fill_[c]++] = t;
            }
      }
      if (pass == 0) {
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        items_.resize(start_.back());
        fill_.assign(start_.begin(), start_.end() - 1);
      }
    }
    stamp_.assign(o.lo.size(), 0);
  }

  // Boxes meeting [lo, hi] (closed), each once.
  void query(const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& hi, std::vector<std::uint32_t>& out) {
    out.clear();
    std::array<int, 3> a, b;
    if (!range(lo, hi, a, b)) return;
    ++now_;
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) {
          const std::size_t c = cell(x, y, z);
          for (std::uint32_t i = start_[c]; i < start_[c + 1]; ++i) {
            const std::uint32_t t = items_[i];
            if (stamp_[t] == now_) continue;
            stamp_[t] = now_;
            bool meet = true;
            for (int k = 0; k < 3; ++k) meet &= o_.lo[t][k] <= hi[k] && o_.hi[t][k] >= lo[k];
            if (meet) out.push_back(t);
          }
        }
  }

 private:
  bool range(const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& hi, std::array<int, 3>& a,
             std::array<int, 3>& b) const {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t l = (lo[k] - lo_[k]) / cell_ - (lo[k] < lo_[k]), h = (hi[k] - lo_[k]) / cell_;
      if (h < 0 || l >= n_[k]) return false;
      a[k] = static_cast<int>(std::max<std::int64_t>(l, 0));
      b[k] = static_cast<int>(std::min<std::int64_t>(h, n_[k] - 1));
    }
    return true;
  }
  std::size_t cell(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * n_[1] + static_cast<std::size_t>(y)) * n_[0] + static_cast<std::size_t>(x);
  }

  const Operand& o_;
  std::array<std::int64_t, 3> lo_{};
  std::int64_t cell_ = 1;
  std::array<int, 3> n_{};
  std::vector<std::uint32_t> start_, items_, fill_, stamp_;
  std::uint32_t now_ = 0;
};

struct LocalNode {
  std::uint32_t plane = kNoIndex;
  std::uint32_t neg = kNoIndex, pos = kNoIndex;
  Label label = Label::none;
  bool leaf() const { return plane == kNoIndex; }
};

// Auto-partition of polygons lying in one cell: at each node the plane of the candidate
// (of the first few polygons) that splits the fewest; a child with no polygon left is a
// leaf, inside behind the node's polygon and outside in front of it.
void build_local(const PlaneSet& planes, std::vector<Polygon> polys, std::vector<LocalNode>& nodes) {
  nodes.assign(1, LocalNode{});
  struct Task {
    std::uint32_t node;
    std::vector<Polygon> polys;
  };
  std::vector<Task> stack;
  stack.push_back({0, std::move(polys)});
  std::vector<int> signs;
  while (!stack.empty()) {
    Task task = std::move(stack.back());
    stack.pop_back();
    auto& ps = task.polys;
    std::uint32_t plane = ps[0].support;
    if (ps.size() > 2) {
      std::size_t best = std::numeric_limits<std::size_t>::max();
      for (std::size_t c = 0; c < std::min<std::size_t>(ps.size(), 4); ++c) {
        std::size_t cuts = 0;
        for (const auto& q : ps) cuts += classify(planes, q, ps[c].support) == Side::straddling;
        if (cuts < best) best = cuts, plane = ps[c].support;
      }
    }
    Task negt{kNoIndex, {}}, post{kNoIndex, {}};
    for (auto& q : ps) {
      const Side s = classify(planes, q, plane, &signs);
      if (s == Side::negative) {
        negt.polys.push_back(std::move(q));
      } else if (s == Side::positive) {
        post.polys.push_back(std::move(q));
      } else if (s == Side::straddling) {
        Polygon x, y;
        split(planes, q, plane, signs, x, y);
        negt.polys.push_back(std::move(x));
        post.polys.push_back(std::move(y));
      }
    }
    nodes[task.node].plane = plane;
    for (int side : {-1, 1}) {
      Task& t = side < 0 ? negt : post;
      const auto child = static_cast<std::uint32_t>(nodes.size());
      nodes.emplace_back();
      (side < 0 ? nodes[task.node].neg : nodes[task.node].pos) = child;
      if (t.polys.empty()) {
        nodes[child].label = side < 0 ? Label::inside : Label::outside;
      } else {
        t.node = child;
        stack.push_back(std::move(t));
      }
    }
  }
}

// Label of a snapped point that lies off the surface (a point on a node plane may go
// either way: every point near it has its label).
Label locate(const PlaneSet& planes, const std::vector<LocalNode>& nodes, std::uint32_t point) {
  const Vertex v{0, 0, 0, point};
  std::uint32_t n = 0;
  while (!nodes[n].leaf()) n = planes.side(nodes[n].plane, v) > 0 ? nodes[n].pos : nodes[n].neg;
  return nodes[n].label;
}

// The pieces of operand x (is_a: x is A) that bound the result, y the other operand: the
// pieces of the cut triangles into pieces, the triangles kept whole (index, +1 as they are or
// -1 reversed) into kept.
void local_pieces(PlaneSet& planes, const std::shared_ptr<PlaneSet>& shared, const Grid& grid, Operand& x,
                  Operand& y, bool is_a, CsgOp op, const BuildOptions& options,
                  std::vector<Polygon>& pieces, std::vector<std::pair<std::uint32_t, int>>& kept, CsgStats& st) {
  BoxGrid boxes(y);
  const std::size_t n = x.tri.size();
  // Cells: the triangle's box grown by one step; the other operand's triangles clipped to it.
  std::vector<std::vector<Polygon>> local(n);
  std::vector<std::uint32_t> cand;
  std::vector<char> touched(n, 0);
  for (std::size_t t = 0; t < n; ++t) {
    std::array<std::int64_t, 3> lo = x.lo[t], hi = x.hi[t];
    for (int k = 0; k < 3; ++k) --lo[k], ++hi[k];
    boxes.query(lo, hi, cand);
    if (cand.empty()) continue;
    std::array<std::uint32_t, 6> cell;
    for (int k = 0; k < 3; ++k) {
      Plane up, down;  // x_k <= hi_k, x_k >= lo_k
      (k == 0 ? up.a : k == 1 ? up.b : up.c) = 1;
      up.d = -hi[k];
      (k == 0 ? down.a : k == 1 ? down.b : down.c) = -1;
      down.d = lo[k];
      cell[2 * k] = planes.add(up);
      cell[2 * k + 1] = planes.add(down);
    }
    for (auto c : cand) {
      Polygon p = y.polygon(planes, c);
      bool ok = true;
      for (int k = 0; k < 6 && ok; ++k) ok = clip(planes, p, cell[k], -1);
      if (ok) local[t].push_back(std::move(p));
    }
    touched[t] = !local[t].empty();
  }
  // Components of the untouched triangles (through shared points); each is one label.
  std::vector<std::uint32_t> comp(planes.point_count(), kNoIndex);  // point -> union-find index
  std::vector<std::uint32_t> parent;
  auto find = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto node_of = [&](std::uint32_t p) {
    if (comp[p] == kNoIndex) comp[p] = static_cast<std::uint32_t>(parent.size()), parent.push_back(comp[p]);
    return comp[p];
  };
  for (std::size_t t = 0; t < n; ++t)
    if (!touched[t]) {
      const std::uint32_t r0 = find(node_of(x.corner[t][0]));
      for (int k = 1; k < 3; ++k) {
        const std::uint32_t r = find(node_of(x.corner[t][k]));
        if (r != r0) parent[r] = r0;
      }
    }
  std::vector<Label> comp_label(parent.size(), Label::none);

  // +1: keep the piece as it is, -1: reversed, 0: drop it.
  auto orientation = [&](Label front, Label back) {
    bool fin, bin;
    if (is_a) {
      fin = member(op, false, front == Label::inside);
      bin = member(op, true, back == Label::inside);
    } else {
      if (front != back) return 0;  // on A's boundary: A's pieces decide
      fin = member(op, front == Label::inside, false);
      bin = member(op, front == Label::inside, true);
    }
    return !fin && bin ? 1 : (fin && !bin ? -1 : 0);
  };
  auto emit = [&](const Polygon& p, Label front, Label back) {
    const int o = orientation(front, back);
    if (o > 0) pieces.push_back(p);
    else if (o < 0) pieces.push_back(p.reversed());
  };
  std::vector<LocalNode> nodes;
  for (std::size_t t = 0; t < n; ++t) {
    if (!touched[t]) continue;
    build_local(planes, std::move(local[t]), nodes);
    local[t] = {};
    st.bsp_nodes += nodes.size();
    for (auto p : x.corner[t]) {
      if (comp[p] == kNoIndex) continue;
      const std::uint32_t r = find(comp[p]);
      if (comp_label[r] == Label::none) comp_label[r] = locate(planes, nodes, p);
    }
    push_polygon(planes, nodes, 0, x.polygon(planes, static_cast<std::uint32_t>(t)), emit);
  }
  std::unique_ptr<BspTree> whole;  // of y, for components far from it
  for (std::size_t t = 0; t < n; ++t) {
    if (touched[t]) continue;
    const std::uint32_t r = find(comp[x.corner[t][0]]);
    if (comp_label[r] == Label::none) {
      if (y.tri.empty()) {  // y is empty at the grid's resolution
        comp_label[r] = Label::outside;
      } else if (!whole) {
        // The BSP of y as snapped (flattened parts removed): its points are exact in world coordinates.
        Triangles ym;
        for (std::uint32_t i = 0; i < planes.point_count(); ++i) ym.vertices.push_back(world_point(planes, grid, i));
        ym.triangles = y.corner;
        whole = std::make_unique<BspTree>(shared, grid, ym.vertices, ym.triangles, options);
      }
    }
    if (comp_label[r] == Label::none) {
      const int s = whole->classify(world_point(planes, grid, x.corner[t][0]));
      if (s == 0) throw Error("csg: a vertex off the other surface classified on it (internal error)");
      comp_label[r] = s < 0 ? Label::inside : Label::outside;
    }
    if (const int o = orientation(comp_label[r], comp_label[r])) kept.push_back({static_cast<std::uint32_t>(t), o});
  }
}

double operand_volume(const PlaneSet& planes, const Grid& grid, const Operand& o) {
  double v = 0;
  for (const auto& c : o.corner) {
    Vec3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = world_point(planes, grid, c[k]);
    v += p[0].dot(p[1].cross(p[2]));
  }
  return v / 6;
}

}  // namespace

CsgResult csg(const Triangles& a, const Triangles& b, CsgOp op, const BuildOptions& options, CsgMethod method) {
  const auto t0 = std::chrono::steady_clock::now();
  check_mesh(a.vertices, a.triangles, "csg: first mesh");
  check_mesh(b.vertices, b.triangles, "csg: second mesh");
  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Triangles* m : {&a, &b})
    for (const auto& t : m->triangles)
      for (auto v : t) lo = lo.cwiseMin(m->vertices[v]), hi = hi.cwiseMax(m->vertices[v]);
  const Grid grid = Grid::fit(lo, hi);
  auto planes = std::make_shared<PlaneSet>();
  CsgResult res;
  std::vector<Polygon> pieces;
  std::vector<std::array<std::uint32_t, 3>> wholes;  // input triangles kept whole (local method)
  if (method == CsgMethod::local) {
    std::unordered_map<std::uint64_t, std::uint32_t> point_of;
    planes->reserve(6 + 10 * (a.triangles.size() + b.triangles.size()), a.vertices.size() + b.vertices.size());
    Operand oa = snap_operand(*planes, grid, a, point_of);
    Operand ob = snap_operand(*planes, grid, b, point_of);
    std::vector<std::pair<std::uint32_t, int>> kept_a, kept_b;
    local_pieces(*planes, planes, grid, oa, ob, true, op, options, pieces, kept_a, res.stats);
    local_pieces(*planes, planes, grid, ob, oa, false, op, options, pieces, kept_b, res.stats);
    res.stats.volume_a = operand_volume(*planes, grid, oa);
    res.stats.volume_b = operand_volume(*planes, grid, ob);
    for (auto [o, kept] : {std::pair{&oa, &kept_a}, std::pair{&ob, &kept_b}})
      for (auto [t, orient] : *kept) {
        const auto& c = o->corner[t];
        wholes.push_back(orient > 0 ? c : std::array<std::uint32_t, 3>{c[0], c[2], c[1]});
      }
  } else {
    const BspTree ta(planes, grid, a.vertices, a.triangles, options);
    const BspTree tb(planes, grid, b.vertices, b.triangles, options);
    Merger m(*planes, op);
    const std::uint32_t ra = m.add_tree(ta);
    const std::uint32_t rb = m.add_tree(tb);
    const std::uint32_t root = m.merge(ra, rb);
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
  }
  res.stats.pieces = pieces.size() + wholes.size();
  res.mesh = to_mesh(*planes, grid, pieces, res.stats, wholes);
  res.stats.vertices = res.mesh.vertices.size();
  res.stats.triangles = res.mesh.triangles.size();
  res.stats.closed = is_closed(res.mesh);
  res.stats.volume = signed_volume(res.mesh);
  res.stats.compute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace geods::bsp
