#include "geods/ray/ray_classifier.hpp"

#include <fmt/format.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "box_margin.hpp"
#include "geods/core/triangle.hpp"

namespace geods::ray {

// A cell of a 5D octree: origins in `box`, directions (u, v) in [uv_lo, uv_hi]
// on direction-cube face `face` (axis face / 2, negative if face is odd).
struct RayClassifier::Node {
  AABB3f box;
  float uv_lo[2] = {-1, -1}, uv_hi[2] = {1, 1};
  std::uint8_t face = 0, depth = 0;
  std::vector<std::uint32_t> candidates;  // by increasing start along the face's axis, then index
  std::atomic<bool> ready{false};         // candidates are built
  // Set once under a lock while queries read the node through const pointers.
  mutable std::atomic<Node*> children{nullptr};  // 32 children, published once
  mutable std::unique_ptr<Node[]> owned_children;
  // Candidates tested by the rays that ended here, and children built: the
  // rent-or-buy rule of locate() pays for building with the queries' work.
  mutable std::atomic<std::uint64_t> work{0};
  mutable std::atomic<std::uint32_t> built{0};

  int axis() const { return face / 2; }
  bool negative() const { return face & 1; }
};

// A ray as a 5D point: face, origin inside B, direction on the face.
struct RayClassifier::Ray5 {
  int face;
  Vec3f origin;
  float uv[2];
};

namespace {

// The start and end of a box along a face's axis, in the face's direction.
inline float start_along(const AABB3f& box, int axis, bool negative) { return negative ? -box.hi[axis] : box.lo[axis]; }
inline float end_along(const AABB3f& box, int axis, bool negative) { return negative ? -box.lo[axis] : box.hi[axis]; }

bool contains(const AABB3f& box, const float* uv_lo, const float* uv_hi, const Vec3f& p, const float* uv) {
  return box.contains(p) && uv[0] >= uv_lo[0] && uv[0] <= uv_hi[0] && uv[1] >= uv_lo[1] && uv[1] <= uv_hi[1];
}

}  // namespace

RayClassifier::RayClassifier(const TriMesh& mesh) : Accelerator(mesh) {}
RayClassifier::RayClassifier(const Archive& in) : Accelerator(in) {}
RayClassifier::~RayClassifier() = default;

namespace {
void check_rays5d_options(const AcceleratorOptions& options) {
  if (options.rays5d_leaf_size == 0) throw Error("5D ray classification: rays5d_leaf_size must be at least 1");
  if (options.rays5d_max_depth > 20) throw Error("5D ray classification: rays5d_max_depth must be at most 20");
  if (std::isnan(options.rays5d_cutoff)) throw Error("5D ray classification: rays5d_cutoff is NaN");
}
}  // namespace

std::unique_ptr<RayClassifier> RayClassifier::build(const TriMesh& mesh, const AcceleratorOptions& options) {
  check_rays5d_options(options);
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<RayClassifier> rc(new RayClassifier(mesh));
  rc->build_roots(options);
  rc->build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return rc;
}

void RayClassifier::save(const std::filesystem::path& path) const {
  ArchiveWriter out(kArchiveKind, kArchiveVersion);
  add_sections(out);
  out.add_value("leaf_size", options_.rays5d_leaf_size);
  out.add_value("max_depth", options_.rays5d_max_depth);
  out.add_value("max_references", std::uint64_t(options_.rays5d_max_references));
  out.add_value("cutoff", options_.rays5d_cutoff);
  out.write(path);
}

std::unique_ptr<RayClassifier> RayClassifier::load(const std::filesystem::path& path) {
  const Archive in = Archive::open(path, kArchiveKind, kArchiveVersion);
  AcceleratorOptions options;
  options.rays5d_leaf_size = in.value<std::uint32_t>("leaf_size");
  options.rays5d_max_depth = in.value<std::uint32_t>("max_depth");
  options.rays5d_max_references = std::size_t(in.value<std::uint64_t>("max_references"));
  options.rays5d_cutoff = in.value<float>("cutoff");
  in.check([&] { check_rays5d_options(options); });
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<RayClassifier> rc(new RayClassifier(in));
  rc->build_roots(options);
  rc->build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return rc;
}

void RayClassifier::build_roots(const AcceleratorOptions& options) {
  options_ = options;
  const std::size_t n = num_triangles();
  scene_ = n == 0 ? AABB3f(Vec3f::Zero(), Vec3f::Ones()) : detail::widened(bounds_, 2 * margin_);
  for (int a = 0; a < 3; ++a) {
    const float extent = scene_.hi[a] - scene_.lo[a];
    // At least 1% of the extent, so a query restarts at most about 100 times.
    cutoff_[a] = options.rays5d_cutoff > 0 && std::isfinite(options.rays5d_cutoff)
                     ? std::max(options.rays5d_cutoff, 0.01f) * extent
                     : std::numeric_limits<float>::infinity();
  }
  boxes_.resize(n);
  parallel_for_each_index(0, n, [&](std::size_t i) {
    const Vec3f* t = &corners_[3 * i];
    boxes_[i] = detail::widened(triangle_bounds(t[0], t[1], t[2]), margin_);
  });
  // The six roots hold every triangle, sorted along their axis (ties by index,
  // a total order: the parallel sort is deterministic).
  parallel_for_each_index(0, 6, [&](std::size_t face) {
    auto root = std::make_unique<Node>();
    root->box = scene_;
    root->face = std::uint8_t(face);
    const int axis = root->axis();
    const bool negative = root->negative();
    std::vector<std::pair<float, std::uint32_t>> keys(n);
    for (std::uint32_t i = 0; i < n; ++i) keys[i] = {start_along(boxes_[i], axis, negative), i};
    tbb::parallel_sort(keys.begin(), keys.end());
    root->candidates.resize(n);
    for (std::size_t i = 0; i < n; ++i) root->candidates[i] = keys[i].second;
    root->ready.store(true, std::memory_order_release);
    roots_[face] = std::move(root);
  }, 1);
  references_ = 6 * n;
}

// Whether the triangle's box meets the node's beam: the rays leaving the box
// with a direction in the node's square, i.e. the points q + s (1, u, v) in the
// face's frame with q in the box and s >= 0. Over the part [wa, wb] of the
// triangle's extent along the axis that lies ahead of the box, s ranges over
// [max(0, wa - far side), wb - near side], and the beam's cross-section is the
// box's widened by u s and v s: a conservative test (the beam's bounding box
// over that slab), exactly what candidate lists need.
bool RayClassifier::beam_meets(const Node& node, std::uint32_t prim) const {
  const AABB3f& o = boxes_[prim];
  const int k = node.axis();
  const bool neg = node.negative();
  const float near = start_along(node.box, k, neg), far = end_along(node.box, k, neg);
  const float wa = std::max(start_along(o, k, neg), near), wb = end_along(o, k, neg);
  if (wa > wb || start_along(o, k, neg) > far + cutoff_[k]) return false;
  const float s0 = std::max(0.0f, wa - far), s1 = wb - near;
  for (int i = 0; i < 2; ++i) {
    const int j = (k + 1 + i) % 3;
    const float lo = node.box.lo[j] + std::min(node.uv_lo[i] * s0, node.uv_lo[i] * s1);
    const float hi = node.box.hi[j] + std::max(node.uv_hi[i] * s0, node.uv_hi[i] * s1);
    if (lo > o.hi[j] || hi < o.lo[j]) return false;
  }
  return true;
}

void RayClassifier::build_child(const Node& parent, Node& child) const {
  for (std::uint32_t prim : parent.candidates)
    if (beam_meets(child, prim)) child.candidates.push_back(prim);
  child.candidates.shrink_to_fit();
  references_.fetch_add(child.candidates.size(), std::memory_order_relaxed);
  nodes_.fetch_add(1, std::memory_order_relaxed);
  std::size_t depth = depth_.load(std::memory_order_relaxed);
  while (child.depth > depth && !depth_.compare_exchange_weak(depth, child.depth, std::memory_order_relaxed)) {
  }
}

const RayClassifier::Node& RayClassifier::locate(const Ray5& r, RayCache& cache) const {
  const Node* node = roots_[std::size_t(r.face)].get();
  // The per-level cache: start in the previous ray's leaf if this ray's 5D point is in it.
  if (cache.cell) {
    const Node* last = static_cast<const Node*>(cache.cell);
    if (last->face == r.face && contains(last->box, last->uv_lo, last->uv_hi, r.origin, r.uv)) {
      node = last;
      ++cache.cell_hits;
    }
  }
  const std::size_t max_refs = options_.rays5d_max_references;
  for (;;) {
    Node* kids = node->children.load(std::memory_order_acquire);
    const std::uint64_t size = node->candidates.size();
    if (!kids) {
      if (size <= options_.rays5d_leaf_size || node->depth >= options_.rays5d_max_depth ||
          references() >= max_refs || node->work.load(std::memory_order_relaxed) < size)
        break;
      std::lock_guard lock(locks_[std::hash<const void*>{}(node) % locks_.size()]);
      kids = node->children.load(std::memory_order_acquire);
      if (!kids) {
        auto block = std::make_unique<Node[]>(32);
        const Vec3f mid = node->box.center();
        for (int c = 0; c < 32; ++c) {
          Node& child = block[std::size_t(c)];
          child.face = node->face;
          child.depth = std::uint8_t(node->depth + 1);
          child.box = node->box;
          for (int a = 0; a < 3; ++a) (c >> a & 1 ? child.box.lo[a] : child.box.hi[a]) = mid[a];
          for (int i = 0; i < 2; ++i) {
            const float uv_mid = 0.5f * (node->uv_lo[i] + node->uv_hi[i]);
            child.uv_lo[i] = c >> (3 + i) & 1 ? uv_mid : node->uv_lo[i];
            child.uv_hi[i] = c >> (3 + i) & 1 ? node->uv_hi[i] : uv_mid;
          }
        }
        kids = block.get();
        node->owned_children = std::move(block);
        node->children.store(kids, std::memory_order_release);
      }
    }
    int c = 0;
    const Vec3f mid = node->box.center();
    for (int a = 0; a < 3; ++a) c |= (r.origin[a] >= mid[a]) << a;
    for (int i = 0; i < 2; ++i) c |= (r.uv[i] >= 0.5f * (node->uv_lo[i] + node->uv_hi[i])) << (3 + i);
    Node& child = kids[c];
    if (!child.ready.load(std::memory_order_acquire)) {
      // Building a child costs a pass over the parent's list; it is built once
      // the rays that stopped at the parent have tested as many candidates as
      // all children built so far and this one cost (so building never costs
      // more than the queries it serves). Until then, or over the budget, the
      // parent answers: its list holds the child's.
      if (references() >= max_refs ||
          node->work.load(std::memory_order_relaxed) < (node->built.load(std::memory_order_relaxed) + 1) * size)
        break;
      std::lock_guard lock(locks_[std::hash<const void*>{}(&child) % locks_.size()]);
      if (!child.ready.load(std::memory_order_relaxed)) {
        build_child(*node, child);
        node->built.fetch_add(1, std::memory_order_relaxed);
        child.ready.store(true, std::memory_order_release);
      }
    }
    node = &child;
  }
  cache.cell = node;
  return *node;
}

template <bool AnyHit>
std::uint32_t RayClassifier::shoot(const Ray3f& ray, RayCache& cache, RayHit& best) const {
  const Vec3f& d = ray.direction;
  int k = 0;
  if (std::abs(d[1]) > std::abs(d[k])) k = 1;
  if (std::abs(d[2]) > std::abs(d[k])) k = 2;
  const bool neg = d[k] < 0;
  const float dk = std::abs(d[k]);
  Ray5 r{2 * k + int(neg), Vec3f::Zero(), {d[(k + 1) % 3] / dk, d[(k + 2) % 3] / dk}};
  const auto [t0, t1] = ray_box_interval(ray, Vec3f(d.cwiseInverse()), scene_);
  if (!(t0 <= t1)) return RayHit::no_hit;
  const RayTriangleTest<float> test(ray);
  const float origin_along = neg ? -ray.origin[k] : ray.origin[k];
  const float scene_end = end_along(scene_, k, neg);
  float t_start = t0;
  for (;;) {
    r.origin = ray.at(t_start).cwiseMax(scene_.lo).cwiseMin(scene_.hi);
    const Node& leaf = locate(r, cache);
    std::uint64_t tested = 0;
    for (std::uint32_t prim : leaf.candidates) {
      // Sorted along the axis: this candidate and all later ones start beyond the closest hit.
      if (start_along(boxes_[prim], k, neg) > origin_along + best.t * dk) break;
      ++tested;
      if constexpr (AnyHit) {
        if (test_any(test, prim, ray.tmin, ray.tmax)) {
          leaf.work.fetch_add(tested, std::memory_order_relaxed);
          return prim;
        }
      } else {
        test_closest(test, prim, ray.tmin, best);
      }
    }
    leaf.work.fetch_add(tested, std::memory_order_relaxed);
    // The leaf lists every triangle starting before its far side + cut-off; a
    // hit before that is final, otherwise start again from there.
    const float cut = end_along(leaf.box, k, neg) + cutoff_[k];
    if (cut >= scene_end) break;
    const float t_cut = (cut - origin_along) / dk;
    if (best.t <= t_cut || t_cut >= t1) break;
    t_start = std::max(t_cut, std::nextafter(t_start, std::numeric_limits<float>::infinity()));
  }
  return AnyHit ? RayHit::no_hit : best.prim;
}

RayHit RayClassifier::closest_hit(const Ray3f& ray, RayCache& cache) const {
  RayHit best;
  best.t = ray.tmax;
  shoot<false>(ray, cache, best);
  return best;
}

std::uint32_t RayClassifier::any_hit(const Ray3f& ray, RayCache& cache) const {
  RayHit bound;
  bound.t = ray.tmax;
  return shoot<true>(ray, cache, bound);
}

AcceleratorStats RayClassifier::stats() const {
  AcceleratorStats s;
  s.kind = "rays5d";
  s.triangles = num_triangles();
  std::vector<const Node*> stack;
  for (const auto& root : roots_) stack.push_back(root.get());
  while (!stack.empty()) {
    const Node* node = stack.back();
    stack.pop_back();
    ++s.nodes;
    s.references += node->candidates.size();
    s.depth = std::max<std::size_t>(s.depth, node->depth);
    const Node* kids = node->children.load(std::memory_order_acquire);
    if (!kids) {
      ++s.leaves;
      continue;
    }
    s.bytes += 32 * sizeof(Node);
    for (int c = 0; c < 32; ++c)
      if (kids[c].ready.load(std::memory_order_acquire)) stack.push_back(&kids[c]);
  }
  s.bytes += 6 * sizeof(Node) + s.references * sizeof(std::uint32_t) + boxes_.size() * sizeof(AABB3f) +
             corners_.size() * sizeof(Vec3f);
  s.build_s = build_s_;
  return s;
}

void RayClassifier::validate() const {
  for (int face = 0; face < 6; ++face) {
    const Node& root = *roots_[std::size_t(face)];
    if (root.candidates.size() != num_triangles())
      throw Error(fmt::format("5D ray classification: root {} lists {} of {} triangles", face, root.candidates.size(),
                              num_triangles()));
  }
  std::vector<std::pair<const Node*, const Node*>> stack;  // node, parent
  for (const auto& root : roots_) stack.push_back({root.get(), nullptr});
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    const int k = node->axis();
    const bool neg = node->negative();
    for (std::size_t i = 1; i < node->candidates.size(); ++i) {
      const std::uint32_t x = node->candidates[i - 1], y = node->candidates[i];
      const float sx = start_along(boxes_[x], k, neg), sy = start_along(boxes_[y], k, neg);
      if (!(sx < sy || (sx == sy && x < y)))
        throw Error(fmt::format("5D ray classification: a list of face {} is not sorted along its axis", node->face));
    }
    if (parent) {
      std::vector<std::uint32_t> expected;
      for (std::uint32_t prim : parent->candidates)
        if (beam_meets(*node, prim)) expected.push_back(prim);
      if (expected != node->candidates)
        throw Error(fmt::format("5D ray classification: a node of depth {} does not list exactly the parent's "
                                "candidates that meet its beam",
                                node->depth));
    }
    const Node* kids = node->children.load(std::memory_order_acquire);
    if (!kids) continue;
    for (int c = 0; c < 32; ++c)
      if (kids[c].ready.load(std::memory_order_acquire)) stack.push_back({&kids[c], node});
  }
}

}  // namespace geods::ray
