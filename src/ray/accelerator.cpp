#include "geods/ray/accelerator.hpp"

#include <array>
#include <atomic>
#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/ray/bvh_accelerator.hpp"
#include "geods/ray/ray_classifier.hpp"
#include "geods/ray/ray_octree.hpp"
#include "geods/ray/uniform_grid.hpp"

namespace geods::ray {

namespace {
constexpr std::array<AcceleratorKind, 4> kKinds = {AcceleratorKind::bvh, AcceleratorKind::grid,
                                                   AcceleratorKind::octree, AcceleratorKind::rays5d};
}  // namespace

std::string_view to_string(AcceleratorKind kind) {
  switch (kind) {
    case AcceleratorKind::bvh: return "bvh";
    case AcceleratorKind::grid: return "grid";
    case AcceleratorKind::octree: return "octree";
    case AcceleratorKind::rays5d: return "rays5d";
  }
  return "?";
}

AcceleratorKind parse_accelerator_kind(std::string_view name) {
  for (AcceleratorKind kind : kKinds)
    if (to_string(kind) == name) return kind;
  std::string valid;
  for (AcceleratorKind kind : kKinds) valid += (valid.empty() ? "" : ", ") + std::string(to_string(kind));
  throw Error("unknown accelerator '" + std::string(name) + "' (valid: " + valid + ")");
}

std::span<const AcceleratorKind> all_accelerator_kinds() { return kKinds; }

namespace {
std::uint64_t next_id() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

Accelerator::Accelerator(const TriMesh& mesh) : id_(next_id()) {
  if (mesh.num_triangles() >= std::size_t(RayHit::no_hit))
    throw Error("ray accelerator: more than 2^32 - 2 triangles");
  // The O(n) checks on the way (in parallel, like the copy: on two threads the
  // grid's and octree's builds spent a fifth of their time here); the full
  // validation (which sorts the edges) only to word the error message.
  std::atomic<bool> usable{true};
  parallel_for(0, mesh.num_vertices(), 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      if (!mesh.vertices[i].allFinite()) usable = false;
  });
  std::vector<Vec3f> corners(mesh.num_triangles() * 3);  // Eigen vectors: no zero-fill
  parallel_for(0, mesh.num_triangles(), 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = mesh.triangles[i][k];
        if (v < mesh.num_vertices()) {
          corners[3 * i + k] = mesh.vertices[v];
        } else {
          usable = false;
        }
      }
  });
  if (!usable) mesh.require_valid("ray accelerator");
  corners_ = std::move(corners);
  set_bounds();
}

Accelerator::Accelerator(const Archive& in) : id_(next_id()) {
  corners_ = in.array<Vec3f>("corners");
  if (corners_.size() % 3 != 0) throw in.error("the corner count is not a multiple of 3");
  if (corners_.size() / 3 >= std::size_t(RayHit::no_hit)) throw in.error("more than 2^32 - 2 triangles");
  for (std::size_t i = 0; i < corners_.size(); ++i)
    if (!corners_[i].allFinite()) throw in.error("triangle " + std::to_string(i / 3) + " has a non-finite corner");
  build_s_ = in.value<double>("build_s");
  set_bounds();
}

void Accelerator::add_sections(ArchiveWriter& out) const {
  out.add("corners", corners_);
  out.add_value("build_s", build_s_);
}

void Accelerator::set_bounds() {
  bounds_ = parallel_bounds<AABB3f>(corners_.size(), [&](AABB3f& box, std::size_t i) { box.extend(corners_[i]); });
  ray_range_problem_ = ray_range_problem(bounds_, "ray accelerator");
  // Float rounding of the traversal is relative to the coordinates (about 1e-7
  // of them); 1e-5 of the scene's size and largest coordinate covers rays
  // starting up to a hundred scene sizes away.
  if (!bounds_.empty()) {
    const float scale = std::max(bounds_.extent().norm(), std::max(bounds_.lo.cwiseAbs().maxCoeff(),
                                                                   bounds_.hi.cwiseAbs().maxCoeff()));
    margin_ = std::max(scale * 1e-5f, 1e-30f);
  }
}

bool Accelerator::shootable(const Ray3f& ray) {
  return ray.origin.allFinite() && ray.direction.allFinite() && !ray.direction.isZero(0) &&
         !std::isnan(ray.tmin) && !std::isnan(ray.tmax) && ray.tmin <= ray.tmax;
}

RayHit Accelerator::intersect(const Ray3f& ray) const {
  RayCache cache;
  return intersect(ray, cache);
}

RayHit Accelerator::intersect(const Ray3f& ray, RayCache& cache) const {
  check_range(ray);
  if (!shootable(ray) || corners_.empty()) return {};
  if (cache.owner != id_) cache = RayCache{id_};
  const RayHit hit = closest_hit(ray, cache);
  return hit.hit() ? hit : RayHit{};
}

bool Accelerator::occluded(const Ray3f& ray) const {
  RayCache cache;
  return occluded(ray, cache);
}

bool Accelerator::occluded(const Ray3f& ray, RayCache& cache) const {
  check_range(ray);
  if (!shootable(ray) || corners_.empty()) return false;
  if (cache.owner != id_) cache = RayCache{id_};
  // The occluder cache (seed §2.5.2): any occluder will do, and the one that
  // blocked the previous shadow ray towards the same light often blocks this one.
  if (cache.occluder != RayHit::no_hit &&
      test_any(RayTriangleTest<float>(ray), cache.occluder, ray.tmin, ray.tmax)) {
    ++cache.occluder_hits;
    return true;
  }
  const std::uint32_t prim = any_hit(ray, cache);
  if (prim == RayHit::no_hit) return false;
  cache.occluder = prim;
  return true;
}

namespace {

// The packet with only its active rays that can hit anything (shootable(ray)).
template <int N, typename Shootable>
bvh::RayPacketN<N> shootable_lanes(const bvh::RayPacketN<N>& packet, Shootable&& shootable) {
  bvh::RayPacketN<N> shot = packet;
  shot.active &= (1u << N) - 1;
  for (std::uint32_t b = shot.active; b != 0; b &= b - 1)
    if (!shootable(packet.rays[__builtin_ctz(b)])) shot.active &= ~(1u << __builtin_ctz(b));
  return shot;
}

}  // namespace

template <int N>
bvh::HitPacketN<N> Accelerator::intersect_packet(const bvh::RayPacketN<N>& packet, RayCache& cache) const {
  const bvh::RayPacketN<N> shot = shootable_lanes(packet, [&](const Ray3f& ray) {
    check_range(ray);
    return shootable(ray);
  });
  if (shot.active == 0 || corners_.empty()) return {};
  if (cache.owner != id_) cache = RayCache{id_};
  bvh::HitPacketN<N> out = closest_hits(shot, cache);
  for (int i = 0; i < N; ++i)
    if (!(shot.active >> i & 1) || !out.hits[i].hit()) out.hits[i] = RayHit{};
  return out;
}

template <int N>
std::uint32_t Accelerator::occluded_packet(const bvh::RayPacketN<N>& packet, RayCache& cache) const {
  const bvh::RayPacketN<N> shot = shootable_lanes(packet, [&](const Ray3f& ray) {
    check_range(ray);
    return shootable(ray);
  });
  if (shot.active == 0 || corners_.empty()) return 0;
  if (cache.owner != id_) cache = RayCache{id_};
  return any_hits(shot, cache) & shot.active;
}

template <int N>
bvh::HitPacketN<N> Accelerator::closest_hits_one_by_one(const bvh::RayPacketN<N>& packet, RayCache& cache) const {
  bvh::HitPacketN<N> out;
  for (int i = 0; i < N; ++i)
    if (packet.active >> i & 1) out.hits[i] = intersect(packet.rays[i], cache);
  return out;
}

template <int N>
std::uint32_t Accelerator::any_hits_one_by_one(const bvh::RayPacketN<N>& packet, RayCache& cache) const {
  std::uint32_t mask = 0;
  for (int i = 0; i < N; ++i)
    if ((packet.active >> i & 1) && occluded(packet.rays[i], cache)) mask |= 1u << i;
  return mask;
}

bvh::HitPacket Accelerator::intersect(const bvh::RayPacket& packet, RayCache& cache) const {
  return intersect_packet(packet, cache);
}
std::uint32_t Accelerator::occluded(const bvh::RayPacket& packet, RayCache& cache) const {
  return occluded_packet(packet, cache);
}
bvh::HitPacket16 Accelerator::intersect(const bvh::RayPacket16& packet, RayCache& cache) const {
  return intersect_packet(packet, cache);
}
std::uint32_t Accelerator::occluded(const bvh::RayPacket16& packet, RayCache& cache) const {
  return occluded_packet(packet, cache);
}
bvh::HitPacket Accelerator::closest_hits(const bvh::RayPacket& packet, RayCache& cache) const {
  return closest_hits_one_by_one(packet, cache);
}
std::uint32_t Accelerator::any_hits(const bvh::RayPacket& packet, RayCache& cache) const {
  return any_hits_one_by_one(packet, cache);
}
bvh::HitPacket16 Accelerator::closest_hits(const bvh::RayPacket16& packet, RayCache& cache) const {
  return closest_hits_one_by_one(packet, cache);
}
std::uint32_t Accelerator::any_hits(const bvh::RayPacket16& packet, RayCache& cache) const {
  return any_hits_one_by_one(packet, cache);
}

std::unique_ptr<Accelerator> make_accelerator(const TriMesh& mesh, AcceleratorKind kind,
                                              const AcceleratorOptions& options) {
  switch (kind) {
    case AcceleratorKind::bvh: return BvhAccelerator::build(mesh, options);
    case AcceleratorKind::grid: return UniformGrid::build(mesh, options);
    case AcceleratorKind::octree: return RayOctree::build(mesh, options);
    case AcceleratorKind::rays5d: return RayClassifier::build(mesh, options);
  }
  throw Error("make_accelerator: unknown kind");
}

std::unique_ptr<Accelerator> load_accelerator(const std::filesystem::path& path) {
  const std::string kind = Archive::peek(path).kind;
  if (kind == BvhAccelerator::kArchiveKind) return BvhAccelerator::load(path);
  if (kind == UniformGrid::kArchiveKind) return UniformGrid::load(path);
  if (kind == RayOctree::kArchiveKind) return RayOctree::load(path);
  if (kind == RayClassifier::kArchiveKind) return RayClassifier::load(path);
  throw Error(path.string() + ": a " + kind + " archive, not a ray accelerator");
}

}  // namespace geods::ray
