#include "geods/ray/render.hpp"

#include <algorithm>
#include <atomic>
#include <array>
#include <chrono>
#include <numbers>
#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::ray {

namespace {

constexpr int kTile = 16;  // a multiple of the 4 x 4 pixel blocks of a packet
constexpr int kBlockX = 4, kBlockY = 4;
using Packet = bvh::RayPacket16;  // 16 rays: faster than 8 (docs/ray.md)
using Hits = bvh::HitPacketN<Packet::size>;
constexpr int kBlock = Packet::size;
static_assert(kBlockX * kBlockY == kBlock);

// Area-weighted vertex normals for smooth shading when the mesh has none.
std::vector<Vec3f> vertex_normals(const TriMesh& mesh) {
  if (mesh.normals.size() == mesh.vertices.size()) return mesh.normals;
  std::vector<Vec3f> normals(mesh.vertices.size(), Vec3f::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (std::uint32_t v : t) normals[v] += n;
  }
  return normals;
}

// Linear intensity to 8-bit sRGB-like values (gamma 2.2), by a table of 4096 entries.
class GammaTable {
 public:
  GammaTable() {
    for (int i = 0; i < kSize; ++i)
      table_[std::size_t(i)] = std::uint8_t(std::lround(255.0 * std::pow(double(i) / (kSize - 1), 1.0 / 2.2)));
  }
  std::uint8_t operator()(float linear) const {
    return table_[std::size_t(std::lround(std::clamp(linear, 0.0f, 1.0f) * (kSize - 1)))];
  }

 private:
  static constexpr int kSize = 4096;
  std::array<std::uint8_t, kSize> table_;
};

// The camera's frame, computed once per image (Camera::primary_ray recomputes it per ray).
struct CameraFrame {
  explicit CameraFrame(const Camera& camera, int width, int height) : eye(camera.eye) {
    forward = (camera.target - camera.eye).normalized();
    right = forward.cross(camera.up).normalized();
    up = right.cross(forward);
    const float h = std::tan(0.5f * camera.vertical_fov_deg * std::numbers::pi_v<float> / 180.0f);
    right *= 2 * h * float(width) / float(height) / float(width);
    up *= 2 * h / float(height);
    corner = forward - 0.5f * float(width) * right + 0.5f * float(height) * up;
  }
  Ray3f ray(float x, float y) const {
    Ray3f r;
    r.origin = eye;
    r.direction = (corner + x * right - y * up).normalized();
    return r;
  }
  Vec3f eye, forward, right, up, corner;
};

}  // namespace

RenderResult render(const TriMesh& mesh, const RenderOptions& options) {
  const auto accel = make_accelerator(mesh, options.accel, options.accel_options);
  RenderResult result = render(mesh, *accel, options);
  result.build_s = accel->build_s();
  return result;
}

RenderResult render(const TriMesh& mesh, const Accelerator& accel, const RenderOptions& options) {
  if (options.width < 1 || options.height < 1 || options.width > 32768 || options.height > 32768)
    throw Error("render: width and height must be in [1, 32768]");
  if (accel.num_triangles() != mesh.num_triangles())
    throw Error("render: the accelerator was built over a different mesh");
  const Camera camera = options.camera.value_or(Camera::framing(mesh.bounds()));
  camera.check();
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Vec3f> normals = vertex_normals(mesh);
  const int width = options.width, height = options.height;
  RenderResult result;
  result.image = Image<std::uint8_t>(std::size_t(width), std::size_t(height), 3);

  // A directional light above and to the left, a little behind the camera.
  const CameraFrame frame(camera, width, height);
  const Vec3f light = (0.55f * frame.up.normalized() - 0.75f * frame.right.normalized() - 0.35f * frame.forward).normalized();
  const GammaTable to_byte;
  const AABB3f bounds = mesh.bounds();
  const float offset = 1e-4f * (bounds.empty() ? 1.0f : std::max(bounds.extent().norm(), 1e-30f));
  const Vec3f albedo(0.90f, 0.72f, 0.50f);

  const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  const std::size_t tiles = std::size_t(tiles_x) * std::size_t(tiles_y);
  std::atomic<std::uint64_t> rays{0}, hits{0}, occluder_hits{0};
  auto render_tile = [&](std::size_t tile) {
    // Per tile: one cache for primary rays, one for the shadow rays of the light.
    RayCache primary_cache, shadow_cache;
    std::uint64_t tile_rays = 0, tile_hits = 0;
    const int x0 = int(tile % std::size_t(tiles_x)) * kTile, y0 = int(tile / std::size_t(tiles_x)) * kTile;
    // Blocks of 4 x 4 pixels: one packet of primary rays, then one of the
    // shadow rays of the lit pixels (ray by ray without options.packets).
    for (int by = y0; by < std::min(y0 + kTile, height); by += kBlockY)
      for (int bx = x0; bx < std::min(x0 + kTile, width); bx += kBlockX) {
        Packet primary;
        primary.active = 0;
        for (int i = 0; i < kBlock; ++i) {
          const int x = bx + i % kBlockX, y = by + i / kBlockX;
          if (x >= width || y >= height) continue;
          primary.rays[i] = frame.ray(float(x) + 0.5f, float(y) + 0.5f);
          primary.active |= 1u << i;
          ++tile_rays;
        }
        Hits primary_hits;
        if (options.packets) {
          primary_hits = accel.intersect(primary, primary_cache);
        } else {
          for (int i = 0; i < kBlock; ++i)
            if (primary.active >> i & 1) primary_hits.hits[i] = accel.intersect(primary.rays[i], primary_cache);
        }
        Vec3f colors[kBlock];
        float keys[kBlock], fills[kBlock];
        Packet shadow;
        shadow.active = 0;
        for (int i = 0; i < kBlock; ++i) {
          if (!(primary.active >> i & 1)) continue;
          const Ray3f& ray = primary.rays[i];
          const RayHit& hit = primary_hits.hits[i];
          if (!hit.hit()) {
            const float s = float(by + i / kBlockX) / float(height);
            colors[i] = (1 - s) * Vec3f(0.93f, 0.95f, 0.98f) + s * Vec3f(0.70f, 0.76f, 0.84f);
            continue;
          }
          ++tile_hits;
          const auto& tri = mesh.triangles[hit.prim];
          const Vec3f &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
          Vec3f geometric = (b - a).cross(c - a).normalized();
          // Two-sided: turn the normals towards the viewer.
          const float facing = geometric.dot(ray.direction) > 0 ? -1.0f : 1.0f;
          geometric *= facing;
          Vec3f n = (1 - hit.u - hit.v) * normals[tri[0]] + hit.u * normals[tri[1]] + hit.v * normals[tri[2]];
          n = n.squaredNorm() > 0 ? Vec3f(facing * n.normalized()) : geometric;
          if (n.dot(ray.direction) > 0) n = geometric;
          keys[i] = std::max(0.0f, n.dot(light));
          fills[i] = std::abs(n.dot(ray.direction));
          if (options.shadows && keys[i] > 0 && geometric.dot(light) > 0) {
            Ray3f& s = shadow.rays[i];
            s.origin = ray.at(hit.t) + offset * geometric;
            s.direction = light;
            shadow.active |= 1u << i;
            ++tile_rays;
          }
        }
        std::uint32_t blocked = 0;
        if (shadow.active != 0) {
          if (options.packets) {
            blocked = accel.occluded(shadow, shadow_cache);
          } else {
            for (int i = 0; i < kBlock; ++i)
              if ((shadow.active >> i & 1) && accel.occluded(shadow.rays[i], shadow_cache)) blocked |= 1u << i;
          }
        }
        for (int i = 0; i < kBlock; ++i) {
          if (!(primary.active >> i & 1)) continue;
          if (primary_hits.hits[i].hit()) {
            const float key = (blocked >> i & 1) ? 0.0f : keys[i];
            colors[i] = albedo * (0.10f + 0.75f * key + 0.20f * fills[i]);
          }
          const int x = bx + i % kBlockX, y = by + i / kBlockX;
          for (int ch = 0; ch < 3; ++ch)
            result.image(std::size_t(x), std::size_t(y), std::size_t(ch)) = to_byte(colors[i][ch]);
        }
      }
    rays.fetch_add(tile_rays, std::memory_order_relaxed);
    hits.fetch_add(tile_hits, std::memory_order_relaxed);
    occluder_hits.fetch_add(shadow_cache.occluder_hits, std::memory_order_relaxed);
  };
  // Tiles in batches, so that progress is reported from this thread.
  Progress progress(options.progress, "render", double(tiles));
  const std::size_t batch = std::max<std::size_t>(1, tiles / 32);
  for (std::size_t first = 0; first < tiles; first += batch) {
    parallel_for_each_index(first, std::min(tiles, first + batch), render_tile, 1);
    progress.update(double(std::min(tiles, first + batch)));
  }
  progress.finish();
  result.render_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.rays = rays.load();
  result.hits = hits.load();
  result.occluder_hits = occluder_hits.load();
  result.accel_stats = accel.stats();
  return result;
}

}  // namespace geods::ray
