// geods delaunay3: Delaunay tetrahedralization of 3D points.
#include <fmt/format.h>

#include <cstdint>
#include <vector>

#include "command.hpp"
#include "geods/io/npy.hpp"
#include "geods/core/parallel.hpp"
#include "geods/voronoi/delaunay3.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

using voronoi::Delaunay3;

class Delaunay3Command : public Command {
 public:
  std::string name() const override { return "delaunay3"; }
  std::string summary() const override {
    return "Delaunay tetrahedralization of 3D points: tetrahedra as int64 .npy";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "points", points_, "Points, n x 3 (.npy, .csv, .txt, .xyz, .ply)");
    app.add_option("-o,--output", output_,
                   "Output: int64 m x 4 positively oriented tetrahedra, indices into the points (duplicates map to "
                   "their first occurrence)");
    app.add_option("--neighbors", neighbors_,
                   "Output: int64 m x 4, the tetrahedron across the face opposite each vertex (-1 on the hull)");
    app.add_option("--hull", hull_, "Output: int64 h x 3 hull triangles, counter-clockwise seen from outside");
    app.add_option("--insertion", insertion_,
                   "How each point is inserted (seed 5.3.1): cavity (Bowyer-Watson) or flips (1-4, 2-3, 3-2); the "
                   "same tetrahedra")
        ->check(CLI::IsMember({"cavity", "flips"}))
        ->capture_default_str();
    add_save(app, save_, "the tetrahedralization", "Delaunay3.load");
  }

  void run(const RunContext&, Report& report) override {
    const std::vector<Vec3d> points = read_points_3d(points_);
    Stopwatch watch;
    voronoi::Delaunay3Options options;
    options.insertion = insertion_ == "flips" ? voronoi::Delaunay3Insertion::flips : voronoi::Delaunay3Insertion::cavity;
    const Delaunay3 dt(points, options);
    const double build_s = watch.seconds();
    const voronoi::Delaunay3Stats stats = dt.stats();

    const auto as_int64 = [](const auto& values) {
      std::vector<std::int64_t> out(values.size());
      for (std::size_t k = 0; k < values.size(); ++k)
        out[k] = values[k] == Delaunay3::no_index ? -1 : std::int64_t(values[k]);
      return out;
    };
    if (!output_.empty()) io::write_npy<std::int64_t>(output_, as_int64(dt.tetrahedra()), {dt.tetrahedron_count(), 4});
    if (!neighbors_.empty())
      io::write_npy<std::int64_t>(neighbors_, as_int64(dt.neighbors()), {dt.tetrahedron_count(), 4});
    if (!hull_.empty()) {
      std::vector<std::uint32_t> flat;
      for (const auto& t : dt.hull()) flat.insert(flat.end(), t.begin(), t.end());
      io::write_npy<std::int64_t>(hull_, as_int64(flat), {flat.size() / 3, 3});
    }

    if (!save_.empty()) dt.save(save_);

    Json& j = report.json;
    put_stats(j, stats);
    j["bytes_per_point"] = points.empty() ? 0.0 : double(stats.bytes) / double(points.size());
    j["threads"] = num_threads();
    j["insertion"] = insertion_;
    j["build_s"] = build_s;
    j["compute_s"] = build_s;
    const char* lower[] = {"no points", "all points equal", "all points collinear", "all points coplanar"};
    report.lines.push_back(fmt::format("delaunay3: {} points ({} distinct, {} duplicates) -> {} tetrahedra, {} hull triangles{}",
                                       points.size(), stats.vertices, stats.duplicates, stats.tetrahedra,
                                       stats.hull_triangles,
                                       dt.dimension() < 3 ? fmt::format(" (dimension {}: {})", dt.dimension(),
                                                                        lower[dt.dimension() + 1])
                                                          : ""));
    report.lines.push_back(fmt::format("  built in {:.3f} s on {} threads{} ({:.1f} bytes per point)", build_s,
                                       num_threads(),
                                       stats.seam_points ? fmt::format(", halves stitched at a seam of {} points",
                                                                       stats.seam_points)
                                                         : "",
                                       points.empty() ? 0.0 : double(stats.bytes) / double(points.size())));
    if (insertion_ == "flips")
      report.lines.push_back(fmt::format("  flips: {} 1-4, {} 2-3, {} 3-2, {} 4-4, {} face/edge splits, {} outside the hull",
                                         stats.flips_14, stats.flips_23, stats.flips_32, stats.flips_44, stats.splits,
                                         stats.hull_inserts));
    for (const std::string* path : {&output_, &neighbors_, &hull_, &save_})
      if (!path->empty()) report.lines.push_back("  wrote " + *path);
  }

 private:
  std::string points_, output_, neighbors_, hull_, save_, insertion_ = "cavity";
};

const bool registered_delaunay3 = register_command<Delaunay3Command>();

}  // namespace
}  // namespace geods::cli
