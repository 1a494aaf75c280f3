// geods morph: a morph between two meshes through their signed distance fields (seed §6.2.1).
#include <fmt/format.h>

#include <regex>
#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/field/modeling.hpp"
#include "geods/field/morph.hpp"
#include "geods/field/stats_fields.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/table_io.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

// OUT_%d.ply -> OUT_3.ply (also %03d); the pattern must hold one such field.
std::string step_name(const std::string& pattern, std::size_t step) {
  static const std::regex field("%(0[0-9]+)?d");
  std::smatch m;
  if (!std::regex_search(pattern, m, field)) throw Error("morph: the output needs a %d for the step, got " + pattern);
  const std::string width = m[1].str();
  const std::string number =
      width.empty() ? std::to_string(step) : fmt::format("{:0{}}", step, std::stoi(width.substr(1)));
  return m.prefix().str() + number + m.suffix().str();
}

class MorphCommand : public Command {
 public:
  std::string name() const override { return "morph"; }
  std::string summary() const override {
    return "morph between two meshes through their signed distance fields, optionally warped by correspondences";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "a", a_, "The first mesh (PLY, OBJ, STL, ...): step 0");
    app.add_option("b", b_, "The second mesh: the last step")->required();
    app.add_option("--steps", steps_, "Number of meshes written, from A (t = 0) to B (t = 1)")
        ->check(at_least(2))
        ->required();
    app.add_option("--correspondences", correspondences_,
                   "Table of x0,y0,z0,x1,y1,z1 rows (.csv, .txt, .npy): a point on A and where it goes on B; "
                   "warps A by a rigid fit and radial basis functions (equation 17)");
    app.add_option("--res", res_, "Samples along the grid's longest side")->check(at_least(4))->capture_default_str();
    app.add_option("--kernel", kernel_, "Radial basis function of the elastic warp")
        ->check(CLI::IsMember({"thin_plate", "gaussian"}))
        ->capture_default_str();
    add_output(app, "-o,--output", output_, "Meshes, one per step: a name with %d (or %03d) for the step",
               io::OutputKind::mesh)
        ->required();
  }

  void run(const RunContext&, Report& report) override {
    step_name(output_, 0);  // the pattern is checked before anything is read
    const TriMesh a = io::read_mesh(a_), b = io::read_mesh(b_);
    field::MorphOptions options;
    options.res = res_;
    options.kernel = field::parse_rbf_kernel(kernel_);
    if (!correspondences_.empty()) {
      const io::Table t = io::read_table(correspondences_, "correspondence", 6);
      for (std::size_t i = 0; i < t.rows; ++i) {
        const auto r = t.row(i);
        options.from.emplace_back(r[0], r[1], r[2]);
        options.to.emplace_back(r[3], r[4], r[5]);
      }
    }
    Stopwatch build_watch;
    const field::Morph morph = field::Morph::build(a, b, options);
    const double build_s = build_watch.seconds();
    double steps_s = 0;
    std::vector<std::size_t> vertices, triangles;
    std::vector<std::string> outputs;
    for (std::size_t k = 0; k < steps_; ++k) {
      const double t = double(k) / double(steps_ - 1);
      Stopwatch watch;
      const TriMesh m = morph.surface(t);
      steps_s += watch.seconds();
      outputs.push_back(step_name(output_, k));
      io::write_mesh(outputs.back(), m);
      vertices.push_back(m.num_vertices());
      triangles.push_back(m.num_triangles());
    }
    const Grid3Geometry& g = morph.grid();
    Json& j = report.json;
    j["a"] = a_;
    j["b"] = b_;
    j["steps"] = steps_;
    j["res"] = res_;
    j["dims"] = std::vector<std::size_t>(g.dims.begin(), g.dims.end());
    j["spacing"] = g.spacing.x();
    j["warped"] = morph.warped();
    if (morph.warped()) j["kernel"] = kernel_;
    put_stats(j, morph.stats());
    j["vertices"] = vertices;
    j["triangles"] = triangles;
    j["build_s"] = build_s;
    j["steps_s"] = steps_s;
    j["compute_s"] = build_s + steps_s;
    j["outputs"] = outputs;
    report.lines.push_back(fmt::format("morph: {} -> {} in {} steps on a {} x {} x {} grid{}", a_, b_, steps_, g.dims[0],
                                       g.dims[1], g.dims[2],
                                       morph.warped() ? fmt::format(", warped by {} correspondences (rotation {:.1f} deg)",
                                                                    morph.stats().correspondences,
                                                                    morph.stats().rotation_angle * 180 / 3.141592653589793)
                                                      : ""));
    report.lines.push_back(fmt::format("  fields in {:.3f} s, steps in {:.3f} s; wrote {} .. {}", build_s, steps_s,
                                       outputs.front(), outputs.back()));
  }

 private:
  std::string a_, b_, correspondences_, output_, kernel_ = "thin_plate";
  std::size_t steps_ = 0, res_ = field::MorphOptions{}.res;
};

const bool registered_morph = register_command<MorphCommand>();

}  // namespace
}  // namespace geods::cli
