#include "geods/field/mesh_distance.hpp"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <string>

#include "../core/prefault.hpp"
#include "geods/bvh/traversal.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/weld.hpp"

namespace geods::field {
namespace {

// A node seen from farther than kDipoleRatio x its radius contributes its dipole.
constexpr double kDipoleRatio = 2.0;

// The solid angle of triangle (a, b, c) seen from p (Van Oosterom and
// Strackee 1983): positive when the triangle turns counter-clockwise seen from p.
// atan2: std::atan2, or one as fast_atan2 below.
template <double (*atan2)(double, double)>
inline double solid_angle(const Vec3d& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3d u = a.cast<double>() - p, v = b.cast<double>() - p, w = c.cast<double>() - p;
  const double lu = u.norm(), lv = v.norm(), lw = w.norm();
  const double det = u.dot(v.cross(w));
  const double den = lu * lv * lw + u.dot(v) * lw + v.dot(w) * lu + w.dot(u) * lv;
  return 2 * atan2(det, den);
}
inline double exact_atan2(double y, double x) { return std::atan2(y, x); }

// atan2(y, x) within 2e-8 (Abramowitz and Stegun 4.4.49 on [0, 1], then the
// octant; 1.4e-8 measured), std::atan2 where y is 0 (its signed zeros and pi).
inline double fast_atan2(double y, double x) {
  if (y == 0) return std::atan2(y, x);
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double z = steep ? ax / ay : ay / ax, s = z * z;
  double r = 0.0028662257;
  for (const double c : {-0.0161657367, 0.0429096138, -0.0752896400, 0.1065626393, -0.1420889944, 0.1999355085,
                         -0.3333314528, 1.0})
    r = r * s + c;
  double angle = r * z;
  if (steep) angle = std::numbers::pi / 2 - angle;
  if (x < 0) angle = std::numbers::pi - angle;
  return y < 0 ? -angle : angle;
}
// fast_atan2's bound with room for rounding, and so that of a solid angle.
constexpr double kFastAngleError = 2 * 2.5e-8;

}  // namespace

SignMethod parse_sign_method(std::string_view name) {
  for (const SignMethod s : {SignMethod::winding, SignMethod::pseudonormal, SignMethod::none})
    if (name == to_string(s)) return s;
  throw Error("signed distance: unknown sign method '" + std::string(name) + "' (winding, pseudonormal or none)");
}

std::string_view to_string(SignMethod sign) {
  switch (sign) {
    case SignMethod::winding: return "winding";
    case SignMethod::pseudonormal: return "pseudonormal";
    case SignMethod::none: break;
  }
  return "none";
}

std::string_view to_string(Feature feature) {
  switch (feature) {
    case Feature::vertex: return "vertex";
    case Feature::edge: return "edge";
    case Feature::face: break;
  }
  return "face";
}

MeshDistance MeshDistance::build(const TriMesh& mesh, const bvh::BuildOptions& options) {
  if (mesh.num_triangles() == 0) throw Error("signed distance: the mesh has no faces");
  mesh.require_valid("signed distance");
  check_coordinate_range(mesh.vertices.front().data(), mesh.num_vertices(), 3, 3, kDistanceCoordinateLimit,
                         kDistanceExtentFloor, "signed distance");
  MeshDistance md;
  detail::reserve_prefaulted(md.faces_, mesh.num_triangles());  // mapped at once: cheaper than a fault per page
  md.faces_.assign(mesh.triangles.begin(), mesh.triangles.end());
  // The normals need only the mesh: they fill the threads the hierarchy's top levels leave idle.
  tbb::parallel_invoke([&] { md.bvh_ = bvh::TriangleBvh::build(mesh, options); }, [&] { md.fit_normals(mesh); });
  md.depth_ = md.bvh_.topology().depth();
  md.fit_moments();
  return md;
}

void MeshDistance::fit_normals(const TriMesh& mesh) {
  const std::size_t n = faces_.size(), nv = mesh.num_vertices();
  const std::vector<std::uint32_t> id = weld(mesh.vertices);
  const auto corner_vertex = [&](std::uint32_t c) { return id[faces_[c / 3][c % 3]]; };
  const auto next = [](std::uint32_t c) { return c % 3 == 2 ? c - 2 : c + 1; };
  const auto prev = [](std::uint32_t c) { return c % 3 == 0 ? c + 2 : c - 1; };
  // The large arrays mapped before they are written (a page fault per 4 KiB
  // page cost about as much as the whole pass); no zeroing: every entry is written.
  std::vector<Vec3d> normals;
  detail::reserve_prefaulted(normals, n);
  normals.resize(n);
  detail::reserve_prefaulted(face_normals_, n);
  face_normals_.resize(n);
  parallel_for_each_index(0, n, [&](std::size_t f) {
    const Vec3d a = mesh.vertices[faces_[f][0]].cast<double>(), b = mesh.vertices[faces_[f][1]].cast<double>(),
                c = mesh.vertices[faces_[f][2]].cast<double>();
    const Vec3d nn = (b - a).cross(c - a);
    const double len = nn.norm();
    normals[f] = len > 0 ? Vec3d(nn / len) : Vec3d::Zero();
    face_normals_[f] = normals[f].cast<float>();
  });

  // The corners c = 3 face + i at each welded vertex, in increasing order (a
  // counting sort), so that each vertex sums its corners in the order of the faces.
  std::vector<std::uint32_t> first(nv + 1, 0), corners = detail::prefaulted_vector<std::uint32_t>(3 * n);
  for (std::uint32_t c = 0; c < 3 * n; ++c) ++first[corner_vertex(c)];
  for (std::size_t v = 1; v <= nv; ++v) first[v] += first[v - 1];
  for (std::uint32_t c = std::uint32_t(3 * n); c-- > 0;) corners[--first[corner_vertex(c)]] = c;

  // Per welded vertex w, in parallel: its angle-weighted normal, and the edges
  // whose smaller welded end is w: the normals of the faces on each are summed
  // in face order, and each direction is counted (closed: as often one way as the other).
  detail::reserve_prefaulted(vertex_normals_, nv);
  vertex_normals_.resize(nv);
  detail::reserve_prefaulted(edge_normals_, 3 * n);
  edge_normals_.resize(3 * n);
  std::atomic<bool> open{false};
  parallel_for(0, nv, 1024, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint64_t> uses;  // (larger end << 32) | corner the edge starts at
    for (std::size_t w = b; w < e; ++w) {
      Vec3d sum = Vec3d::Zero();
      uses.clear();
      for (std::uint32_t k = first[w]; k < first[w + 1]; ++k) {
        const std::uint32_t c = corners[k], f = c / 3, i = c % 3;
        const Vec3d v0 = mesh.vertices[faces_[f][i]].cast<double>();
        const Vec3d e1 = mesh.vertices[faces_[f][(i + 1) % 3]].cast<double>() - v0,
                    e2 = mesh.vertices[faces_[f][(i + 2) % 3]].cast<double>() - v0;
        const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));  // weights the normal at w
        sum += angle * normals[f];
        // The edge from this corner when its other end is not below w, the edge into it when that one's is above.
        if (const std::uint32_t to = corner_vertex(next(c)); to >= w) uses.push_back(std::uint64_t(to) << 32 | c);
        if (const std::uint32_t from = corner_vertex(prev(c)); from > w)
          uses.push_back(std::uint64_t(from) << 32 | prev(c));
      }
      vertex_normals_[w] = sum.cast<float>();
      std::sort(uses.begin(), uses.end());
      for (std::size_t u = 0; u < uses.size();) {
        std::size_t v = u;
        Vec3d edge_sum = Vec3d::Zero();
        long balance = 0;
        for (; v < uses.size() && uses[v] >> 32 == uses[u] >> 32; ++v) {
          const auto c = std::uint32_t(uses[v]);
          edge_sum += normals[c / 3];
          balance += corner_vertex(c) < corner_vertex(next(c)) ? 1 : -1;
        }
        // An edge between welded copies of one vertex belongs to a degenerate face: no boundary.
        if (balance != 0 && uses[u] >> 32 != w) open = true;
        for (std::size_t k = u; k < v; ++k) edge_normals_[std::uint32_t(uses[k])] = edge_sum.cast<float>();
        u = v;
      }
    }
  });
  closed_ = !open;
  // Welded copies share the normal of their smallest index.
  parallel_for_each_index(0, nv, [&](std::size_t v) {
    if (id[v] != v) vertex_normals_[v] = vertex_normals_[id[v]];
  });
}

void MeshDistance::fit_moments() {
  const bvh::Topology& topo = bvh_.topology();
  const auto& tris = bvh_.triangles();
  detail::reserve_prefaulted(moments_, topo.nodes.size());
  moments_.assign(topo.nodes.size(), Moment{});
  // Each node from its own range of triangles (O(n log n) in all).
  parallel_for_each_index(
      0, topo.nodes.size(),
      [&](std::size_t k) {
        const bvh::TopoNode& node = topo.nodes[k];
        Moment m;
        double area = 0;
        Vec3d box_lo = Vec3d::Constant(INFINITY), box_hi = Vec3d::Constant(-INFINITY);
        for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i) {
          const Vec3d a = tris[i].a.cast<double>(), b = tris[i].b.cast<double>(), c = tris[i].c.cast<double>();
          const Vec3d na = 0.5 * (b - a).cross(c - a);
          m.normal_area += na;
          const double ai = na.norm();
          area += ai;
          m.centroid += ai * (a + b + c) / 3;
          for (const Vec3d* v : {&a, &b, &c}) box_lo = box_lo.cwiseMin(*v), box_hi = box_hi.cwiseMax(*v);
        }
        m.centroid = area > 0 ? Vec3d(m.centroid / area) : Vec3d(0.5 * (box_lo + box_hi));
        // The square root of the largest square: the same as the largest root (sqrt is monotone).
        double radius2 = 0;
        for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i)
          for (const Vec3f* v : {&tris[i].a, &tris[i].b, &tris[i].c})
            radius2 = std::max(radius2, (v->cast<double>() - m.centroid).squaredNorm());
        m.radius = std::sqrt(radius2);
        moments_[k] = m;
      },
      16);
}

template <class Angle>
double MeshDistance::solid_angle_sum(const Vec3f& p, const Angle& angle, std::size_t& triangles) const {
  const bvh::Topology& topo = bvh_.topology();
  const auto& tris = bvh_.triangles();
  const Vec3d q = p.cast<double>();
  double omega = 0;
  bvh::TraversalStack<bvh::NodeRef> stack(stack_size());
  bvh::traverse_topology<false>(
      topo, 0, stack,
      [&](std::uint32_t node, float&) {
        const Moment& m = moments_[node];
        const Vec3d r = m.centroid - q;
        const double d2 = r.squaredNorm();
        if (d2 > kDipoleRatio * kDipoleRatio * m.radius * m.radius) {
          omega += m.normal_area.dot(r) / (d2 * std::sqrt(d2));
          return false;
        }
        return true;
      },
      [&](const bvh::TopoNode& node) {
        for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i)
          omega += angle(q, tris[i].a, tris[i].b, tris[i].c);
        triangles += node.prim_count;
      },
      [](float) { return true; });
  return omega;
}

double MeshDistance::winding_number(const Vec3f& p) const {
  if (!p.allFinite()) throw Error("winding number: the query point is not finite");
  std::size_t triangles = 0;
  return solid_angle_sum(p, [](const auto&... a) { return solid_angle<exact_atan2>(a...); }, triangles) / (4 * std::numbers::pi);
}

bool MeshDistance::inside_by_winding(const Vec3f& p) const {
  if (!p.allFinite()) throw Error("winding number: the query point is not finite");
  std::size_t triangles = 0;
  const double w = solid_angle_sum(p, [](const auto&... a) { return solid_angle<fast_atan2>(a...); }, triangles) / (4 * std::numbers::pi);
  // Each triangle's term differs from the exact one by at most kFastAngleError (plus the
  // sum's rounding, far below): where the bound leaves w on one side of 1/2, so is the exact w.
  const double error = (double(triangles) * kFastAngleError + 1e-6) / (4 * std::numbers::pi);
  if (std::abs(w - 0.5) > error) return w > 0.5;
  return winding_number(p) > 0.5;
}

void MeshDistance::feature_of(std::uint32_t face, TriangleRegion region, Feature& feature,
                              std::uint32_t& index) const {
  using R = TriangleRegion;
  switch (region) {
    case R::vertex_a: case R::vertex_b: case R::vertex_c:
      feature = Feature::vertex;
      index = faces_[face][int(region) - int(R::vertex_a)];
      return;
    case R::edge_ab: case R::edge_bc: case R::edge_ca:
      feature = Feature::edge;
      index = std::uint32_t(int(region) - int(R::edge_ab));
      return;
    case R::face:
      feature = Feature::face;
      index = face;
      return;
  }
}

Vec3f MeshDistance::pseudonormal(std::uint32_t face, TriangleRegion region) const {
  using R = TriangleRegion;
  switch (region) {
    case R::vertex_a: case R::vertex_b: case R::vertex_c:
      return vertex_normals_[faces_[face][int(region) - int(R::vertex_a)]];
    case R::edge_ab: case R::edge_bc: case R::edge_ca:
      return edge_normals_[3 * face + (int(region) - int(R::edge_ab))];
    case R::face:
      break;
  }
  return face_normals_[face];
}

bool MeshDistance::inside_by_pseudonormal(const Vec3f& p, const MeshPointDistance& q) const {
  if (q.face == kNoIndex) return false;
  TriangleRegion region = TriangleRegion::face;
  if (q.feature == Feature::vertex) {
    for (int i = 0; i < 3; ++i)
      if (faces_[q.face][i] == q.feature_index) region = TriangleRegion(int(TriangleRegion::vertex_a) + i);
  } else if (q.feature == Feature::edge) {
    region = TriangleRegion(int(TriangleRegion::edge_ab) + int(q.feature_index));
  }
  return (p - q.closest).cast<double>().dot(pseudonormal(q.face, region).cast<double>()) < 0;
}

MeshPointDistance MeshDistance::query(const Vec3f& p, SignMethod sign, float max_distance) const {
  if (!p.allFinite()) throw Error("signed distance: the query point is not finite");
  check_query_range(std::span<const float>(p.data(), 3), kDistanceCoordinateLimit, "signed distance");
  MeshPointDistance out;
  float best_d2 = max_distance * max_distance;
  std::uint32_t best = kNoIndex;  // leaf-order index
  TriangleRegion best_region = TriangleRegion::face;
  const bvh::Topology& topo = bvh_.topology();
  const auto& tris = bvh_.triangles();
  const auto& ids = bvh_.triangle_ids();
  std::visit(
      [&](const auto& volumes) {
        bvh::TraversalStack<bvh::NodeRef> stack(stack_size());
        bvh::traverse_topology<true>(
            topo, 0, stack,
            [&](std::uint32_t node, float& d2) GEODS_BVH_INLINE_LAMBDA {
              d2 = bvh::squared_distance(volumes[node], p);
              return d2 <= best_d2;
            },
            [&](const bvh::TopoNode& node) GEODS_BVH_INLINE_LAMBDA {
              for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i) {
                TriangleRegion region;
                const Vec3f q = closest_point_on_triangle(p, tris[i].a, tris[i].b, tris[i].c, region);
                const float d2 = (q - p).squaredNorm();
                // Ties go to the smallest face index, as brute force over the faces in order.
                if (d2 < best_d2 || (d2 == best_d2 && (best == kNoIndex || ids[i] < ids[best]))) {
                  best_d2 = d2;
                  best = i;
                  best_region = region;
                  out.closest = q;
                }
              }
            },
            [&](float d2) GEODS_BVH_INLINE_LAMBDA { return d2 <= best_d2; });
      },
      bvh_.volumes());
  if (best == kNoIndex) {
    out.closest = Vec3f::Constant(std::numeric_limits<float>::quiet_NaN());
    if (sign == SignMethod::winding && inside_by_winding(p)) out.distance = -out.distance;
    return out;
  }
  out.face = ids[best];
  out.distance = std::sqrt(best_d2);
  feature_of(out.face, best_region, out.feature, out.feature_index);
  if ((sign == SignMethod::winding && inside_by_winding(p)) ||
      (sign == SignMethod::pseudonormal && inside_by_pseudonormal(p, out)))
    out.distance = -out.distance;
  return out;
}

std::vector<MeshPointDistance> signed_distance(const MeshDistance& mesh, std::span<const Vec3f> points,
                                               SignMethod sign) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) throw Error("signed distance: point " + std::to_string(i) + " is not finite");
  std::vector<MeshPointDistance> out(points.size());
  parallel_for_each_index(0, points.size(), [&](std::size_t i) { out[i] = mesh.query(points[i], sign); }, 64);
  return out;
}

std::vector<MeshPointDistance> signed_distance(const TriMesh& mesh, std::span<const Vec3f> points, SignMethod sign) {
  return signed_distance(MeshDistance::build(mesh), points, sign);
}

}  // namespace geods::field
