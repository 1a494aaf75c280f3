// geods render: ray-trace a mesh into a PNG with one of the ray accelerators.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <sstream>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/core/simd_level.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/ray/render.hpp"
#include "geods/ray/stats_fields.hpp"
#include "stats_json.hpp"

namespace geods::cli {
namespace {

// "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov": eye, target, up, vertical field of view in degrees.
ray::Camera parse_camera(const std::string& text) {
  std::vector<float> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stof(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw Error(fmt::format("render: --camera: '{}' is not a number", item));
    }
  }
  if (values.size() != 10)
    throw Error(fmt::format("render: --camera needs 10 numbers ex,ey,ez,tx,ty,tz,ux,uy,uz,fov (got {})", values.size()));
  ray::Camera camera{{values[0], values[1], values[2]}, {values[3], values[4], values[5]},
                     {values[6], values[7], values[8]}, values[9]};
  camera.check();
  return camera;
}

class RenderCommand : public Command {
 public:
  std::string name() const override { return "render"; }
  std::string summary() const override {
    return "ray-trace a mesh into a PNG (Lambert shading, optional shadows) with a ray accelerator";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "mesh", mesh_, "Mesh (PLY, OBJ, OFF, STL, glTF)");
    add_output(app, "-o,--output", output_, "Output image", io::OutputKind::image)->required();
    accel_option_ = app.add_option("--accel", accel_, "Accelerator: bvh, grid, octree or rays5d")->default_val(accel_);
    add_save(app, save_, "the accelerator (written before rendering)", "--load or Accelerator.load");
    app.add_option("--load", load_, "Render with an accelerator saved by --save over the same mesh (no build)");
    app.add_option("--width", width_, "Image width in pixels")->default_val(width_);
    app.add_option("--height", height_, "Image height in pixels")->default_val(height_);
    app.add_option("--camera", camera_, "ex,ey,ez,tx,ty,tz,ux,uy,uz,fov (default: a three-quarter view of the mesh)");
    app.add_flag("--shadows", shadows_, "Hard shadows (any-hit rays towards the light)");
    app.add_flag("--packets,!--no-packets", packets_,
                 "Shoot primary and shadow rays in packets of 4 x 4 pixels (default; the same picture)");
  }

  void run(const RunContext& context, Report& report) override {
    ray::RenderOptions options;
    options.accel = ray::parse_accelerator_kind(accel_);
    options.width = width_;
    options.height = height_;
    options.shadows = shadows_;
    options.packets = packets_;
    if (!camera_.empty()) options.camera = parse_camera(camera_);
    options.progress = context.progress;
    const TriMesh mesh = io::read_mesh(mesh_);
    std::unique_ptr<ray::Accelerator> accel;
    if (load_.empty()) {
      accel = ray::make_accelerator(mesh, options.accel, options.accel_options);
    } else {
      accel = ray::load_accelerator(load_);
      if (accel_option_->count() > 0 && accel->kind() != options.accel)
        throw Error(fmt::format("render: {} holds a {} accelerator, --accel asks for {}", load_,
                                ray::to_string(accel->kind()), accel_));
      accel_ = std::string(ray::to_string(accel->kind()));
    }
    if (!save_.empty()) accel->save(save_);
    ray::RenderResult result = ray::render(mesh, *accel, options);
    if (load_.empty()) result.build_s = accel->build_s();
    io::write_png(output_, result.image);

    const ray::AcceleratorStats& s = result.accel_stats;
    Json& j = report.json;
    j["mesh"] = mesh_;
    j["output"] = output_;
    j["triangles"] = mesh.num_triangles();
    j["accel"] = accel_;
    if (!load_.empty()) j["loaded"] = load_;
    if (!save_.empty()) j["saved"] = save_;
    j["width"] = width_;
    j["height"] = height_;
    j["shadows"] = shadows_;
    j["packets"] = packets_;
    j["simd_level"] = simd_level_name(simd_level());
    j["rays"] = result.rays;
    j["primary_hits"] = result.hits;
    j["occluder_cache_hits"] = result.occluder_hits;
    put_stats(j, s, "accel_");
    j["build_s"] = result.build_s;
    j["render_s"] = result.render_s;
    j["compute_s"] = result.build_s + result.render_s;
    j["mrays_per_s"] = result.mrays_per_s();
    report.lines.push_back(fmt::format("render: {} ({} triangles), {} x {}{}, accelerator {}", mesh_,
                                       mesh.num_triangles(), width_, height_, shadows_ ? ", shadows" : "", accel_));
    report.lines.push_back(fmt::format("  {}: {} nodes, {} triangle references, {:.1f} MB",
                                       load_.empty() ? fmt::format("built in {:.3f} s", result.build_s)
                                                     : "loaded from " + load_,
                                       s.nodes, s.references, double(s.bytes) / 1e6));
    if (!save_.empty()) report.lines.push_back("  saved the accelerator to " + save_);
    report.lines.push_back(fmt::format("  {} rays in {:.3f} s: {:.2f} Mrays/s", result.rays, result.render_s,
                                       result.mrays_per_s()));
    report.lines.push_back("  wrote " + output_);
  }

 private:
  std::string mesh_, output_, accel_ = "bvh", camera_, save_, load_;
  CLI::Option* accel_option_ = nullptr;
  int width_ = 512, height_ = 512;
  bool shadows_ = false;
  bool packets_ = true;
};

const bool registered_render = register_command<RenderCommand>();

}  // namespace
}  // namespace geods::cli
