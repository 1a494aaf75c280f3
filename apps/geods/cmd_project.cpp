// geods project: distance field and discrete Voronoi diagram of sites by projecting their
// distance functions into a z-buffer (seed §6.1.2).
#include <fmt/format.h>

#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/field/projection.hpp"
#include "geods/field/stats_fields.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/table_io.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

class ProjectCommand : public Command {
 public:
  std::string name() const override { return "project"; }
  std::string summary() const override {
    return "distance field and discrete Voronoi diagram of points and segments by projected distance functions";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "sites", sites_, "Point sites, a table of x,y (2D) or x,y,z rows (.npy, .csv, .txt, .xyz, .ply)");
    app.add_option("--segments", segments_, "Segment sites: a table of x0,y0,x1,y1 (or x0,y0,z0,x1,y1,z1) rows");
    app.add_option("--size", size_, "Samples W,H (an image) or W,H,D (slices of a volume)")->required();
    app.add_option("--origin", origin_, "Position of sample (0, 0[, 0]): X,Y[,Z] (default 0)");
    app.add_option("--spacing", spacing_, "Distance between samples")->capture_default_str();
    app.add_option("--max-distance", max_distance_, "Bounded distance functions: farther samples get inf and id -1");
    add_output(app, "-o,--output", output_, "Distances, float64 .npy of shape (H, W) or (D, H, W)",
               io::OutputKind::array)
        ->required();
    add_output(app, "--ids", ids_, "Nearest site per sample (int64 .npy; points first, then segments; -1: none)",
               io::OutputKind::array);
  }

  void run(const RunContext&, Report& report) override {
    const std::vector<double> size = parse_numbers(size_);
    if (size.size() != 2 && size.size() != 3) throw Error("project: --size needs W,H or W,H,D, got " + size_);
    Grid3Geometry grid;
    for (std::size_t a = 0; a < size.size(); ++a) {
      if (!(size[a] >= 1 && size[a] <= 1e9 && size[a] == std::floor(size[a])))
        throw Error("project: --size needs positive integers, got " + size_);
      grid.dims[a] = std::size_t(size[a]);
    }
    if (size.size() == 2) grid.dims[2] = 1;
    if (!origin_.empty()) {
      const std::vector<double> o = parse_numbers(origin_);
      if (o.size() != size.size()) throw Error("project: --origin needs one value per axis of --size, got " + origin_);
      for (std::size_t a = 0; a < o.size(); ++a) grid.origin[Eigen::Index(a)] = float(o[a]);
    }
    grid.spacing = Vec3f::Constant(float(spacing_));
    const std::size_t dim = size.size();
    field::ProjectionSites sites;
    const io::Table points = io::read_table(sites_, "point", dim);
    for (std::size_t i = 0; i < points.rows; ++i)
      sites.points.emplace_back(points.row(i)[0], points.row(i)[1], dim == 3 ? points.row(i)[2] : 0.0);
    if (!segments_.empty()) {
      const io::Table s = io::read_table(segments_, "segment", 2 * dim);
      for (std::size_t i = 0; i < s.rows; ++i) {
        const auto r = s.row(i);
        sites.segments.push_back(dim == 2 ? std::array<Vec3d, 2>{Vec3d(r[0], r[1], 0), Vec3d(r[2], r[3], 0)}
                                          : std::array<Vec3d, 2>{Vec3d(r[0], r[1], r[2]), Vec3d(r[3], r[4], r[5])});
      }
    }
    field::ProjectionOptions options;
    if (max_distance_) options.max_distance = *max_distance_;
    Stopwatch watch;
    const field::Projection r = field::project_distance(sites, grid, options);
    const double compute_s = watch.seconds();
    std::vector<std::size_t> shape{grid.dims[1], grid.dims[0]};
    if (dim == 3) shape.insert(shape.begin(), grid.dims[2]);
    io::write_npy(output_, std::span<const double>(r.distance.data), shape);
    if (!ids_.empty()) {
      std::vector<std::int64_t> ids(r.ids.size());
      for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = r.ids[i] == field::kNoIndex ? -1 : std::int64_t(r.ids[i]);
      io::write_npy(ids_, std::span<const std::int64_t>(ids), shape);
    }
    Json& j = report.json;
    j["input"] = sites_;
    j["points"] = sites.points.size();
    j["segments"] = sites.segments.size();
    j["dims"] = std::vector<std::size_t>(grid.dims.begin(), grid.dims.end());
    j["spacing"] = spacing_;
    put_stats(j, r.stats);
    j["max_error"] = 0.0;  // exact distance functions at the sample positions
    j["compute_s"] = compute_s;
    j["output"] = output_;
    if (!ids_.empty()) j["ids_output"] = ids_;
    report.lines.push_back(fmt::format("project: {} points and {} segments onto {} x {} x {} samples", sites.points.size(),
                                       sites.segments.size(), grid.dims[0], grid.dims[1], grid.dims[2]));
    report.lines.push_back(fmt::format("  {:.2f} fragments per sample, {:.3f} s; wrote {}{}", r.stats.fragments_per_pixel,
                                       compute_s, output_, ids_.empty() ? "" : " and " + ids_));
  }

 private:
  std::string sites_, segments_, size_, origin_, output_, ids_;
  double spacing_ = 1;
  std::optional<double> max_distance_;
};

const bool registered_project = register_command<ProjectCommand>();

}  // namespace
}  // namespace geods::cli
