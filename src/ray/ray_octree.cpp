#include "geods/ray/ray_octree.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "mailbox.hpp"
#include "box_margin.hpp"
#include "geods/core/triangle_box.hpp"
#include "geods/core/triangle.hpp"

namespace geods::ray {

namespace {

// Child c of a box split at its middle: bit 4 upper x half, bit 2 y, bit 1 z.
AABB3f child_box(const AABB3f& box, int c) {
  const Vec3f mid = box.center();
  AABB3f child = box;
  for (int a = 0; a < 3; ++a) {
    if (c & (4 >> a))
      child.lo[a] = mid[a];
    else
      child.hi[a] = mid[a];
  }
  return child;
}

struct Pending {
  std::uint32_t node;
  AABB3f box;
  std::vector<std::uint32_t> triangles;
};

}  // namespace

std::unique_ptr<RayOctree> RayOctree::build(const TriMesh& mesh, const AcceleratorOptions& options) {
  if (options.octree_leaf_size == 0) throw Error("ray octree: octree_leaf_size must be at least 1");
  if (options.octree_max_depth > kMaxDepth)
    throw Error(fmt::format("ray octree: octree_max_depth must be at most {}", kMaxDepth));
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<RayOctree> tree(new RayOctree(mesh));
  RayOctree& o = *tree;
  const std::size_t n = o.num_triangles();
  o.set_root_bounds();

  // Level by level: the nodes of one level decide and partition in parallel,
  // then are numbered in order, so the layout is the same for any thread count.
  std::vector<Pending> level(1);
  level[0] = {0, o.root_bounds_, std::vector<std::uint32_t>(n)};
  for (std::uint32_t i = 0; i < n; ++i) level[0].triangles[i] = i;
  std::vector<Node> nodes(1);
  std::vector<std::uint32_t> leaf_triangles;
  for (std::size_t depth = 0; !level.empty(); ++depth) {
    o.depth_ = depth;
    std::vector<std::array<std::vector<std::uint32_t>, 8>> children(level.size());
    std::vector<char> split(level.size(), 0);
    parallel_for_each_index(0, level.size(), [&](std::size_t k) {
      const Pending& p = level[k];
      if (p.triangles.size() <= options.octree_leaf_size || depth >= options.octree_max_depth) return;
      std::array<AABB3f, 8> boxes;
      for (int c = 0; c < 8; ++c) boxes[c] = detail::widened(child_box(p.box, c), o.margin_);
      const Vec3f mid = p.box.center();
      auto classify = [&](std::size_t first, std::size_t last, std::array<std::vector<std::uint32_t>, 8>& out) {
        for (std::size_t i = first; i < last; ++i) {
          const std::uint32_t t = p.triangles[i];
          const Vec3f* corners = &o.corners_[3 * std::size_t(t)];
          const AABB3f tri_box = triangle_bounds(corners[0], corners[1], corners[2]);
          // The halves of each axis the (widened) triangle box reaches: a
          // triangle inside one child needs no triangle-box test.
          int lo_bits = 0, hi_bits = 0;
          for (int a = 0; a < 3; ++a) {
            if (tri_box.lo[a] <= mid[a] + o.margin_) lo_bits |= 4 >> a;
            if (tri_box.hi[a] >= mid[a] - o.margin_) hi_bits |= 4 >> a;
          }
          const bool single = (lo_bits ^ hi_bits) == 7;
          for (int c = 0; c < 8; ++c) {
            // Child c takes the upper half of the axes whose bit is set in c.
            if ((c & ~hi_bits & 7) != 0 || (~c & ~lo_bits & 7) != 0) continue;
            if (single || triangle_box_overlap(corners[0], corners[1], corners[2], boxes[c])) out[c].push_back(t);
          }
        }
      };
      // The top levels have fewer nodes than threads: a large node's triangles
      // are classified in fixed chunks in parallel and the lists joined in
      // order, the same lists as one pass.
      constexpr std::size_t kChunk = 32768;
      const std::size_t chunks = (p.triangles.size() + kChunk - 1) / kChunk;
      if (chunks == 1) {
        classify(0, p.triangles.size(), children[k]);
      } else {
        std::vector<std::array<std::vector<std::uint32_t>, 8>> parts(chunks);
        parallel_for_each_index(0, chunks, [&](std::size_t j) {
          classify(j * kChunk, std::min(p.triangles.size(), (j + 1) * kChunk), parts[j]);
        }, 1);
        for (int c = 0; c < 8; ++c) {
          std::size_t size = 0;
          for (const auto& part : parts) size += part[c].size();
          children[k][c].reserve(size);
          for (const auto& part : parts) children[k][c].insert(children[k][c].end(), part[c].begin(), part[c].end());
        }
      }
      // A child is hit by about a quarter of the rays that hit its parent (the
      // ratio of their surface areas), so splitting pays only while the
      // children hold fewer than four times the node's triangles in total; and
      // not at all when no child holds fewer than the node (coincident or
      // overlapping large triangles, which would otherwise be copied down to
      // max_depth along every edge).
      std::size_t total = 0;
      for (const auto& list : children[k]) {
        total += list.size();
        if (list.size() < p.triangles.size()) split[k] = 1;
      }
      if (total >= 4 * p.triangles.size()) split[k] = 0;
      if (!split[k]) children[k] = {};
    }, 1);
    std::vector<Pending> next;
    for (std::size_t k = 0; k < level.size(); ++k) {
      Pending& p = level[k];
      if (!split[k]) {
        if (leaf_triangles.size() + p.triangles.size() >= Node::kInner)
          throw Error("ray octree: more than 2^32 triangle references");
        nodes[p.node] = {std::uint32_t(leaf_triangles.size()), std::uint32_t(p.triangles.size())};
        leaf_triangles.insert(leaf_triangles.end(), p.triangles.begin(), p.triangles.end());
        continue;
      }
      const std::uint32_t first = std::uint32_t(nodes.size());
      nodes[p.node] = {first, Node::kInner};
      nodes.resize(nodes.size() + 8);
      for (int c = 0; c < 8; ++c) next.push_back({first + std::uint32_t(c), child_box(p.box, c), std::move(children[k][c])});
    }
    level = std::move(next);
  }
  o.nodes_ = std::move(nodes);
  o.leaf_triangles_ = std::move(leaf_triangles);
  o.build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return tree;
}

void RayOctree::set_root_bounds() {
  root_bounds_ = num_triangles() == 0 ? AABB3f(Vec3f::Zero(), Vec3f::Ones()) : detail::widened(bounds_, margin_);
}

void RayOctree::save(const std::filesystem::path& path) const {
  ArchiveWriter out(kArchiveKind, kArchiveVersion);
  add_sections(out);
  out.add_value("depth", std::uint64_t(depth_));
  out.add("nodes", nodes_);
  out.add("leaf_triangles", leaf_triangles_);
  out.write(path);
}

std::unique_ptr<RayOctree> RayOctree::load(const std::filesystem::path& path) {
  const Archive in = Archive::open(path, kArchiveKind, kArchiveVersion);
  std::unique_ptr<RayOctree> tree(new RayOctree(in));
  RayOctree& o = *tree;
  o.set_root_bounds();
  o.depth_ = in.value<std::uint64_t>("depth");
  o.nodes_ = in.array<Node>("nodes");
  o.leaf_triangles_ = in.array<std::uint32_t>("leaf_triangles");
  in.check([&] { o.validate(); });
  return tree;
}

// The recursive procedure of Revelles et al. over the mirrored ray (all
// direction components positive); `mirror` holds the axis bits to XOR.
template <bool AnyHit>
struct RayOctree::Traversal {
  Traversal(const RayOctree& tree_, const Ray3f& ray_, RayHit& best_) : tree(tree_), ray(ray_), test(ray_), best(best_) {}

  const RayOctree& tree;
  const Ray3f& ray;
  const RayTriangleTest<float> test;
  RayHit& best;
  int mirror = 0;
  detail::Mailbox mailbox;
  std::uint32_t found = RayHit::no_hit;

  // Table 2: the first child hit, from the entry plane (Table 1: the largest t0).
  static int first_child(float tx0, float ty0, float tz0, float txm, float tym, float tzm) {
    int c = 0;
    if (tx0 > ty0 && tx0 > tz0) {  // enters through a YZ plane
      if (tym < tx0) c |= 2;
      if (tzm < tx0) c |= 1;
    } else if (ty0 > tz0) {  // XZ plane
      if (txm < ty0) c |= 4;
      if (tzm < ty0) c |= 1;
    } else {  // XY plane
      if (txm < tz0) c |= 4;
      if (tym < tz0) c |= 2;
    }
    return c;
  }
  // Table 3: the next child through the exit plane (the smallest exit t); 8 = leaves the node.
  static int next_child(float tx, int x, float ty, int y, float tz, int z) {
    if (tx < ty && tx < tz) return x;
    return ty < tz ? y : z;
  }

  // True when the traversal is finished (a hit that no later node can beat).
  bool visit(std::uint32_t index, float tx0, float ty0, float tz0, float tx1, float ty1, float tz1) {
    const float t_enter = std::max({tx0, ty0, tz0}), t_exit = std::min({tx1, ty1, tz1});
    if (t_exit < ray.tmin || t_enter > t_exit) return false;
    if (t_enter > best.t) return true;  // nodes come in order along the ray
    const Node& node = tree.nodes_[index];
    if (node.leaf()) {
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
        const std::uint32_t prim = tree.leaf_triangles_[k];
        if (mailbox.seen(prim)) continue;
        if constexpr (AnyHit) {
          if (tree.test_any(test, prim, ray.tmin, ray.tmax)) {
            found = prim;
            return true;
          }
        } else {
          tree.test_closest(test, prim, ray.tmin, best);
        }
      }
      return best.t <= t_exit;
    }
    const float txm = 0.5f * (tx0 + tx1), tym = 0.5f * (ty0 + ty1), tzm = 0.5f * (tz0 + tz1);
    const std::uint32_t first = node.first;
    int c = first_child(tx0, ty0, tz0, txm, tym, tzm);
    while (c < 8) {
      const std::uint32_t child = first + std::uint32_t(c ^ mirror);
      switch (c) {
        case 0:
          if (visit(child, tx0, ty0, tz0, txm, tym, tzm)) return true;
          c = next_child(txm, 4, tym, 2, tzm, 1);
          break;
        case 1:
          if (visit(child, tx0, ty0, tzm, txm, tym, tz1)) return true;
          c = next_child(txm, 5, tym, 3, tz1, 8);
          break;
        case 2:
          if (visit(child, tx0, tym, tz0, txm, ty1, tzm)) return true;
          c = next_child(txm, 6, ty1, 8, tzm, 3);
          break;
        case 3:
          if (visit(child, tx0, tym, tzm, txm, ty1, tz1)) return true;
          c = next_child(txm, 7, ty1, 8, tz1, 8);
          break;
        case 4:
          if (visit(child, txm, ty0, tz0, tx1, tym, tzm)) return true;
          c = next_child(tx1, 8, tym, 6, tzm, 5);
          break;
        case 5:
          if (visit(child, txm, ty0, tzm, tx1, tym, tz1)) return true;
          c = next_child(tx1, 8, tym, 7, tz1, 8);
          break;
        case 6:
          if (visit(child, txm, tym, tz0, tx1, ty1, tzm)) return true;
          c = next_child(tx1, 8, ty1, 8, tzm, 7);
          break;
        default:
          if (visit(child, txm, tym, tzm, tx1, ty1, tz1)) return true;
          c = 8;
          break;
      }
    }
    return false;
  }

  void run() {
    // Mirror negative components (the XOR of the child index undoes it); the
    // ray parameters of the mirrored ray are those of the true one.
    Vec3f o = ray.origin, d = ray.direction;
    const AABB3f& box = tree.root_bounds_;
    for (int a = 0; a < 3; ++a) {
      if (d[a] < 0) {
        o[a] = box.lo[a] + box.hi[a] - o[a];
        d[a] = -d[a];
        mirror |= 4 >> a;
      }
      d[a] = std::max(d[a], 1e-20f);
    }
    float t0[3], t1[3];
    for (int a = 0; a < 3; ++a) {
      t0[a] = (box.lo[a] - o[a]) / d[a];
      t1[a] = (box.hi[a] - o[a]) / d[a];
    }
    visit(0, t0[0], t0[1], t0[2], t1[0], t1[1], t1[2]);
  }
};

RayHit RayOctree::closest_hit(const Ray3f& ray, RayCache&) const {
  RayHit best;
  best.t = ray.tmax;
  Traversal<false>(*this, ray, best).run();
  return best;
}

std::uint32_t RayOctree::any_hit(const Ray3f& ray, RayCache&) const {
  RayHit bound;
  bound.t = ray.tmax;
  Traversal<true> traversal(*this, ray, bound);
  traversal.run();
  return traversal.found;
}

AcceleratorStats RayOctree::stats() const {
  AcceleratorStats s;
  s.kind = "octree";
  s.triangles = num_triangles();
  s.nodes = nodes_.size();
  for (const Node& node : nodes_) s.leaves += node.leaf();
  s.references = leaf_triangles_.size();
  s.depth = depth_;
  s.bytes = nodes_.size() * sizeof(Node) + leaf_triangles_.size() * sizeof(std::uint32_t) +
            corners_.size() * sizeof(Vec3f);
  s.build_s = build_s_;
  return s;
}

void RayOctree::validate() const {
  if (nodes_.empty()) throw Error("ray octree: no root");
  // Walk from the root with each node's box: children in range, every leaf's
  // range in bounds, and every triangle listed in the leaf of each of its corners.
  // The depth recorded is the deepest node's, within the build's limit (the
  // traversal recurses that deep).
  if (depth_ > kMaxDepth) throw Error(fmt::format("ray octree: depth {} above {}", depth_, kMaxDepth));
  std::vector<char> reached(nodes_.size(), 0);
  struct Item {
    std::uint32_t index;
    AABB3f box;
    std::size_t depth;
  };
  std::vector<Item> stack = {{0, root_bounds_, 0}};
  std::size_t deepest = 0;
  while (!stack.empty()) {
    const auto [index, box, depth] = stack.back();
    stack.pop_back();
    if (reached[index]) throw Error(fmt::format("ray octree: node {} reached twice", index));
    reached[index] = 1;
    deepest = std::max(deepest, depth);
    if (depth > depth_) throw Error(fmt::format("ray octree: node {} deeper than the tree's depth {}", index, depth_));
    const Node& node = nodes_[index];
    if (node.leaf()) {
      if (std::size_t(node.first) + node.count > leaf_triangles_.size())
        throw Error(fmt::format("ray octree: leaf {} refers past the triangle list", index));
      for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
        if (leaf_triangles_[k] >= num_triangles())
          throw Error(fmt::format("ray octree: leaf {} lists triangle {} of {}", index, leaf_triangles_[k],
                                  num_triangles()));
      continue;
    }
    if (std::size_t(node.first) + 8 > nodes_.size() || node.first <= index)
      throw Error(fmt::format("ray octree: node {} has children out of range", index));
    for (int c = 0; c < 8; ++c) stack.push_back({node.first + std::uint32_t(c), child_box(box, c), depth + 1});
  }
  if (deepest != depth_) throw Error(fmt::format("ray octree: depth {} recorded, {} found", depth_, deepest));
  if (std::find(reached.begin(), reached.end(), 0) != reached.end())
    throw Error("ray octree: a node is not reachable from the root");
  for (std::size_t i = 0; i < num_triangles(); ++i)
    for (int k = 0; k < 3; ++k) {
      const Vec3f& p = corners_[3 * i + k];
      std::uint32_t index = 0;
      AABB3f box = root_bounds_;
      while (!nodes_[index].leaf()) {
        const Vec3f mid = box.center();
        const int c = (p[0] >= mid[0] ? 4 : 0) | (p[1] >= mid[1] ? 2 : 0) | (p[2] >= mid[2] ? 1 : 0);
        box = child_box(box, c);
        index = nodes_[index].first + std::uint32_t(c);
      }
      const Node& leaf = nodes_[index];
      const auto begin = leaf_triangles_.begin() + leaf.first;
      if (std::find(begin, begin + leaf.count, std::uint32_t(i)) == begin + leaf.count)
        throw Error(fmt::format("ray octree: triangle {} is missing from the leaf of its corner {}", i, k));
    }
}

}  // namespace geods::ray
