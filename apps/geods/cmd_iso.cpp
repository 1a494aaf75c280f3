// geods iso: the isosurface of a volume by marching cubes (scan or min/max octree).
#include <fmt/format.h>

#include <optional>
#include <variant>
#include <vector>

#include "command.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/volume_io.hpp"
#include "geods/iso/marching_cubes.hpp"
#include "geods/iso/min_max_octree.hpp"
#include "stopwatch.hpp"

namespace geods::cli {
namespace {

class IsoCommand : public Command {
 public:
  std::string name() const override { return "iso"; }
  std::string summary() const override {
    return "isosurface of a volume (marching cubes, optionally through a min/max octree) as a mesh";
  }
  void add_options(CLI::App& app) override {
    add_input(app, "volume", volume_, "Volume: .npy (z, y, x), .nrrd, .nii/.nii.gz, or raw with --dims/--dtype");
    app.add_option("--iso", iso_, "Iso-value: samples >= it are inside")->required();
    add_output(app, "-o,--output", output_, "Output mesh, with normals where the format has them", io::OutputKind::mesh);
    app.add_option("--dims", dims_, "Raw input: samples along x, y, z (x fastest)")->delimiter(',')->expected(3);
    app.add_option("--dtype", dtype_, "Raw input: f32, u8, u16 or i16 (little-endian)");
    app.add_option("--coords", coords_,
                   "Curvilinear grid: float .npy of shape (z, y, x, 3), the x, y, z position of every sample");
    app.add_flag("--octree", octree_, "Build a min/max octree and extract through it (reports build_s, query_s)");
    app.add_option("--leaf-cells", leaf_cells_, "Octree: cells per leaf along each axis (1 to 32)")
        ->check(CLI::Range(std::size_t(1), iso::MinMaxOctree<float>::kMaxLeafCells));
    app.add_option("--sharing", sharing_,
                   "Octree: how cells share edge vertices: block_masks (bit masks per leaf, the default) or "
                   "hash_table (the hash table of seed 2.4); blocks and hash are deprecated spellings");
    app.add_flag("--no-normals", no_normals_, "Do not compute vertex normals");
    add_save(app, save_, "the min/max octree of --octree with its volume", "MinMaxOctree.load")->needs("--octree");
  }

  void run(const RunContext& context, Report& report) override {
    io::AnyGrid3 volume = read_input();
    const auto dims = std::visit([](const auto& g) { return g.dims; }, volume);
    std::vector<Vec3f> positions;
    if (!coords_.empty()) positions = read_coords(dims);
    iso::IsoOptions options;
    options.normals = !no_normals_;
    options.positions = positions;
    options.progress = context.progress;
    const iso::VertexSharing sharing = iso::parse_vertex_sharing(sharing_);

    TriMesh mesh;
    std::size_t cells_visited = 0, nodes_visited = 0;
    double build_s = 0, query_s = 0;
    std::visit(
        [&](auto& grid) {
          using T = typename std::decay_t<decltype(grid)>::value_type;
          if (octree_) {
            Stopwatch build_watch;
            const iso::MinMaxOctree<T> tree(std::move(grid), leaf_cells_);
            build_s = build_watch.seconds();
            if (!save_.empty()) tree.save(save_);
            Stopwatch query_watch;
            iso::OctreeIsoResult r = tree.isosurface(iso_, options, sharing);
            query_s = query_watch.seconds();
            mesh = std::move(r.mesh);
            cells_visited = r.cells_visited;
            nodes_visited = r.nodes_visited;
          } else {
            Stopwatch query_watch;
            mesh = iso::isosurface(grid, iso_, options, &cells_visited);
            query_s = query_watch.seconds();
          }
        },
        volume);
    if (!output_.empty()) io::write_mesh(output_, mesh);

    const std::size_t cells = dims[0] > 1 && dims[1] > 1 && dims[2] > 1 ? (dims[0] - 1) * (dims[1] - 1) * (dims[2] - 1) : 0;
    Json& j = report.json;
    j["volume"] = volume_;
    j["dims"] = {dims[0], dims[1], dims[2]};
    j["iso"] = iso_;
    j["method"] = octree_ ? "octree" : "scan";
    j["curvilinear"] = !coords_.empty();
    j["vertices"] = mesh.num_vertices();
    j["triangles"] = mesh.num_triangles();
    j["cells"] = cells;
    j["cells_visited"] = cells_visited;
    if (octree_) {
      j["leaf_cells"] = leaf_cells_;
      j["sharing"] = iso::to_string(sharing);
      j["nodes_visited"] = nodes_visited;
      j["build_s"] = build_s;
    }
    j["query_s"] = query_s;
    j["compute_s"] = build_s + query_s;
    if (!output_.empty()) j["output"] = output_;
    if (!save_.empty()) j["saved"] = save_;
    report.lines.push_back(fmt::format("iso: {} ({} x {} x {}) at {}{}", volume_, dims[0], dims[1], dims[2], iso_,
                                       coords_.empty() ? "" : ", curvilinear"));
    report.lines.push_back(fmt::format("  {} vertices, {} triangles; {} of {} cells visited ({:.2f} %)",
                                       mesh.num_vertices(), mesh.num_triangles(), cells_visited, cells,
                                       cells ? 100.0 * double(cells_visited) / double(cells) : 0.0));
    if (octree_)
      report.lines.push_back(fmt::format("  min/max octree built in {:.3f} s, queried in {:.3f} s ({} nodes tested, {} sharing)",
                                         build_s, query_s, nodes_visited, iso::to_string(sharing)));
    else
      report.lines.push_back(fmt::format("  extracted in {:.3f} s", query_s));
    if (!output_.empty()) report.lines.push_back("  wrote " + output_);
    if (!save_.empty()) report.lines.push_back("  wrote the octree to " + save_);
  }

 private:
  io::AnyGrid3 read_input() const {
    if (dims_.empty() != dtype_.empty())
      throw Error("iso: raw input needs both --dims and --dtype");
    if (dims_.empty()) return io::read_volume(volume_);
    const DType dtype = parse_dtype(dtype_);
    if (dtype != DType::f32 && dtype != DType::u8 && dtype != DType::u16 && dtype != DType::i16)
      throw Error("iso: --dtype must be f32, u8, u16 or i16");
    return io::read_raw_volume(volume_, {dims_[0], dims_[1], dims_[2]}, dtype);
  }

  std::vector<Vec3f> read_coords(const std::array<std::size_t, 3>& dims) const {
    const io::NpyArray a = io::read_npy(coords_);
    if (a.shape != std::vector<std::size_t>{dims[2], dims[1], dims[0], 3})
      throw Error(fmt::format("{}: coordinates of shape ({}), expected ({}, {}, {}, 3) for the volume", coords_,
                              fmt::join(a.shape, ", "), dims[2], dims[1], dims[0]));
    const std::vector<float> xyz = a.to_vector<float>();
    std::vector<Vec3f> positions(xyz.size() / 3);
    for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = Vec3f(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    return positions;
  }

  std::string volume_, output_, dtype_, coords_, save_, sharing_ = "block_masks";
  double iso_ = 0;
  std::vector<std::size_t> dims_;
  bool octree_ = false, no_normals_ = false;
  std::size_t leaf_cells_ = iso::MinMaxOctree<float>::kDefaultLeafCells;
};

const bool registered_iso = register_command<IsoCommand>();

}  // namespace
}  // namespace geods::cli
