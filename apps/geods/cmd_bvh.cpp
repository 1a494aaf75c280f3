// geods bvh: build a bounding volume hierarchy over a mesh, print its
// statistics, and optionally shoot rays from a .npy file.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/bvh/stats_fields.hpp"
#include "geods/io/table_io.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class BvhCommand : public Command {
 public:
  std::string name() const override { return "bvh"; }
  std::string summary() const override {
    return "bounding volume hierarchy of a mesh: build time, nodes, depth, SAH cost, tightness; optional ray hits";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "mesh", mesh_, "Triangle mesh (.ply, .obj, .off, .stl, .gltf)");
    app.add_option("--builder", builder_, "sah, median, pca, bottom_up, tiling, insertion or boxtree (bottomup: deprecated)");
    app.add_option("--bv", bv_, "Bounding volume: aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, obb_hull or rss");
    app.add_option("--leaf-size", leaf_size_, "Most triangles per leaf (1..255)");
    app.add_option("--arity", arity_, "Children per node: 2, 4 or 8");
    app.add_option("--rays", rays_, "Rays, n x 6 (ox oy oz dx dy dz; .npy, .csv)");
    app.add_option("--packets", packet_size_,
                   "Shoot --rays in packets of 8 (or 16: --packets 16) consecutive rays traversed together (the "
                   "same hits; faster for coherent rays in neighbouring order: 4 x 2 or 4 x 4 pixel tiles)")
        ->expected(0, 1)
        ->default_str("8")
        ->check(CLI::IsMember({8, 16}));
    add_output(app, "-o,--output", output_, "Output for --rays: float64 n x 2 (t, triangle), inf and -1 on a miss",
               io::OutputKind::table);
    add_save(app, save_, "the hierarchy", "TriangleBvh.load");
  }

  void run(const RunContext& context, Report& report) override {
    bvh::BuildOptions options;
    options.builder = bvh::parse_builder(builder_);
    options.bv = bvh::parse_bounding_volume(bv_);
    options.leaf_size = leaf_size_;
    options.arity = arity_;
    options.progress = context.progress;
    bvh::check_options(options);
    if (!output_.empty() && rays_.empty()) throw Error("bvh: -o needs --rays");
    const TriMesh mesh = io::read_mesh(mesh_);
    io::Table rays;
    if (!rays_.empty()) {
      rays = io::read_table(rays_, "ray", 6);
    }

    Stopwatch build_watch;
    const bvh::TriangleBvh bvh = bvh::TriangleBvh::build(mesh, options);
    const double build_s = build_watch.seconds();
    if (!save_.empty()) bvh.save(save_);
    Stopwatch stats_watch;
    const bvh::BvhStats s = bvh.stats();
    const double stats_s = stats_watch.seconds();

    double query_s = 0;
    std::size_t hits = 0;
    if (!rays_.empty()) {
      std::vector<double> out(rays.rows * 2);
      Stopwatch query_watch;
      const auto put = [&](std::size_t i, const RayHit& h) {
        out[2 * i] = h.hit() ? double(h.t) : std::numeric_limits<double>::infinity();
        out[2 * i + 1] = h.hit() ? double(h.prim) : -1.0;
      };
      const auto ray_at = [&](std::size_t i) {
        const double* r = &rays.values[6 * i];
        Ray3f ray;
        ray.origin = Vec3f(float(r[0]), float(r[1]), float(r[2]));
        ray.direction = Vec3f(float(r[3]), float(r[4]), float(r[5]));
        return ray;
      };
      if (packet_size_ != 0) {
        std::vector<Ray3f> all(rays.rows);
        std::vector<RayHit> found(rays.rows);
        parallel_for_each_index(0, rays.rows, [&](std::size_t i) { all[i] = ray_at(i); });
        bvh.intersect_packets(all, found, packet_size_);
        for (std::size_t i = 0; i < rays.rows; ++i) put(i, found[i]);
      } else {
        parallel_for_each_index(0, rays.rows, [&](std::size_t i) { put(i, bvh.intersect(ray_at(i))); }, 256);
      }
      query_s = query_watch.seconds();
      for (std::size_t i = 0; i < rays.rows; ++i) hits += out[2 * i + 1] >= 0;
      if (!output_.empty()) io::write_table(output_, std::span<const double>(out), {rays.rows, 2});
    }

    Json& j = report.json;
    j["mesh"] = mesh_;
    j["builder"] = builder_;
    j["bv"] = bv_;
    j["leaf_size"] = leaf_size_;
    j["arity"] = arity_;
    put_stats(j, s);
    j["build_s"] = build_s;
    j["stats_s"] = stats_s;
    if (!rays_.empty()) {
      j["rays"] = rays.rows;
      j["hits"] = hits;
      j["query_s"] = query_s;
      j["packets"] = packet_size_ != 0;
      j["packet_size"] = packet_size_;
      j["simd_level"] = simd_level_name(simd_level());
      j["mrays_per_s"] = query_s > 0 ? double(rays.rows) / query_s * 1e-6 : 0.0;
    }
    if (!save_.empty()) j["saved"] = save_;
    j["compute_s"] = build_s + stats_s + query_s;
    report.lines.push_back(fmt::format("bvh: {} triangles, builder {}, {} volumes, arity {}, leaf size {}",
                                       s.triangles, builder_, bv_, arity_, leaf_size_));
    report.lines.push_back(fmt::format("  built in {:.3f} s: {} nodes ({} leaves), depth {}, {:.1f} MB", build_s,
                                       s.nodes, s.leaves, s.depth, double(s.bytes) / 1e6));
    report.lines.push_back(fmt::format("  SAH cost {:.2f}, tightness: volume {:.3f} (Def. 4), Hausdorff {:.3f} (Def. 3)",
                                       s.sah_cost, s.tightness_volume, s.tightness_hausdorff));
    if (!rays_.empty())
      report.lines.push_back(fmt::format("  {} rays, {} hits in {:.3f} s ({:.2f} Mrays/s){}", rays.rows, hits, query_s,
                                         query_s > 0 ? double(rays.rows) / query_s * 1e-6 : 0.0,
                                         output_.empty() ? "" : ", wrote " + output_));
    if (!save_.empty()) report.lines.push_back("  saved the hierarchy to " + save_);
  }

 private:
  std::string mesh_, rays_, output_, save_;
  std::string builder_ = "sah", bv_ = "aabb";
  int leaf_size_ = 8, arity_ = 4;
  int packet_size_ = 0;  // 0: one ray at a time
};

const bool registered_bvh = register_command<BvhCommand>();

}  // namespace
}  // namespace geods::cli
