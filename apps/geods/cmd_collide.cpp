// geods collide: collision detection / distance between two meshes, B in a
// sequence of poses (A at identity).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "command.hpp"
#include "geods/collide/collide.hpp"
#include "geods/collide/stats_fields.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/table_io.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class CollideCommand : public Command {
 public:
  std::string name() const override { return "collide"; }
  std::string summary() const override {
    return "collision detection and distance between two meshes, B in each of a list of poses (A at identity)";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "a", a_, "Mesh A (.ply, .obj, .stl, .off, ...), at identity");
    app.add_option("b", b_, "Mesh B, in each pose of --poses")->required();
    app.add_option("--poses", poses_, "Poses of B: N rows (qw, qx, qy, qz, tx, ty, tz), .npy, .csv or .txt")->required();
    app.add_option("--mode", mode_, "first: stop at the first contact; all: every intersecting triangle pair; "
                                    "distance: least distance and closest points")
        ->check(CLI::IsMember({"first", "all", "distance"}));
    app.add_option("--bv", bv_, "Bounding volume: aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, obb_hull, rss, "
                                "boxtree (restricted boxtree, AABBs)");
    app.add_option("--descend", descend_, "Which node of a pair to open: larger, count, a_first, b_first");
    app.add_option("--leaf-size", leaf_size_, "Most triangles per leaf")->check(at_least(1));
    app.add_option("--within", within_, "distance mode: stop once a pair within this distance is found");
    add_output(app, "-o,--output", output_,
               "Contacts: rows (pose, triangle of A, triangle of B); distance mode: rows (pose, distance, "
               "point on A xyz, point on B xyz)",
               io::OutputKind::table);
  }

  void run(const RunContext&, Report& report) override {
    collide::CollisionMeshOptions options;
    options.bv = collide::parse_collision_volume(bv_);
    options.leaf_size = leaf_size_;
    const collide::DescendRule rule = collide::parse_descend_rule(descend_);
    const std::vector<collide::Posed> poses = read_poses();
    const TriMesh ma = io::read_mesh(a_), mb = io::read_mesh(b_);

    Stopwatch watch;
    const collide::CollisionMesh a(ma, options);
    const collide::CollisionMesh b = b_ == a_ ? a : collide::CollisionMesh(mb, options);
    const double build_s = watch.seconds();

    const std::size_t n = poses.size();
    std::vector<collide::CollideResult> hits(mode_ == "distance" ? 0 : n);
    std::vector<collide::DistanceResult> dists(mode_ == "distance" ? n : 0);
    Stopwatch query;
    if (mode_ == "distance") {
      parallel_for_each_index(0, n, [&](std::size_t i) {
        dists[i] = collide::distance(a, collide::Posed{}, b, poses[i], {rule, within_});
      }, 1);
    } else {
      const collide::CollideRequest request{collide::parse_collide_mode(mode_), rule};
      parallel_for_each_index(0, n, [&](std::size_t i) { hits[i] = collide::collide(a, collide::Posed{}, b, poses[i], request); }, 1);
    }
    const double query_s = query.seconds();

    std::size_t colliding = 0, pairs = 0;
    collide::CollideStats stats;
    double min_distance = std::numeric_limits<double>::infinity();
    auto add = [&](const collide::CollideStats& s) {
      stats.volume_tests += s.volume_tests, stats.leaf_pairs += s.leaf_pairs, stats.triangle_tests += s.triangle_tests;
    };
    for (const auto& h : hits) colliding += h.colliding, pairs += h.pairs.size(), add(h.stats);
    for (const auto& d : dists) colliding += d.distance == 0, min_distance = std::min(min_distance, d.distance), add(d.stats);

    if (!output_.empty()) {
      if (mode_ == "distance") {
        std::vector<double> rows;
        for (std::size_t i = 0; i < n; ++i) {
          const auto& d = dists[i];
          rows.insert(rows.end(), {double(i), d.distance, d.point_a[0], d.point_a[1], d.point_a[2], d.point_b[0],
                                   d.point_b[1], d.point_b[2]});
        }
        io::write_table(output_, std::span<const double>(rows), {n, 8});
      } else {
        std::vector<std::int64_t> rows;
        for (std::size_t i = 0; i < n; ++i)
          for (const auto& c : hits[i].pairs) rows.insert(rows.end(), {std::int64_t(i), std::int64_t(c.a), std::int64_t(c.b)});
        io::write_table(output_, std::span<const std::int64_t>(rows), {rows.size() / 3, 3});
      }
    }

    Json& j = report.json;
    j["a"] = a_;
    j["b"] = b_;
    j["triangles_a"] = a.num_triangles();
    j["triangles_b"] = b.num_triangles();
    j["bv"] = bv_;
    j["mode"] = mode_;
    j["descend"] = descend_;
    j["poses"] = n;
    j["colliding"] = colliding;
    if (mode_ == "all") j["pairs"] = pairs;
    if (mode_ == "distance") j["min_distance"] = min_distance;
    collide::for_each_field(stats, [&](const char* name, const auto& v) { j[name] = v; });
    j["build_s"] = build_s;
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    if (!output_.empty()) j["output"] = output_;
    report.lines.push_back(fmt::format("collide: {} ({} triangles) and {} ({} triangles), {} poses of B, {} volumes",
                                       a_, a.num_triangles(), b_, b.num_triangles(), n, bv_));
    if (mode_ == "distance")
      report.lines.push_back(fmt::format("  {} poses in contact; least distance {:.6g}", colliding, min_distance));
    else
      report.lines.push_back(fmt::format("  {} poses collide{}", colliding,
                                         mode_ == "all" ? fmt::format(", {} triangle pairs in all", pairs) : ""));
    report.lines.push_back(fmt::format("  built in {:.3f} s, queries in {:.3f} s ({:.4f} ms per pose)", build_s,
                                       query_s, n ? 1e3 * query_s / double(n) : 0.0));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
  }

 private:
  std::vector<collide::Posed> read_poses() const {
    const io::Table table = io::read_table(poses_, "pose", 7);  // finite values, 7 per row
    std::vector<collide::Posed> poses;
    for (std::size_t i = 0; i < table.rows; ++i) {
      const auto r = table.row(i);
      if (r[0] == 0 && r[1] == 0 && r[2] == 0 && r[3] == 0)
        throw Error(fmt::format("{}: pose {} has a zero quaternion", poses_, i));
      poses.push_back(collide::Posed::from_row(r.data()));
    }
    return poses;
  }

  std::string a_, b_, poses_, output_, mode_ = "first", bv_ = "obb", descend_ = "larger";
  int leaf_size_ = 2;
  double within_ = -1;
};

const bool registered_collide = register_command<CollideCommand>();

}  // namespace
}  // namespace geods::cli
