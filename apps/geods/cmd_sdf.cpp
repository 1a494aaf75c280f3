// geods sdf: the exact signed distance field of a triangle mesh on a grid.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/field/sdf_grid.hpp"
#include "geods/field/stats_fields.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/npy.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class SdfCommand : public Command {
 public:
  std::string name() const override { return "sdf"; }
  std::string summary() const override {
    return "exact signed distance field of a triangle mesh on a grid (negative inside), whole or in a narrow band";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "mesh", mesh_, "Triangle mesh (PLY, OBJ, STL, ... : anything Assimp reads)");
    app.add_option("-o,--output", output_, "Distances as float32 .npy of shape (nz, ny, nx)")->required();
    auto* res = app.add_option("--res", res_, "Samples along the mesh's longest side, padding included");
    auto* spacing = app.add_option("--spacing", spacing_, "Distance between samples (instead of --res)");
    res->excludes(spacing);
    app.add_option("--padding", padding_, "Samples of margin beyond the mesh's bounds on each side")
        ->capture_default_str();
    app.add_option("--band", band_,
                   "Half-width of a narrow band, in samples: samples farther from the surface get +-inf "
                   "(default: the whole grid)");
    app.add_option("--sign", sign_, "Inside by generalized winding number, by pseudonormals (closed meshes), or none")
        ->check(CLI::IsMember({"winding", "pseudonormal", "none"}))
        ->capture_default_str();
    app.add_option("--method", method_,
                   "exact, or propagation (exact on a shell about the surface, passed on to neighbours by two scans)")
        ->check(CLI::IsMember({"exact", "propagation"}))
        ->capture_default_str();
    app.add_option("--faces", faces_, "Also the closest face of each sample, int64 .npy (-1 outside the band)");
  }

  void run(const RunContext&, Report& report) override {
    for (const std::string& path : {output_, faces_})
      if (!path.empty() && std::filesystem::path(path).extension() != ".npy")
        throw Error("sdf: outputs are .npy files, got " + path);
    if (res_ == 0 && spacing_ == 0) throw Error("sdf: give --res N or --spacing H");
    if (spacing_ != 0 && !(spacing_ > 0)) throw Error(fmt::format("sdf: --spacing must be > 0, got {}", spacing_));
    const TriMesh mesh = io::read_mesh(mesh_);
    field::SdfGridOptions options;
    options.sign = field::parse_sign_method(sign_);
    options.faces = !faces_.empty();
    options.method = field::parse_sdf_method(method_);
    if (band_) options.band = *band_;
    // The grid is checked (and refused if too large) before the hierarchy is built.
    const Grid3Geometry grid = field::sdf_grid_geometry(mesh.bounds(), res_, spacing_, padding_);
    Stopwatch build_watch;
    const field::MeshDistance md = field::MeshDistance::build(mesh);
    const double build_s = build_watch.seconds();
    Stopwatch grid_watch;
    const field::SdfGrid r = field::sdf_grid(md, grid, options);
    const double grid_s = grid_watch.seconds();

    const std::vector<std::size_t> shape{grid.dims[2], grid.dims[1], grid.dims[0]};
    io::write_npy(output_, std::span<const float>(r.distance.data), shape);
    if (!faces_.empty()) {
      std::vector<std::int64_t> ids(r.faces.size());
      for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = r.faces[i] == field::kNoIndex ? -1 : std::int64_t(r.faces[i]);
      io::write_npy(faces_, std::span<const std::int64_t>(ids), shape);
    }

    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (const float d : r.distance.data)
      if (std::isfinite(d)) lo = std::min(lo, d), hi = std::max(hi, d);
    Json& j = report.json;
    j["mesh"] = mesh_;
    j["vertices"] = mesh.num_vertices();
    j["faces"] = mesh.num_triangles();
    j["closed"] = md.closed();
    j["dims"] = std::vector<std::size_t>(grid.dims.begin(), grid.dims.end());
    j["spacing"] = std::vector<double>{grid.spacing.x(), grid.spacing.y(), grid.spacing.z()};
    j["origin"] = std::vector<double>{grid.origin.x(), grid.origin.y(), grid.origin.z()};
    j["sign"] = sign_;
    j["method"] = method_;
    if (band_) j["band"] = *band_;
    put_stats(j, r.stats);
    j["inside"] = std::count_if(r.distance.data.begin(), r.distance.data.end(), [](float d) { return d < 0; });
    j["min_distance"] = lo;
    j["max_distance"] = hi;
    j["build_s"] = build_s;
    j["grid_s"] = grid_s;
    j["compute_s"] = build_s + grid_s;
    j["output"] = output_;
    if (!faces_.empty()) j["faces_output"] = faces_;
    report.lines.push_back(fmt::format("sdf: {} ({} vertices, {} faces, {}), grid {} x {} x {}, spacing {:.6g}",
                                       mesh_, mesh.num_vertices(), mesh.num_triangles(),
                                       md.closed() ? "closed" : "open", grid.dims[0], grid.dims[1], grid.dims[2],
                                       grid.spacing.x()));
    report.lines.push_back(fmt::format("  distances {:.6g} to {:.6g} ({} sign); {} of {} samples in the band",
                                       lo, hi, sign_, r.stats.in_band, r.stats.samples));
    report.lines.push_back(fmt::format("  built in {:.3f} s, grid in {:.3f} s; wrote {}{}", build_s, grid_s, output_,
                                       faces_.empty() ? "" : " and " + faces_));
  }

 private:
  std::string mesh_, output_, faces_, sign_ = "winding", method_ = "exact";
  std::size_t res_ = 0;
  double spacing_ = 0, padding_ = field::kDefaultPadding;
  std::optional<double> band_;
};

const bool registered_sdf = register_command<SdfCommand>();

}  // namespace
}  // namespace geods::cli
