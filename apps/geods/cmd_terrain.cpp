// geods terrain: a level-of-detail mesh of a height field (4-8 hierarchy or greedy TIN).
#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/ray/render.hpp"
#include "geods/terrain/stats_fields.hpp"
#include "geods/terrain/terrain.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class TerrainCommand : public Command {
 public:
  std::string name() const override { return "terrain"; }
  std::string summary() const override {
    return "level-of-detail mesh of a height field: 4-8 refinement by error or view (one triangle strip), or a greedy TIN";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "height", height_,
              "Height field: .png (8/16-bit grey), .bmp, .npy (2-D), .ter (Terragen), GeoTIFF or another GDAL "
              "raster; or a terrain saved with --save (.geodsterrain)");
    add_output(app, "-o,--output", output_, "The mesh", io::OutputKind::mesh)->required();
    app.add_option("--max-error", max_error_, "Maximum vertical error E (height units after --z-scale)");
    app.add_option("--eye", eye_, "View-dependent: camera position X,Y,Z")->delimiter(',')->expected(3);
    app.add_option("--target", target_, "View-dependent: point looked at X,Y,Z")->delimiter(',')->expected(3);
    app.add_option("--up", up_, "View-dependent: up vector (default 0,0,1)")->delimiter(',')->expected(3);
    app.add_option("--fov", fov_, "View-dependent: vertical field of view, degrees (default 60)");
    app.add_option("--size", size_, "View-dependent: image width,height in pixels (default 1024,768)")
        ->delimiter(',')
        ->expected(2);
    app.add_option("--pixel-error", pixel_error_, "View-dependent: screen-space error tau, pixels (default 1)");
    app.add_flag("--tin", tin_, "A greedy-insertion TIN (Delaunay) instead of the 4-8 mesh (with --max-error)");
    app.add_option("--tiles", tiles_, "Cut the field into N x N tiles meshed on their own, without cracks")
        ->check(at_least(1));
    app.add_option("--spacing", spacing_, "Sample spacing SX,SY (default: the file's, else 1,1)")
        ->delimiter(',')
        ->expected(2);
    app.add_option("--z-scale", z_scale_, "Height scale (default 1)");
    app.add_option("--layout", layout_,
                   "Vertex layout in memory: matrix (default; interleaved with --save) or interleaved; files are interleaved");
    add_save(app, save_, "the terrain (memory-mapped when read back)", "Terrain.load");
    add_output(app, "--strip", strip_, "The triangle strip as int64 vertex indices", io::OutputKind::array);
    add_output(app, "--png", png_, "A rendering of the mesh from the camera (or a three-quarter view)",
               io::OutputKind::image);
  }

  void run(const RunContext&, Report& report) override {
    const bool view = !eye_.empty() || !target_.empty();
    if (view && (eye_.empty() || target_.empty())) throw Error("terrain: --eye and --target go together");
    if (!max_error_ && !view) throw Error("terrain: give --max-error E or a view (--eye and --target)");
    if (tin_ && (!max_error_ || view)) throw Error("terrain: --tin takes --max-error and no view");
    terrain::Refinement refinement;
    refinement.max_error = max_error_;
    refinement.pixel_error = pixel_error_;
    if (view) {
      terrain::TerrainView v;
      v.camera.eye = Vec3f(float(eye_[0]), float(eye_[1]), float(eye_[2]));
      v.camera.target = Vec3f(float(target_[0]), float(target_[1]), float(target_[2]));
      if (!up_.empty()) v.camera.up = Vec3f(float(up_[0]), float(up_[1]), float(up_[2]));
      else v.camera.up = Vec3f(0, 0, 1);
      v.camera.vertical_fov_deg = float(fov_);
      if (!size_.empty()) v.width = size_[0], v.height = size_[1];
      refinement.view = v;
    }

    Stopwatch watch;
    terrain::Terrain t;
    const bool saved = std::filesystem::path(height_).extension() == ".geodsterrain";
    if (saved) {
      if (!spacing_.empty() || z_scale_ != 1 || !layout_.empty())
        throw Error("terrain: --spacing, --z-scale and --layout are fixed in a saved terrain");
      t = terrain::Terrain::load(height_);
    } else {
      terrain::HeightField field = terrain::read_height_field(height_);
      if (!spacing_.empty()) field.spacing = {spacing_[0], spacing_[1]};
      terrain::TerrainOptions options;
      options.z_scale = z_scale_;
      // With --save the file's layout unless asked: no rearranging, no second copy of the records.
      if (layout_ == "interleaved" || (layout_.empty() && !save_.empty())) options.layout = terrain::Layout::interleaved;
      else if (!layout_.empty() && layout_ != "matrix")
        throw Error("terrain: --layout must be interleaved or matrix, got '" + layout_ + "'");
      t = terrain::Terrain(std::move(field), options);
    }
    const double build_s = watch.seconds();
    if (!save_.empty()) t.save(save_);

    const Stopwatch refine_watch;
    const terrain::TerrainMesh mesh =
        tin_ ? t.tin(*max_error_, tiles_) : t.refine_tiles(refinement, tiles_);
    const double refine_s = refine_watch.seconds();
    const double measured = t.measure_error(mesh);

    TriMesh out;
    out.vertices = mesh.vertices;
    out.triangles = mesh.triangles;
    io::write_mesh(output_, out);
    if (!strip_.empty()) {
      std::vector<std::int64_t> s(mesh.strip.begin(), mesh.strip.end());
      io::write_npy(strip_, std::span<const std::int64_t>(s), {s.size()});
    }
    if (!png_.empty()) {
      ray::RenderOptions options;
      if (refinement.view) options.camera = refinement.view->camera;
      if (refinement.view) options.width = refinement.view->width, options.height = refinement.view->height;
      io::write_png(png_, ray::render(out, options).image);
    }

    const terrain::TerrainStats stats = t.stats();
    Json& j = report.json;
    j["height"] = height_;
    j["method"] = tin_ ? "tin" : "4-8";
    if (max_error_) j["max_error_bound"] = *max_error_;
    if (view) j["pixel_error"] = pixel_error_;
    j["tiles"] = tiles_;
    j["vertices"] = mesh.vertices.size();
    j["triangles"] = mesh.triangles.size();
    j["strip_length"] = mesh.strip.size();
    j["max_error"] = measured;
    j["unused_slots_pct"] = stats.unused_slots_pct;
    j["build_s"] = build_s;
    j["refine_s"] = refine_s;
    j["compute_s"] = build_s + refine_s;
    put_stats(j, stats, "terrain_");
    j["output"] = output_;
    report.lines.push_back(fmt::format("terrain: {} ({} x {} samples, grid {}^2{}), built in {:.3f} s", height_,
                                       stats.width, stats.height, stats.grid, saved ? ", mapped" : "", build_s));
    report.lines.push_back(fmt::format("  {} mesh: {} vertices, {} triangles, strip of {}, measured max error {:.6g}",
                                       tin_ ? "TIN" : "4-8", mesh.vertices.size(), mesh.triangles.size(),
                                       mesh.strip.size(), measured));
    report.lines.push_back(fmt::format("  refined in {:.4f} s; {:.1f} % unused slots ({} layout)", refine_s,
                                       stats.unused_slots_pct,
                                       t.layout().layout() == terrain::Layout::matrix ? "matrix" : "interleaved"));
    report.lines.push_back("  wrote " + output_);
  }

 private:
  std::string height_, output_, save_, strip_, png_, layout_;
  std::optional<double> max_error_;
  std::vector<double> eye_, target_, up_, spacing_;
  std::vector<int> size_;
  double fov_ = 60, pixel_error_ = 1, z_scale_ = 1;
  bool tin_ = false;
  std::uint32_t tiles_ = 1;
};

const bool registered_terrain = register_command<TerrainCommand>();

}  // namespace
}  // namespace geods::cli
