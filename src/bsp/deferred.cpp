#include "geods/bsp/deferred.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/predicates.hpp"

namespace geods::bsp {

DeferredBsp::DeferredBsp(const Triangles& mesh, std::size_t threshold, std::size_t leaf_size)
    : mesh_(mesh), hits_(mesh.triangles.size(), 0), threshold_(threshold), leaf_size_(std::max<std::size_t>(leaf_size, 1)) {
  check_mesh(mesh_.vertices, mesh_.triangles, "DeferredBsp");
  DNode root;
  for (std::uint32_t t = 0; t < mesh_.triangles.size(); ++t) {
    const auto& tr = mesh_.triangles[t];
    const Vec3d n = (mesh_.vertices[tr[1]] - mesh_.vertices[tr[0]]).cross(mesh_.vertices[tr[2]] - mesh_.vertices[tr[0]]);
    if (n.squaredNorm() > 0) root.list.push_back(t);  // degenerate triangles are never hit
  }
  nodes_.push_back(std::move(root));
  if (threshold_ == 0) {
    // Oblivious: split every leaf now.
    for (std::size_t i = 0; i < nodes_.size(); ++i)
      if (nodes_[i].tri == kNoIndex && nodes_[i].list.size() > leaf_size_) split(static_cast<std::uint32_t>(i));
  }
  stats_.nodes = nodes_.size();
}

// Side of x w.r.t. the plane of triangle `tri` (exact; positive on its normal side).
int DeferredBsp::side(std::uint32_t tri, const Vec3d& x) const {
  const auto& t = mesh_.triangles[tri];
  const double o = orient3d(mesh_.vertices[t[0]], mesh_.vertices[t[1]], mesh_.vertices[t[2]], x);
  return o < 0 ? 1 : (o > 0 ? -1 : 0);  // orient3d > 0: below (behind the counter-clockwise normal)
}

void DeferredBsp::split(std::uint32_t node) {
  DNode& n0 = nodes_[node];
  // The most-hit triangle (the list is sorted by hits): its plane splits the list.
  const std::uint32_t h = n0.list.front();
  std::vector<std::uint32_t> neg, pos;
  for (std::uint32_t t : n0.list) {
    if (t == h) continue;
    int lo = 1, hi = -1;
    for (auto v : mesh_.triangles[t]) {
      const int s = side(h, mesh_.vertices[v]);
      lo = std::min(lo, s), hi = std::max(hi, s);
    }
    if (lo == 0 && hi == 0) {  // coplanar: both sides (it lies on their common boundary)
      neg.push_back(t), pos.push_back(t);
      continue;
    }
    if (lo < 0 || (lo == 0 && hi <= 0)) neg.push_back(t);
    if (hi > 0) pos.push_back(t);
  }
  // The splitting triangle stays at the node (tested there), so both children are smaller.
  n0.tri = h;
  n0.list.clear();
  n0.list.shrink_to_fit();
  DNode a, b;
  a.list = std::move(neg);
  b.list = std::move(pos);
  const auto ia = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(std::move(a));
  nodes_.push_back(std::move(b));
  nodes_[node].neg = ia;
  nodes_[node].pos = ia + 1;
  ++stats_.splits;
}

namespace {

bool segment_hits_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const double sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) return false;
  if (sp == 0 && sq == 0) return false;  // coplanar segment: counted as no crossing (measure zero)
  const double e0 = orient3d(p, q, a, b), e1 = orient3d(p, q, b, c), e2 = orient3d(p, q, c, a);
  return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
}

}  // namespace

bool DeferredBsp::intersects(const Vec3d& p, const Vec3d& q) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(p[i]) || !std::isfinite(q[i])) throw Error("DeferredBsp: segment is not finite");
  ++stats_.queries;
  const bool hit = query(0, p, q);
  stats_.nodes = nodes_.size();
  return hit;
}

bool DeferredBsp::query(std::uint32_t node, const Vec3d& p, const Vec3d& q) {
  ++stats_.node_visits;
  ++nodes_[node].accesses;
  if (nodes_[node].tri == kNoIndex) {
    auto& list = nodes_[node].list;
    for (std::size_t i = 0; i < list.size(); ++i) {
      ++stats_.triangle_tests;
      const auto& t = mesh_.triangles[list[i]];
      if (segment_hits_triangle(p, q, mesh_.vertices[t[0]], mesh_.vertices[t[1]], mesh_.vertices[t[2]])) {
        const std::uint32_t tri = list[i];
        ++hits_[tri];
        // Keep the list sorted by hits: move the hit triangle forward past less-hit ones.
        std::size_t j = i;
        while (j > 0 && hits_[list[j - 1]] < hits_[tri]) list[j] = list[j - 1], --j;
        list[j] = tri;
        if (threshold_ > 0 && nodes_[node].accesses >= threshold_ && list.size() > leaf_size_) split(node);
        return true;
      }
    }
    if (threshold_ > 0 && nodes_[node].accesses >= threshold_ && list.size() > leaf_size_) split(node);
    return false;
  }
  const std::uint32_t tri = nodes_[node].tri;
  ++stats_.triangle_tests;
  {
    const auto& t = mesh_.triangles[tri];
    if (segment_hits_triangle(p, q, mesh_.vertices[t[0]], mesh_.vertices[t[1]], mesh_.vertices[t[2]])) {
      ++hits_[tri];
      return true;
    }
  }
  const int sp = side(tri, p), sq = side(tri, q);
  const std::uint32_t first = sp < 0 || (sp == 0 && sq < 0) ? nodes_[node].neg : nodes_[node].pos;
  const std::uint32_t second = first == nodes_[node].neg ? nodes_[node].pos : nodes_[node].neg;
  if (query(first, p, q)) return true;
  // The other side only if the segment reaches it (touching the plane counts).
  const bool reaches = (first == nodes_[node].neg) ? (sp >= 0 || sq >= 0) : (sp <= 0 || sq <= 0);
  if (!reaches) return false;
  return query(second, p, q);
}

}  // namespace geods::bsp
