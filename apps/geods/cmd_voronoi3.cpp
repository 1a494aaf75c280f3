// geods voronoi3: the Voronoi cells of 3D points clipped to a box, as closed polyhedra.
#include <fmt/format.h>

#include <vector>

#include "command.hpp"
#include "geods/core/error.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/voronoi/stats_fields.hpp"
#include "geods/voronoi/voronoi3.hpp"
#include "stats_json.hpp"
#include "stopwatch.hpp"
#include "voronoi_cli.hpp"

namespace geods::cli {
namespace {

using voronoi::Voronoi3;

// "x0,y0,z0,x1,y1,z1"; Voronoi3 checks lo < hi and finiteness.
AABB3d parse_box3(const std::string& text) {
  const std::vector<double> v = parse_numbers(text);
  if (v.size() != 6) throw Error("--box: expected X0,Y0,Z0,X1,Y1,Z1, got '" + text + "'");
  return AABB3d(Vec3d(v[0], v[1], v[2]), Vec3d(v[3], v[4], v[5]));
}

class Voronoi3Command : public Command {
 public:
  std::string name() const override { return "voronoi3"; }
  std::string summary() const override {
    return "Voronoi cells of 3D points clipped to a box or the convex hull: closed polyhedra (PLY), volumes and centroids";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "points", points_, "Sites, n x 3 (.npy, .csv, .txt, .xyz, .ply)");
    app.add_option("--box", box_, "The box X0,Y0,Z0,X1,Y1,Z1 (default: the sites' bounding box)");
    app.add_flag("--hull", hull_, "Clip the cells to the sites' convex hull instead of a box")->excludes("--box");
    app.add_option("-o,--output", output_, "Output: the cells as one triangle mesh (.ply, .obj, .stl), each closed");
    app.add_option("--explode", explode_,
                   "Move each cell away from the box centre by this fraction of its centroid's offset (0: none)")
        ->check(CLI::Range(0.0, 100.0));
    app.add_option("--volumes", volumes_,
                   "Output: float64 c x 5 per cell: site index, volume, centroid x, y, z (.npy)");
    add_save(app, save_, "the cells", "Voronoi3.load");
  }

  void run(const RunContext&, Report& report) override {
    const std::vector<Vec3d> points = read_points_3d(points_);
    AABB3d box;
    if (hull_) {
      if (points.empty()) throw Error(points_ + ": no points");
    } else if (box_.empty()) {
      for (const Vec3d& p : points) box.extend(p);
      if (points.empty()) throw Error(points_ + ": no points");
      for (int a = 0; a < 3; ++a)
        if (!(box.lo[a] < box.hi[a])) box.lo[a] -= 0.5, box.hi[a] += 0.5;  // flat along an axis: a unit slab
    } else {
      box = parse_box3(box_);
    }
    Stopwatch watch;
    const voronoi::Delaunay3 dt(points);
    const double build_s = watch.seconds();
    watch = Stopwatch();
    const Voronoi3 vd = hull_ ? Voronoi3(dt) : Voronoi3(dt, box);
    const double cells_s = watch.seconds();
    if (hull_) box = vd.box();
    const voronoi::Voronoi3Stats stats = vd.stats();
    if (!output_.empty()) io::write_mesh(output_, vd.mesh(explode_));
    if (!save_.empty()) vd.save(save_);
    if (!volumes_.empty()) {
      std::vector<double> rows;
      for (const auto& cell : vd.cells())
        rows.insert(rows.end(), {double(cell.site), cell.volume, cell.centroid[0], cell.centroid[1], cell.centroid[2]});
      io::write_npy<double>(volumes_, rows, {vd.cells().size(), 5});
    }
    Json& j = report.json;
    j["points"] = points.size();
    j["cells"] = vd.cells().size();
    put_stats(j, stats);
    j["volume_total"] = vd.volume_total();
    j["box_volume"] = (box.hi - box.lo).prod();  // with --hull: the hull's bounding box
    j["build_s"] = build_s;
    j["cells_s"] = cells_s;
    j["compute_s"] = build_s + cells_s;
    if (hull_)
      report.lines.push_back(fmt::format("voronoi3: {} points -> {} cells, {} faces; volume {:.6g} (the convex hull's)",
                                         points.size(), vd.cells().size(), stats.faces, vd.volume_total()));
    else
      report.lines.push_back(fmt::format("voronoi3: {} points -> {} cells ({} miss the box), {} faces; volume {:.6g} of a {:.6g} box",
                                         points.size(), vd.cells().size(), stats.empty, stats.faces, vd.volume_total(),
                                         (box.hi - box.lo).prod()));
    report.lines.push_back(fmt::format("  tetrahedralized in {:.3f} s, cells in {:.3f} s", build_s, cells_s));
    for (const std::string* path : {&output_, &volumes_, &save_})
      if (!path->empty()) report.lines.push_back("  wrote " + *path);
  }

 private:
  std::string points_, box_, output_, volumes_, save_;
  double explode_ = 0;
  bool hull_ = false;
};

const bool registered_voronoi3 = register_command<Voronoi3Command>();

}  // namespace
}  // namespace geods::cli
