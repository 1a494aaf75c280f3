// Collision and distance queries between two CollisionMeshes: the
// simultaneous traversal of their hierarchies on bvh::traverse, one volume
// tester per bounding volume, exact triangle tests at the leaves.
#include "geods/collide/collide.hpp"
#include "geods/collide/incremental.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>

#include "geods/bvh/traversal.hpp"
#include "geods/collide/triangle_pair.hpp"
#include "geods/core/error.hpp"

namespace geods::collide {

namespace {
constexpr std::pair<std::string_view, CollisionVolume> kVolumes[] = {
    {"aabb", CollisionVolume::aabb},     {"sphere", CollisionVolume::sphere}, {"kdop6", CollisionVolume::kdop6},
    {"kdop14", CollisionVolume::kdop14}, {"kdop18", CollisionVolume::kdop18}, {"kdop26", CollisionVolume::kdop26},
    {"obb", CollisionVolume::obb},       {"obb_hull", CollisionVolume::obb_hull},
    {"boxtree", CollisionVolume::boxtree}, {"rss", CollisionVolume::rss}};
constexpr std::pair<std::string_view, DescendRule> kRules[] = {{"larger", DescendRule::larger},
                                                               {"count", DescendRule::count},
                                                               {"a_first", DescendRule::a_first},
                                                               {"b_first", DescendRule::b_first}};
constexpr std::pair<std::string_view, CollideMode> kModes[] = {{"first", CollideMode::first},
                                                               {"all", CollideMode::all}};

template <typename E, std::size_t N>
E parse_name(const std::pair<std::string_view, E> (&table)[N], std::string_view name, const char* what) {
  std::string names;
  for (const auto& [n, e] : table) {
    if (n == name) return e;
    names += (names.empty() ? "" : ", ") + std::string(n);
  }
  throw Error("unknown " + std::string(what) + " '" + std::string(name) + "' (expected one of " + names + ")");
}
template <typename E, std::size_t N>
std::string_view name_of(const std::pair<std::string_view, E> (&table)[N], E e) {
  for (const auto& [n, v] : table)
    if (v == e) return n;
  return "?";
}
}  // namespace

CollisionVolume parse_collision_volume(std::string_view name) { return parse_name(kVolumes, name, "bounding volume"); }
std::string_view to_string(CollisionVolume bv) { return name_of(kVolumes, bv); }
DescendRule parse_descend_rule(std::string_view name) { return parse_name(kRules, name, "descend rule"); }
std::string_view to_string(DescendRule rule) { return name_of(kRules, rule); }
CollideMode parse_collide_mode(std::string_view name) { return parse_name(kModes, name, "collide mode"); }
std::string_view to_string(CollideMode mode) { return name_of(kModes, mode); }

CollisionMesh::CollisionMesh(const TriMesh& mesh, const CollisionMeshOptions& options) : options_(options) {
  mesh.require_valid("collide: mesh");
  bvh::BuildOptions bo;
  bo.leaf_size = options.leaf_size;
  bo.arity = options.arity;
  bo.builder = options.builder;
  switch (options.bv) {
    case CollisionVolume::aabb: bo.bv = bvh::BoundingVolume::aabb; break;
    case CollisionVolume::sphere: bo.bv = bvh::BoundingVolume::sphere; break;
    case CollisionVolume::kdop6: bo.bv = bvh::BoundingVolume::kdop6; break;
    case CollisionVolume::kdop14: bo.bv = bvh::BoundingVolume::kdop14; break;
    case CollisionVolume::kdop18: bo.bv = bvh::BoundingVolume::kdop18; break;
    case CollisionVolume::kdop26: bo.bv = bvh::BoundingVolume::kdop26; break;
    case CollisionVolume::obb: bo.bv = bvh::BoundingVolume::obb; break;
    case CollisionVolume::obb_hull: bo.bv = bvh::BoundingVolume::obb_hull; break;
    case CollisionVolume::rss: bo.bv = bvh::BoundingVolume::rss; break;
    case CollisionVolume::boxtree:
      bo.bv = bvh::BoundingVolume::aabb;
      bo.builder = bvh::Builder::boxtree;
      break;
    default: throw Error("collide: unknown bounding volume");
  }
  bvh::check_options(bo);
  if (mesh.triangles.empty()) return;
  bvh_ = bvh::TriangleBvh::build(mesh, bo);
  depth_ = bvh_.topology().depth();
  leaf_position_.resize(mesh.triangles.size());
  for (std::uint32_t k = 0; k < bvh_.triangle_ids().size(); ++k) leaf_position_[bvh_.triangle_ids()[k]] = k;
  for (const auto& t : mesh.triangles)
    for (const auto v : t) extent_ = std::max(extent_, double(mesh.vertices[v].cwiseAbs().maxCoeff()));
  std::visit(
      [&](const auto& volumes) {
        const std::size_t n = volumes.size();
        boxes_.resize(n);
        sizes_.resize(n);
        using BV = std::decay_t<decltype(volumes[0])>;
        if constexpr (std::is_same_v<BV, bvh::Sphere3f>) balls_.resize(n);
        if constexpr (std::is_same_v<BV, bvh::Obb3f>) oriented_.resize(n);
        if constexpr (std::is_same_v<BV, bvh::Rss3f>) swept_.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
          const AABB3f box = bvh::bounds(volumes[i]);
          boxes_[i] = {((box.lo.cast<double>() + box.hi.cast<double>()) / 2),
                       ((box.hi.cast<double>() - box.lo.cast<double>()) / 2)};
          sizes_[i] = 2 * boxes_[i].half.norm();
          if constexpr (std::is_same_v<BV, bvh::Sphere3f>) {
            balls_[i] = {volumes[i].center.template cast<double>(), double(volumes[i].radius)};
            sizes_[i] = 2 * balls_[i].radius;
          }
          if constexpr (std::is_same_v<BV, bvh::Obb3f>) {
            oriented_[i] = {volumes[i].axes.template cast<double>(), volumes[i].center.template cast<double>(),
                            volumes[i].half.template cast<double>(), volumes[i].half.template cast<double>().norm()};
            sizes_[i] = 2 * oriented_[i].half.norm();
          }
          if constexpr (std::is_same_v<BV, bvh::Rss3f>) {
            const auto& v = volumes[i];
            const double h0 = v.half[0], h1 = v.half[1], r = v.radius;
            swept_[i] = {v.axes.template cast<double>(), v.center.template cast<double>(), h0, h1, r,
                         std::sqrt(h0 * h0 + h1 * h1) + r};
            sizes_[i] = 2 * swept_[i].reach;
          }
        }
      },
      bvh_.volumes());
}

namespace {

// A pose as a rotation matrix and translation, checked.
struct Rigid {
  Eigen::Matrix3d r;
  Vec3d t;
};

Rigid rigid(const Posed& pose, const char* which) {
  const Eigen::Vector4d q = pose.rotation.coeffs();
  if (!q.allFinite() || !pose.translation.allFinite())
    throw Error(std::string("collide: pose of ") + which + " is not finite (NaN or infinity)");
  const double n = q.norm();
  if (!(n > 0)) throw Error(std::string("collide: pose of ") + which + " has a zero quaternion");
  return {Eigen::Quaterniond(q / n).toRotationMatrix(), pose.translation};
}

Posed to_double(const Posef& p) {
  return {p.rotation.cast<double>(), p.translation.cast<double>()};
}

// The world coordinates of a model point: the same expression for both meshes.
inline Vec3d to_world(const Rigid& m, const Vec3f& p) {
  const Vec3d q = p.cast<double>();
  return m.r * q + m.t;
}

// What a query knows: both meshes, their poses, B's frame in A's frame.
struct Frames {
  const CollisionMesh& a;
  const CollisionMesh& b;
  Rigid wa, wb;  // model -> world
  Rigid ab;      // B's model frame -> A's model frame
  double eps;    // padding of the volume tests
};

Frames frames(const CollisionMesh& a, const Posed& pa, const CollisionMesh& b, const Posed& pb) {
  Frames f{a, b, rigid(pa, "A"), rigid(pb, "B"), {}, 0};
  f.ab.r = f.wa.r.transpose() * f.wb.r;
  f.ab.t = f.wa.r.transpose() * (f.wb.t - f.wa.t);
  const double scale = a.extent() + b.extent() + f.wa.t.cwiseAbs().maxCoeff() + f.wb.t.cwiseAbs().maxCoeff();
  f.eps = 1e-9 * scale;
  return f;
}

// ---- Volume testers: overlap(i, j) and a distance lower bound lower(i, j)
// for node i of A and node j of B (B carried into A's frame).

struct BoxTester {
  const Frames& f;
  const CollisionMesh::Box* a;
  const CollisionMesh::Box* b;
  Eigen::Matrix3d abs_r;
  explicit BoxTester(const Frames& fr) : f(fr), a(fr.a.boxes().data()), b(fr.b.boxes().data()) {
    abs_r = f.ab.r.cwiseAbs();
  }
  Vec3d gap(std::uint32_t i, std::uint32_t j) const {
    const Vec3d c = f.ab.r * b[j].center + f.ab.t;
    const Vec3d h = abs_r * b[j].half;
    return (c - a[i].center).cwiseAbs() - a[i].half - h;
  }
  bool overlap(std::uint32_t i, std::uint32_t j) const { return (gap(i, j).array() <= f.eps).all(); }
  double separation(std::uint32_t i, std::uint32_t j) const { return gap(i, j).maxCoeff() - f.eps; }
  double lower(std::uint32_t i, std::uint32_t j, double) const {
    return gap(i, j).cwiseMax(Vec3d::Zero()).norm() - f.eps;
  }
};

struct BallTester {
  const Frames& f;
  const CollisionMesh::Ball* a;
  const CollisionMesh::Ball* b;
  explicit BallTester(const Frames& fr) : f(fr), a(fr.a.balls().data()), b(fr.b.balls().data()) {}
  double gap(std::uint32_t i, std::uint32_t j) const {
    const Vec3d c = f.ab.r * b[j].center + f.ab.t;
    return (c - a[i].center).norm() - a[i].radius - b[j].radius;
  }
  bool overlap(std::uint32_t i, std::uint32_t j) const { return gap(i, j) <= f.eps; }
  double lower(std::uint32_t i, std::uint32_t j, double) const { return gap(i, j) - f.eps; }
  double separation(std::uint32_t i, std::uint32_t j) const { return gap(i, j) - f.eps; }
};

// k-DOPs do not rotate: each side's k-DOP is tested against the rotated
// bounding box of the other side's (support function of the box along each
// slab direction), in both frames.
template <int K>
struct KdopTester {
  using Kdop = bvh::Kdop<float, K>;
  static constexpr int M = K / 2;
  const Frames& f;
  const Kdop* ka;
  const Kdop* kb;
  const CollisionMesh::Box* ba;
  const CollisionMesh::Box* bb;
  Vec3d n_in_b[M], abs_n_in_b[M];  // A's slab directions in B's frame
  Vec3d n_in_a[M], abs_n_in_a[M];  // B's slab directions in A's frame (same set)
  double inv_len[M];
  Vec3d t_ba;  // A's frame -> B's frame: x_b = R^T (x_a - t)
  explicit KdopTester(const Frames& fr)
      : f(fr),
        ka(std::get<FlatArray<Kdop>>(fr.a.bvh().volumes()).data()),
        kb(std::get<FlatArray<Kdop>>(fr.b.bvh().volumes()).data()),
        ba(fr.a.boxes().data()),
        bb(fr.b.boxes().data()) {
    for (int s = 0; s < M; ++s) {
      const Vec3d n = bvh::kdop_direction<K>(s);
      n_in_b[s] = f.ab.r.transpose() * n;  // (R^T n): projection of R x onto n
      abs_n_in_b[s] = n_in_b[s].cwiseAbs();
      n_in_a[s] = f.ab.r * n;
      abs_n_in_a[s] = n_in_a[s].cwiseAbs();
      inv_len[s] = 1 / n.norm();
    }
    t_ba = -(f.ab.r.transpose() * f.ab.t);
  }
  // Largest normalized gap over the slabs, both frames.
  double gap(std::uint32_t i, std::uint32_t j, bool stop_at_separation) const {
    double g = -std::numeric_limits<double>::infinity();
    const Kdop& A = ka[i];
    const Kdop& B = kb[j];
    const Vec3d cb = f.ab.r * bb[j].center + f.ab.t;  // B's box centre in A's frame
    const Vec3d ca = f.ab.r.transpose() * ba[i].center + t_ba;
    for (int s = 0; s < M; ++s) {
      const Vec3d n = bvh::kdop_direction<K>(s);
      // B's rotated box on A's slab s: n . (R c + t) +- |R^T n| . h.
      const double mid = n.dot(cb), rad = abs_n_in_b[s].dot(bb[j].half);
      const double gs = std::max(double(A.lo[s]) - (mid + rad), (mid - rad) - double(A.hi[s])) * inv_len[s];
      // A's rotated box on B's slab s.
      const double mid2 = n.dot(ca), rad2 = abs_n_in_a[s].dot(ba[i].half);
      const double gs2 = std::max(double(B.lo[s]) - (mid2 + rad2), (mid2 - rad2) - double(B.hi[s])) * inv_len[s];
      g = std::max({g, gs, gs2});
      if (stop_at_separation && g > f.eps) return g;
    }
    return g;
  }
  bool overlap(std::uint32_t i, std::uint32_t j) const { return gap(i, j, true) <= f.eps; }
  double separation(std::uint32_t i, std::uint32_t j) const { return gap(i, j, true) - f.eps; }
  double lower(std::uint32_t i, std::uint32_t j, double) const { return gap(i, j, false) - f.eps; }
};

// Gottschalk's 15-axis separating test, B's box carried into A's box frame.
// Written out by hand: the rows of the relative rotation are computed as the
// tests need them, so that a pair separated along one of A's axes (the usual
// case deep in the trees) costs a third of the full test.
struct ObbTester {
  const Frames& f;
  const CollisionMesh::Oriented* a;
  const CollisionMesh::Oriented* b;
  explicit ObbTester(const Frames& fr) : f(fr), a(fr.a.oriented().data()), b(fr.b.oriented().data()) {}

  // Lower: a lower bound of the distance, returned as soon as it reaches
  // `cutoff` (the pair is then pruned whatever its exact bound).
  template <bool Lower>
  double gap(std::uint32_t i, std::uint32_t j, double cutoff = 0) const {
    const CollisionMesh::Oriented& A = a[i];
    const CollisionMesh::Oriented& B = b[j];
    const Eigen::Matrix3d& R = f.ab.r;
    const double eps = f.eps;
    // B's centre in A's model frame, then relative to A's centre.
    const Vec3d d = R * B.center + f.ab.t - A.center;
    // The bounding spheres first: apart, they bound the gap from below.
    const double reach = A.radius + B.radius + eps;
    const double d2 = d.squaredNorm();
    if (d2 > reach * reach) {
      if constexpr (!Lower) return std::sqrt(d2) - A.radius - B.radius;
    }
    double g = -std::numeric_limits<double>::infinity();
    if constexpr (Lower) {
      g = std::sqrt(d2) - A.radius - B.radius;
      if (g >= cutoff) return g;
    }
    double t[3], r[3][3], ar[3][3];
    // Lower bound: the gaps along A's axes are those between A's box and B's
    // box bounded in A's frame, whose distance is their Euclidean norm (and
    // the same in B's frame).
    double sum_a = 0, sum_b = 0;
    for (int k = 0; k < 3; ++k) {
      // Row k: A's axis k in B's model frame (m = R^T a_k), against B's axes.
      const Vec3d ak = A.axes.col(k);
      t[k] = ak.dot(d);
      const Vec3d m = R.transpose() * ak;
      for (int l = 0; l < 3; ++l) {
        r[k][l] = m.dot(B.axes.col(l));
        ar[k][l] = std::abs(r[k][l]) + 1e-9;
      }
      const double s = std::abs(t[k]) - A.half[k] - (B.half[0] * ar[k][0] + B.half[1] * ar[k][1] + B.half[2] * ar[k][2]);
      g = std::max(g, s);
      if (!Lower && g > eps) return g;
      if (s > 0) sum_a += s * s;
    }
    const Vec3d& ha = A.half;
    const Vec3d& hb = B.half;
    for (int l = 0; l < 3; ++l) {
      const double s = std::abs(t[0] * r[0][l] + t[1] * r[1][l] + t[2] * r[2][l]) -
                       (ha[0] * ar[0][l] + ha[1] * ar[1][l] + ha[2] * ar[2][l]) - hb[l];
      g = std::max(g, s);
      if (!Lower && g > eps) return g;
      if (s > 0) sum_b += s * s;
    }
    if constexpr (Lower) {
      g = std::max(g, std::sqrt(std::max(sum_a, sum_b)));
      if (g >= cutoff) return g;
    }
    for (int k = 0; k < 3; ++k) {
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      for (int l = 0; l < 3; ++l) {
        const int l1 = (l + 1) % 3, l2 = (l + 2) % 3;
        const double ra = ha[k1] * ar[k2][l] + ha[k2] * ar[k1][l];
        const double rb = hb[l1] * ar[k][l2] + hb[l2] * ar[k][l1];
        double s = std::abs(t[k2] * r[k1][l] - t[k1] * r[k2][l]) - ra - rb;
        if constexpr (Lower) {
          // Normalized by the axis' length, only if it can raise the bound.
          if (s <= std::min(g, 0.0)) continue;
          const double len = std::sqrt(std::max(0.0, 1 - r[k][l] * r[k][l]));
          if (len < 1e-6) continue;
          s /= len;
        }
        g = std::max(g, s);
        if (!Lower && g > eps) return g;
        if (Lower && g >= cutoff) return g;
      }
    }
    return g;
  }
  bool overlap(std::uint32_t i, std::uint32_t j) const { return gap<false>(i, j) <= f.eps; }
  // The gap along the first separating axis found (or the spheres'): a lower
  // bound of the distance (an unnormalized cross axis, shorter than 1, only
  // lowers it). Computing a larger bound (all face axes, normalized cross
  // axes) lets incremental queries skip few more pairs and costs more than it saves.
  double separation(std::uint32_t i, std::uint32_t j) const { return gap<false>(i, j) - f.eps; }
  double lower(std::uint32_t i, std::uint32_t j, double cutoff) const {
    return gap<true>(i, j, cutoff + f.eps) - f.eps;
  }
};

// Rectangle swept spheres: the rectangles' distance (bvh::rectangle_distance,
// exact) less both radii, after cheaper bounds that often settle the pair:
// the bounding spheres, then the boxes' distances in A's and B's frames; and
// a pair whose distance is surely below the cutoff (B's centre is that near
// A's rectangle) keeps the cheaper bound as its key.
struct RssTester {
  const Frames& f;
  const CollisionMesh::Swept* a;
  const CollisionMesh::Swept* b;
  explicit RssTester(const Frames& fr) : f(fr), a(fr.a.swept().data()), b(fr.b.swept().data()) {}

  // A lower bound of the distance between the volumes, exact if below `cutoff`.
  double gap(std::uint32_t i, std::uint32_t j, double cutoff) const {
    const CollisionMesh::Swept& A = a[i];
    const CollisionMesh::Swept& B = b[j];
    const Vec3d d = f.ab.r * B.center + f.ab.t - A.center;  // in A's model frame
    const double reach = A.reach + B.reach;
    const double d2 = d.squaredNorm();
    if (d2 > (reach + cutoff) * (reach + cutoff)) return std::sqrt(d2) - reach;
    const double rr = A.radius + B.radius;
    // B's rectangle in A's rectangle frame.
    const Vec3d c = A.axes.transpose() * d;
    const Eigen::Matrix3d r = A.axes.transpose() * (f.ab.r * B.axes);
    // B's rectangle bounded by a box in A's frame: the distance from A's
    // rectangle to that box (the norm of the gaps along A's axes) bounds the
    // rectangles' distance from below; the same in B's frame.
    const double ha[3] = {A.half0, A.half1, 0};
    double sa = 0;
    for (int k = 0; k < 3; ++k) {
      const double s = std::abs(c[k]) - ha[k] - std::abs(r(k, 0)) * B.half0 - std::abs(r(k, 1)) * B.half1;
      if (s > 0) sa += s * s;
    }
    double g = std::sqrt(sa) - rr;
    if (g > cutoff) return g;
    const double hb[3] = {B.half0, B.half1, 0};
    double sb = 0;
    for (int l = 0; l < 3; ++l) {
      const double cl = r(0, l) * c[0] + r(1, l) * c[1] + r(2, l) * c[2];
      const double s = std::abs(cl) - hb[l] - std::abs(r(0, l)) * A.half0 - std::abs(r(1, l)) * A.half1;
      if (s > 0) sb += s * s;
    }
    g = std::max(g, std::sqrt(sb) - rr);
    if (g > cutoff) return g;
    // An upper bound below the cutoff: the pair is kept whatever its exact
    // distance, and the lower bound serves as its key.
    const double dx = std::max(std::abs(c[0]) - A.half0, 0.0), dy = std::max(std::abs(c[1]) - A.half1, 0.0);
    if (std::sqrt(dx * dx + dy * dy + c[2] * c[2]) - rr < cutoff) return g;
    return bvh::rectangle_distance<double>(r, c, A.half0, A.half1, B.half0, B.half1) - rr;
  }
  bool overlap(std::uint32_t i, std::uint32_t j) const { return gap(i, j, f.eps) <= f.eps; }
  double separation(std::uint32_t i, std::uint32_t j) const { return gap(i, j, f.eps) - f.eps; }
  double lower(std::uint32_t i, std::uint32_t j, double cutoff) const { return gap(i, j, cutoff + f.eps) - f.eps; }
};

// ---- The traversal.

struct PairRef {
  std::uint32_t a, b;
  float key;
};

bool open_a(const bvh::TopoNode& na, const bvh::TopoNode& nb, double size_a, double size_b, DescendRule rule) {
  if (na.leaf()) return false;
  if (nb.leaf()) return true;
  switch (rule) {
    case DescendRule::larger: return size_a >= size_b;
    case DescendRule::count: return na.prim_count >= nb.prim_count;
    case DescendRule::a_first: return true;
    case DescendRule::b_first: return false;
  }
  return true;
}

// Runs the simultaneous traversal. accept(i, j, key) tests a node pair and
// sets its key; leaf(i, j) handles two leaves (false stops); still_needed(key).
// BestFirst: the pairs wait on a heap by key, the one of smallest key is
// opened next (distance queries: still_needed must be monotone in the key);
// else depth-first in no order (collision queries).
template <bool BestFirst, typename Accept, typename Leaf, typename StillNeeded>
void traverse_pairs(const Frames& f, DescendRule rule, Accept&& accept, Leaf&& leaf, StillNeeded&& still_needed) {
  const bvh::Topology& ta = f.a.bvh().topology();
  const bvh::Topology& tb = f.b.bvh().topology();
  if (ta.nodes.empty() || tb.nodes.empty()) return;
  PairRef root{0, 0, 0.0f};
  if (!accept(0u, 0u, root.key)) return;
  const bvh::TopoNode* na = ta.nodes.data();
  const bvh::TopoNode* nb = tb.nodes.data();
  const double* sa = f.a.sizes().data();
  const double* sb = f.b.sizes().data();
  auto is_leaf = [&](const PairRef& e) { return na[e.a].leaf() && nb[e.b].leaf(); };
  auto children = [&](const PairRef& e, float* keys) {
    const bvh::TopoNode& x = na[e.a];
    const bvh::TopoNode& y = nb[e.b];
    unsigned bits = 0;
    if (open_a(x, y, sa[e.a], sb[e.b], rule)) {
      for (std::uint32_t c = 0; c < x.num_children; ++c)
        if ((keys[c] = 0.0f, accept(x.first_child + c, e.b, keys[c]))) bits |= 1u << c;
    } else {
      for (std::uint32_t c = 0; c < y.num_children; ++c)
        if ((keys[c] = 0.0f, accept(e.a, y.first_child + c, keys[c]))) bits |= 1u << c;
    }
    return bits;
  };
  auto child = [&](const PairRef& e, int c, float key) {
    const bvh::TopoNode& x = na[e.a];
    const bvh::TopoNode& y = nb[e.b];
    if (open_a(x, y, sa[e.a], sb[e.b], rule)) return PairRef{x.first_child + std::uint32_t(c), e.b, key};
    return PairRef{e.a, y.first_child + std::uint32_t(c), key};
  };
  auto at_leaf = [&](const PairRef& e) { return leaf(e.a, e.b); };
  auto needed = [&](const PairRef& e) { return still_needed(e.key); };
  if constexpr (BestFirst) {
    std::vector<PairRef> heap;
    heap.reserve(256);
    bvh::traverse_best_first<8>(root, heap, is_leaf, children, child, at_leaf, needed);
  } else {
    const int arity = std::max(f.a.options().arity, f.b.options().arity);
    bvh::TraversalStack<PairRef> stack(bvh::traversal_stack_size(f.a.depth() + f.b.depth(), arity));
    bvh::traverse<8, false>(root, stack, is_leaf, children, child, at_leaf, needed);
  }
}

// The world triangles of a leaf, computed once per visit.
struct LeafTriangles {
  std::vector<TriangleD> tri;
  std::vector<AABB3d> box;
  std::vector<std::uint32_t> id;
  // The leaf's triangles carried by `pose` (nullptr: left in the model frame).
  void load(const CollisionMesh& m, const Rigid* pose, const bvh::TopoNode& leaf) {
    tri.resize(leaf.prim_count);
    box.resize(leaf.prim_count);
    id.resize(leaf.prim_count);
    const auto& tris = m.bvh().triangles();
    const auto& ids = m.bvh().triangle_ids();
    for (std::uint32_t k = 0; k < leaf.prim_count; ++k) {
      const auto& t = tris[leaf.prim_first + k];
      if (pose)
        tri[k] = {to_world(*pose, t.a), to_world(*pose, t.b), to_world(*pose, t.c)};
      else
        tri[k] = {t.a.cast<double>(), t.b.cast<double>(), t.c.cast<double>()};
      box[k] = AABB3d(tri[k][0].cwiseMin(tri[k][1]).cwiseMin(tri[k][2]), tri[k][0].cwiseMax(tri[k][1]).cwiseMax(tri[k][2]));
      id[k] = ids[leaf.prim_first + k];
    }
  }
};

template <typename Fn>
auto with_tester(const Frames& f, Fn&& fn) {
  const CollisionVolume va = f.a.options().bv, vb = f.b.options().bv;
  auto same = [&](std::initializer_list<CollisionVolume> kinds) {
    bool ia = false, ib = false;
    for (auto k : kinds) ia |= va == k, ib |= vb == k;
    return ia && ib;
  };
  if (same({CollisionVolume::obb, CollisionVolume::obb_hull})) return fn(ObbTester(f));
  if (va == CollisionVolume::rss && vb == CollisionVolume::rss) return fn(RssTester(f));
  if (va == vb) {
    switch (va) {
      case CollisionVolume::sphere: return fn(BallTester(f));
      case CollisionVolume::kdop6: return fn(BoxTester(f));  // the k-DOP 6 is its box
      case CollisionVolume::kdop14: return fn(KdopTester<14>(f));
      case CollisionVolume::kdop18: return fn(KdopTester<18>(f));
      case CollisionVolume::kdop26: return fn(KdopTester<26>(f));
      default: break;
    }
  }
  return fn(BoxTester(f));  // aabb, boxtree, and meshes of different volumes
}

// The exact tests of the triangles of leaves i (of A) and j (of B): calls
// contact(Contact) for each intersecting pair; false from it stops.
template <typename OnContact>
bool leaf_contacts(const Frames& f, LeafTriangles& la, LeafTriangles& lb, std::uint32_t i, std::uint32_t j,
                   CollideStats& stats, OnContact&& contact) {
  ++stats.leaf_pairs;
  la.load(f.a, &f.wa, f.a.bvh().topology().nodes[i]);
  lb.load(f.b, &f.wb, f.b.bvh().topology().nodes[j]);
  for (std::size_t s = 0; s < la.tri.size(); ++s)
    for (std::size_t t = 0; t < lb.tri.size(); ++t) {
      if (!la.box[s].overlaps(lb.box[t])) continue;
      ++stats.triangle_tests;
      if (!triangles_intersect(la.tri[s], lb.tri[t])) continue;
      if (!contact(Contact{la.id[s], lb.id[t]})) return false;
    }
  return true;
}

CollideResult collide_frames(const Frames& f, const CollideRequest& request) {
  CollideResult result;
  const bool all = request.mode == CollideMode::all;
  if (request.max_pairs == 0) return result;
  LeafTriangles la, lb;
  with_tester(f, [&](const auto& tester) {
    traverse_pairs<false>(
        f, request.descend,
        [&](std::uint32_t i, std::uint32_t j, float&) {
          ++result.stats.volume_tests;
          return tester.overlap(i, j);
        },
        [&](std::uint32_t i, std::uint32_t j) {
          return leaf_contacts(f, la, lb, i, j, result.stats, [&](const Contact& c) {
            result.colliding = true;
            result.pairs.push_back(c);
            return all && result.pairs.size() < request.max_pairs;
          });
        },
        [](float) { return true; });
    return 0;
  });
  std::sort(result.pairs.begin(), result.pairs.end());
  return result;
}

// A lower bound of the distance between triangles s and t: how far t lies on
// one side of s's plane (0 if it reaches the plane or s is degenerate).
double plane_gap(const TriangleD& s, const TriangleD& t) {
  const Vec3d n = (s[1] - s[0]).cross(s[2] - s[0]);
  const double len = n.norm();
  if (!(len > 0)) return 0;
  const double d0 = n.dot(t[0] - s[0]), d1 = n.dot(t[1] - s[0]), d2 = n.dot(t[2] - s[0]);
  const double lo = std::min({d0, d1, d2}), hi = std::max({d0, d1, d2});
  const double g = lo > 0 ? lo : (hi < 0 ? -hi : 0.0);
  return g / len * (1 - 1e-12);  // rounded down a little: a bound, never above the distance
}

float key_below(double x) {
  float k = float(x);
  if (double(k) > x) k = std::nextafter(k, -std::numeric_limits<float>::infinity());
  return k;
}

DistanceResult distance_frames(const Frames& f, const DistanceRequest& request) {
  DistanceResult result;
  // In contact: the first contact answers (distance 0, a common point), far
  // faster than the search for a pair at distance 0 among all pairs that may be.
  const CollideResult contact = collide_frames(f, {CollideMode::first, request.descend});
  result.stats = contact.stats;
  if (contact.colliding) {
    const Contact c = contact.pairs[0];
    auto world_triangle = [](const CollisionMesh& m, const Rigid& pose, std::uint32_t id) {
      const auto& t = m.bvh().triangles()[m.leaf_position(id)];
      return TriangleD{to_world(pose, t.a), to_world(pose, t.b), to_world(pose, t.c)};
    };
    const TrianglePairDistance d = triangle_distance(world_triangle(f.a, f.wa, c.a), world_triangle(f.b, f.wb, c.b));
    result.distance = 0;
    result.point_a = d.on_s;
    result.point_b = d.on_t;
    result.triangle_a = c.a;
    result.triangle_b = c.b;
    result.within = request.within >= 0;
    return result;
  }
  double best = std::numeric_limits<double>::infinity();
  const double within = request.within;
  LeafTriangles la, lb;
  const bvh::TopoNode* na = f.a.bvh().topology().nodes.data();
  const bvh::TopoNode* nb = f.b.bvh().topology().nodes.data();
  with_tester(f, [&](const auto& tester) {
    traverse_pairs<true>(
        f, request.descend,
        [&](std::uint32_t i, std::uint32_t j, float& key) {
          ++result.stats.volume_tests;
          const double lower = tester.lower(i, j, within >= 0 ? std::min(best, within) : best);
          key = key_below(lower);
          return lower < best && !(within >= 0 && lower > within);
        },
        [&](std::uint32_t i, std::uint32_t j) {
          ++result.stats.leaf_pairs;
          la.load(f.a, nullptr, na[i]);  // in A's frame: only B's triangles move
          lb.load(f.b, &f.ab, nb[j]);
          for (std::size_t s = 0; s < la.tri.size(); ++s)
            for (std::size_t t = 0; t < lb.tri.size(); ++t) {
              // The boxes' distance bounds the triangles' from below.
              const Vec3d gap = (la.box[s].lo - lb.box[t].hi).cwiseMax(lb.box[t].lo - la.box[s].hi).cwiseMax(0.0);
              if (gap.squaredNorm() >= best * best) continue;
              if (plane_gap(la.tri[s], lb.tri[t]) >= best || plane_gap(lb.tri[t], la.tri[s]) >= best) continue;
              ++result.stats.triangle_tests;
              const TrianglePairDistance d = triangle_distance(la.tri[s], lb.tri[t]);
              if (d.distance < best) {
                best = d.distance;
                result.distance = d.distance;
                result.point_a = d.on_s;
                result.point_b = d.on_t;
                result.triangle_a = la.id[s];
                result.triangle_b = lb.id[t];
                if (best == 0 || (within >= 0 && best <= within)) return false;
              }
            }
          return true;
        },
        [&](float key) { return double(key) < best; });
    return 0;
  });
  result.point_a = f.wa.r * result.point_a + f.wa.t;  // A's frame -> world
  result.point_b = f.wa.r * result.point_b + f.wa.t;
  result.within = within >= 0 && result.distance <= within;
  return result;
}

}  // namespace

CollideResult collide(const CollisionMesh& a, const Posed& pose_a, const CollisionMesh& b, const Posed& pose_b,
                      const CollideRequest& request) {
  return collide_frames(frames(a, pose_a, b, pose_b), request);
}
CollideResult collide(const CollisionMesh& a, const Posef& pose_a, const CollisionMesh& b, const Posef& pose_b,
                      const CollideRequest& request) {
  return collide(a, to_double(pose_a), b, to_double(pose_b), request);
}
DistanceResult distance(const CollisionMesh& a, const Posed& pose_a, const CollisionMesh& b, const Posed& pose_b,
                        const DistanceRequest& request) {
  if (std::isnan(request.within)) throw Error("collide: distance tolerance 'within' is NaN");
  return distance_frames(frames(a, pose_a, b, pose_b), request);
}
DistanceResult distance(const CollisionMesh& a, const Posef& pose_a, const CollisionMesh& b, const Posef& pose_b,
                        const DistanceRequest& request) {
  return distance(a, to_double(pose_a), b, to_double(pose_b), request);
}

// ---- Incremental collision detection.

IncrementalCollide::IncrementalCollide(const CollisionMesh& a, const CollisionMesh& b, DescendRule descend)
    : a_(&a), b_(&b), descend_(descend) {
  reach_b_.resize(b.boxes().size());
  for (std::size_t j = 0; j < reach_b_.size(); ++j) reach_b_[j] = b.boxes()[j].center.norm() + b.boxes()[j].half.norm();
}

void IncrementalCollide::reset() {
  slice_.clear();
  opened_.clear();
  free_.clear();
}

CollideResult IncrementalCollide::update(const Posed& pose_a, const Posed& pose_b) {
  const Frames f = frames(*a_, pose_a, *b_, pose_b);
  CollideResult result;
  skipped_ = 0;
  const auto& na = a_->bvh().topology().nodes;
  const auto& nb = b_->bvh().topology().nodes;
  if (na.empty() || nb.empty()) return result;
  // The motion since the last frame, summed: a point p of B's model frame
  // moved in A's frame by |(R' - R) p + t' - t| <= |R' - R|_F |p| + |t' - t|.
  if (has_last_) {
    rot_ += (f.ab.r - last_r_).norm();
    trans_ += (f.ab.t - last_t_).norm();
  }
  has_last_ = true;
  last_r_ = f.ab.r;
  last_t_ = f.ab.t;
  ++frame_;
  rot_at_.push_back(rot_);
  trans_at_.push_back(trans_);
  if (slice_.empty()) slice_.push_back({0, 0, kNoIndex, frame_, 0.0f});
  auto opens_a = [&](std::uint32_t i, std::uint32_t j) {
    return open_a(na[i], nb[j], a_->sizes()[i], b_->sizes()[j], descend_);
  };
  auto moved = [&](const Entry& e) {
    return ((rot_ - rot_at_[e.frame]) * reach_b_[e.b] + (trans_ - trans_at_[e.frame])) * (1 + 1e-9);
  };
  LeafTriangles la, lb;
  std::vector<Entry> next;
  next.reserve(slice_.size() + 64);
  with_tester(f, [&](const auto& tester) {
    // Down: each slice pair that may overlap now is tested; one that does is
    // replaced by the bottom slice of its subtree (in place: every subtree of
    // the recursion tree stays a contiguous run of the slice).
    std::vector<Entry> stack;
    for (const Entry& e : slice_) {
      if (e.gap > 0 && moved(e) < e.gap) {
        next.push_back(e);
        ++skipped_;
        continue;
      }
      stack.push_back(e);
      while (!stack.empty()) {
        const Entry p = stack.back();
        stack.pop_back();
        ++result.stats.volume_tests;
        const double gap = tester.separation(p.a, p.b);
        if (gap > 0) {
          next.push_back({p.a, p.b, p.parent, frame_, key_below(gap)});
          continue;
        }
        if (na[p.a].leaf() && nb[p.b].leaf()) {
          leaf_contacts(f, la, lb, p.a, p.b, result.stats, [&](const Contact& c) {
            result.pairs.push_back(c);
            return true;
          });
          next.push_back({p.a, p.b, p.parent, frame_, 0.0f});
          continue;
        }
        std::uint32_t here;
        if (!free_.empty()) {
          here = free_.back();
          free_.pop_back();
          opened_[here] = {p.a, p.b, p.parent};
        } else {
          here = std::uint32_t(opened_.size());
          opened_.push_back({p.a, p.b, p.parent});
        }
        if (opens_a(p.a, p.b)) {
          for (std::uint32_t c = na[p.a].num_children; c-- > 0;)
            stack.push_back({na[p.a].first_child + c, p.b, here, frame_, 0.0f});
        } else {
          for (std::uint32_t c = nb[p.b].num_children; c-- > 0;)
            stack.push_back({p.a, nb[p.b].first_child + c, here, frame_, 0.0f});
        }
      }
    }
    // Up: a run of siblings that is the whole subtree of their parent, all
    // apart, one of them tested this frame or the last, becomes the parent
    // if the parent's volumes are apart too; repeated while pairs rise, so
    // that the slice follows a contact region that moves away.
    // After the first pass only groups with a pair raised in the last pass are tried.
    std::vector<char> risen, risen_next;
    for (bool raised = true, first = true; raised; first = false) {
    raised = false;
    std::size_t w = 0;
    risen_next.assign(next.size(), 0);
    for (std::size_t g = 0; g < next.size();) {
      const std::uint32_t p = next[g].parent;
      bool apart = true, fresh = false;
      std::size_t h = g;
      for (; h < next.size() && next[h].parent == p; ++h) {
        apart = apart && next[h].gap > 0;
        fresh = fresh || (first ? next[h].frame + 1 >= frame_ : risen[h] != 0);
      }
      if (p != kNoIndex && apart && fresh) {
        const std::uint32_t i = opened_[p].a, j = opened_[p].b;
        const std::uint32_t children = opens_a(i, j) ? na[i].num_children : nb[j].num_children;
        if (h - g == children) {
          ++result.stats.volume_tests;
          const double gap = tester.separation(i, j);
          if (gap > 0) {
            risen_next[w] = 1;
            next[w++] = {i, j, opened_[p].parent, frame_, key_below(gap)};
            free_.push_back(p);
            raised = true;
            g = h;
            continue;
          }
        }
      }
      for (; g < h; ++g) next[w++] = next[g];
    }
    next.resize(w);
    risen.swap(risen_next);
    }
    return 0;
  });
  slice_.swap(next);
  std::sort(result.pairs.begin(), result.pairs.end());
  result.colliding = !result.pairs.empty();
  return result;
}

// ---- Broad phase.

BroadPhase::BroadPhase(std::vector<const CollisionMesh*> meshes) : meshes_(std::move(meshes)) {
  order_.resize(meshes_.size());
  for (std::uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> BroadPhase::update(const std::vector<Posed>& poses) {
  if (poses.size() != meshes_.size())
    throw Error("collide: BroadPhase::update needs one pose per mesh (" + std::to_string(meshes_.size()) + "), got " +
                std::to_string(poses.size()));
  // World boxes: the root's bounding box carried by the pose, padded like the volume tests.
  std::vector<AABB3d> boxes(meshes_.size());
  for (std::size_t i = 0; i < meshes_.size(); ++i) {
    const Rigid r = rigid(poses[i], "a mesh");
    if (meshes_[i]->boxes().empty()) continue;  // empty mesh: empty box
    const CollisionMesh::Box& b = meshes_[i]->boxes()[0];
    const Vec3d c = r.r * b.center + r.t;
    const double pad = 1e-9 * (meshes_[i]->extent() + r.t.cwiseAbs().maxCoeff());
    const Vec3d h = r.r.cwiseAbs() * b.half + Vec3d::Constant(pad);
    boxes[i] = AABB3d(c - h, c + h);
  }
  // Insertion sort by the low x: nearly sorted after a small motion, O(n) then.
  auto low = [&](std::uint32_t i) { return boxes[i].empty() ? std::numeric_limits<double>::infinity() : boxes[i].lo[0]; };
  for (std::size_t k = 1; k < order_.size(); ++k) {
    const std::uint32_t v = order_[k];
    std::size_t m = k;
    while (m > 0 && low(order_[m - 1]) > low(v)) order_[m] = order_[m - 1], --m;
    order_[m] = v;
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  candidates_ = 0;
  for (std::size_t k = 0; k < order_.size(); ++k) {
    const std::uint32_t i = order_[k];
    if (boxes[i].empty()) break;
    for (std::size_t m = k + 1; m < order_.size() && low(order_[m]) <= boxes[i].hi[0]; ++m) {
      const std::uint32_t j = order_[m];
      if (!boxes[i].overlaps(boxes[j])) continue;
      ++candidates_;
      const std::uint32_t x = std::min(i, j), y = std::max(i, j);
      if (collide(*meshes_[x], poses[x], *meshes_[y], poses[y]).colliding) out.push_back({x, y});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace geods::collide
