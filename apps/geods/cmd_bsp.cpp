// geods bsp: the BSP tree of a mesh (seed §3): nodes, depth, fragments, expected cost.
// geods csg: a boolean operation on two closed meshes by merging their BSP trees.
#include <fmt/format.h>

#include "command.hpp"
#include "geods/bsp/csg.hpp"
#include "geods/bsp/stats_fields.hpp"
#include "geods/core/error.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/npy.hpp"
#include "stats_json.hpp"

namespace geods::cli {
namespace {

class BspCommand : public Command {
 public:
  std::string name() const override { return "bsp"; }
  std::string summary() const override {
    return "BSP tree of a mesh (auto-partition by cost or random-k, balanced planes, or customized for a ray "
           "sample): nodes, depth, fragments, expected cost, work per ray";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "mesh", mesh_, "Triangle mesh (.ply, .obj, .off, .stl, .gltf)");
    app.add_option("--heuristic", heuristic_,
                   "cost (equation (5)), random (k random, fewest splits), balanced, or custom (customized for the "
                   "rays of --rays, §3.4.3)");
    app.add_option("--alpha", options_.alpha, "Equation (5): weight |S-|^alpha + |S+|^alpha (> 0)");
    app.add_option("--beta", options_.beta, "Equation (5): penalty per split polygon (>= 0)");
    app.add_option("--k", k_, "Candidate polygons per node: the k largest (cost), k random (random) or the k best-scoring, one "
                   "taken at random (custom)")
        ->check(at_least(1));
    app.add_option("--seed", options_.seed, "Seed of the random choices");
    app.add_option("--rays", rays_,
                   "Rays (.npy, (n, 6): origin x y z, direction x y z): the sample of --heuristic custom; with any "
                   "heuristic, first hits are computed for them and the work per ray reported");
    add_save(app, save_, "the tree", "BspTree.load");
  }
  void run(const RunContext&, Report& report) override {
    options_.heuristic = bsp::parse_heuristic(heuristic_);
    options_.k = static_cast<std::uint32_t>(k_);
    bsp::RayQuery rays;
    if (!rays_.empty()) {
      const io::NpyArray a = io::read_npy(rays_);
      if (a.shape.size() != 2 || a.shape[1] != 6)
        throw Error(fmt::format("{}: rays of shape ({}), expected (n, 6)", rays_, fmt::join(a.shape, ", ")));
      const std::vector<double> r = a.to_vector<double>();
      for (std::size_t i = 0; i < a.shape[0]; ++i) {
        rays.origins.emplace_back(r[6 * i], r[6 * i + 1], r[6 * i + 2]);
        rays.directions.emplace_back(r[6 * i + 3], r[6 * i + 4], r[6 * i + 5]);
      }
    } else if (options_.heuristic == bsp::Heuristic::custom) {
      throw Error("bsp: --heuristic custom needs --rays");
    }
    if (options_.heuristic == bsp::Heuristic::custom) options_.rays = rays;
    const bsp::Triangles mesh = bsp::from_tri_mesh(io::read_mesh(mesh_));
    const bsp::BspTree tree(mesh.vertices, mesh.triangles, options_);
    if (!save_.empty()) tree.save(save_);
    const bsp::BspStats& s = tree.stats();
    Json& j = report.json;
    j["mesh"] = mesh_;
    j["heuristic"] = heuristic_;
    j["alpha"] = options_.alpha;
    j["beta"] = options_.beta;
    j["k"] = k_;
    put_stats(j, s);
    j["grid_step"] = tree.grid().step();
    report.lines.push_back(fmt::format("bsp: {} polygons, heuristic {} (alpha {}, beta {}, k {})", s.polygons,
                                       heuristic_, options_.alpha, options_.beta, k_));
    report.lines.push_back(fmt::format("  built in {:.3f} s: {} nodes ({} leaves), depth {}, {} fragments, expected cost {:.2f}",
                                       s.build_s, s.nodes, s.leaves, s.depth, s.fragments, s.expected_cost));
    if (!rays.origins.empty()) {
      const bsp::RayQueryStats r = tree.first_hits(rays).stats;
      Json& jr = j["first_hits"];
      put_stats(jr, r);
      report.lines.push_back(fmt::format("  {} rays ({} hits): {:.1f} nodes visited and {:.1f} polygon tests per ray, {:.4f} s",
                                         r.rays, r.hits, r.nodes_per_ray, r.tests_per_ray, r.query_s));
    }
  }

 private:
  std::string mesh_, heuristic_ = "cost", rays_, save_;
  long long k_ = 8;
  bsp::BuildOptions options_;
};

class CsgCommand : public Command {
 public:
  std::string name() const override { return "csg"; }
  std::string summary() const override {
    return "boolean operation (union, intersection, difference, xor) of two closed meshes (local BSPs or BSP merging)";
  }
  void add_options(CLI::App& app) override {
    app.add_option("a", a_, "First closed mesh")->required();
    app.add_option("op", op_, "union, intersection, difference (a minus b) or xor")->required();
    app.add_option("b", b_, "Second closed mesh")->required();
    add_output(app, "-o,--output", output_, "Output: the closed result mesh", io::OutputKind::mesh)->required();
    app.add_option("--heuristic", heuristic_, "BSP construction of the operands: cost, random or balanced");
    app.add_option("--k", k_, "Candidate polygons per node")->check(at_least(1));
    app.add_option("--method", method_,
                   "local (cut only near the other operand, local BSPs) or bsp_merge (merge the operands' BSP trees)");
  }
  void run(const RunContext&, Report& report) override {
    const bsp::CsgOp op = bsp::parse_csg_op(op_);
    const bsp::CsgMethod method = bsp::parse_csg_method(method_);
    const bsp::Triangles a = bsp::from_tri_mesh(io::read_mesh(a_));
    const bsp::Triangles b = bsp::from_tri_mesh(io::read_mesh(b_));
    bsp::BuildOptions options;
    options.heuristic = bsp::parse_heuristic(heuristic_);
    options.k = static_cast<std::uint32_t>(k_);
    const bsp::CsgResult r = bsp::csg(a, b, op, options, method);
    io::write_mesh(output_, bsp::to_tri_mesh(r.mesh));
    const bsp::CsgStats& s = r.stats;
    Json& j = report.json;
    j["a"] = a_;
    j["op"] = op_;
    j["b"] = b_;
    j["output"] = output_;
    j["method"] = method_;
    put_stats(j, s);
    report.lines.push_back(fmt::format("csg: {} {} {} -> {}", a_, op_, b_, output_));
    report.lines.push_back(fmt::format("  {} vertices, {} triangles, {}, volume {:.6g} (operands {:.6g}, {:.6g}), "
                                       "{} BSP nodes ({}), {:.3f} s",
                                       s.vertices, s.triangles, s.closed ? "closed" : "NOT closed", s.volume,
                                       s.volume_a, s.volume_b, s.bsp_nodes, method_, s.compute_s));
  }

 private:
  std::string a_, op_, b_, output_, heuristic_ = "cost", method_ = "local";
  long long k_ = 8;
};

const bool registered_bsp = register_command<BspCommand>();
const bool registered_csg = register_command<CsgCommand>();

}  // namespace
}  // namespace geods::cli
