// geods adf: an adaptively sampled distance field of a triangle mesh (an
// octree of trilinear cells within a given error of the exact signed distance).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/field/adf.hpp"
#include "geods/field/stats_fields.hpp"
#include "geods/io/mesh_io.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class AdfCommand : public Command {
 public:
  std::string name() const override { return "adf"; }
  std::string summary() const override {
    return "adaptively sampled distance field of a triangle mesh: an octree whose cells interpolate the signed "
           "distance within --error";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "mesh", mesh_, "Triangle mesh (PLY, OBJ, STL, ... : anything Assimp reads)");
    app.add_option("--error", options_.error, "Largest error of the interpolation at each cell's test points (world units)")
        ->required();
    app.add_option("-o,--output", output_, "The ADF (a geods archive, read by Adf.load), e.g. ADF.geodsadf")->required();
    app.add_option("--max-depth", options_.max_depth, "Deepest octree level (the root is 0)")->capture_default_str();
    app.add_option("--band", band_,
                   "Half-width of a band about the surface (world units): the field is clamped to [-band, band] and "
                   "refined only near the surface (default: the whole field)");
    app.add_option("--checks", options_.checks,
                   "Test points per cell: an N x N x N lattice less the corners (odd; 3: the 19 edge, face and centre points)")
        ->capture_default_str();
    app.add_option("--padding", options_.padding, "Margin of the root cube beyond the mesh, times its largest extent")
        ->capture_default_str();
    app.add_option("--sign", sign_, "Inside by generalized winding number, by pseudonormals (closed meshes), or none")
        ->check(CLI::IsMember({"winding", "pseudonormal", "none"}))
        ->capture_default_str();
    app.add_option("--error-samples", error_samples_,
                   "Random points at which max_error is measured against the exact field (0: not measured)")
        ->capture_default_str();
    add_output(app, "--surface", surface_, "Output: the isosurface at --offset of the ADF", io::OutputKind::mesh);
    app.add_option("--offset", offset_, "Distance of the --surface from the mesh (negative: inside)")->capture_default_str();
    app.add_option("--res", res_, "Samples along the root cube's side for --surface (0: 2^min(depth, 8) + 1)")
        ->capture_default_str();
  }

  void run(const RunContext&, Report& report) override {
    options_.sign = field::parse_sign_method(sign_);
    if (band_) options_.band = *band_;
    const TriMesh mesh = io::read_mesh(mesh_);
    Stopwatch build_watch;
    const field::MeshDistance md = field::MeshDistance::build(mesh);
    const double build_s = build_watch.seconds();
    Stopwatch adf_watch;
    const field::Adf adf = field::Adf::build(mesh, md, options_);
    const double adf_s = adf_watch.seconds();
    adf.save(output_);
    field::AdfError error;
    if (error_samples_ > 0) error = field::measure_adf_error(adf, mesh, md, error_samples_);
    TriMesh surface;
    if (!surface_.empty()) {
      surface = adf.isosurface(offset_, res_);
      io::write_mesh(surface_, surface);
    }

    const field::AdfStats s = adf.stats();
    Json& j = report.json;
    j["mesh"] = mesh_;
    j["vertices"] = mesh.num_vertices();
    j["faces"] = mesh.num_triangles();
    j["error"] = options_.error;
    j["max_depth"] = options_.max_depth;
    if (band_) j["band"] = *band_;
    j["checks"] = options_.checks;
    j["sign"] = sign_;
    put_stats(j, s);
    j["ratio"] = double(s.dense_bytes) / double(s.bytes);
    if (error_samples_ > 0) {
      j["max_error"] = error.max_error;
      j["mean_error"] = error.mean_error;
      j["error_samples"] = error.samples;
    }
    j["build_s"] = build_s;
    j["adf_s"] = adf_s;
    j["compute_s"] = build_s + adf_s;
    j["output"] = output_;
    if (!surface_.empty()) j["surface_triangles"] = surface.num_triangles();
    report.lines.push_back(fmt::format("adf: {} ({} vertices, {} faces), error {:.6g}, {} cells ({} leaves), depth {}",
                                       mesh_, mesh.num_vertices(), mesh.num_triangles(), options_.error, s.cells,
                                       s.leaves, s.depth));
    report.lines.push_back(fmt::format("  {} bytes, {:.1f}x smaller than a dense grid of the finest cells ({} bytes); "
                                       "{} leaves over the error at max depth",
                                       s.bytes, double(s.dense_bytes) / double(s.bytes), s.dense_bytes, s.unresolved));
    if (error_samples_ > 0)
      report.lines.push_back(fmt::format("  error at {} random points: max {:.6g}, mean {:.6g}", error.samples,
                                         error.max_error, error.mean_error));
    report.lines.push_back(fmt::format("  built in {:.3f} s (hierarchy {:.3f} s); wrote {}{}", adf_s, build_s, output_,
                                       surface_.empty() ? "" : " and " + surface_));
  }

 private:
  std::string mesh_, output_, surface_, sign_ = "winding";
  field::AdfOptions options_;
  std::optional<double> band_;
  std::size_t error_samples_ = 10000, res_ = 0;
  double offset_ = 0;
};

const bool registered_adf = register_command<AdfCommand>();

}  // namespace
}  // namespace geods::cli
