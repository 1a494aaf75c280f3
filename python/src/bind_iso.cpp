// Python bindings of the iso module: geods.isosurface and geods.MinMaxOctree.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "arrays.hpp"
#include "without_gil.hpp"
#include "bindings.hpp"
#include "geods/core/error.hpp"
#include "geods/iso/marching_cubes.hpp"
#include "geods/iso/min_max_octree.hpp"
#include "geods/iso/stats_fields.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

// The volume of isosurface() and MinMaxOctree(): volume_from_array with a finite, non-zero spacing.
io::AnyGrid3 volume_from(const py::array& array, const std::array<double, 3>& spacing,
                         const std::array<double, 3>& origin) {
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(spacing[d]) || spacing[d] == 0 || !std::isfinite(origin[d]))
      throw Error("isosurface: spacing must be finite and non-zero, origin finite");
  return volume_from_array(array, spacing, origin, "isosurface");
}

// Curvilinear node positions: float (nz, ny, nx, 3), x, y, z per sample.
std::vector<Vec3f> positions_from(const py::object& coords, const std::array<std::size_t, 3>& dims) {
  if (coords.is_none()) return {};
  auto a = Rows<float>::ensure(coords);
  if (!a || a.ndim() != 4 || std::size_t(a.shape(0)) != dims[2] || std::size_t(a.shape(1)) != dims[1] ||
      std::size_t(a.shape(2)) != dims[0] || a.shape(3) != 3)
    throw Error("isosurface: coords must be a float array of shape (nz, ny, nx, 3) matching the volume");
  return points_of<float, 3>(a.reshape({a.size() / 3, py::ssize_t(3)}), "isosurface: coords");
}

py::tuple isosurface_py(const py::array& volume, double iso, const std::array<double, 3>& spacing,
                        const std::array<double, 3>& origin, bool normals, const py::object& coords) {
  const io::AnyGrid3 grid = volume_from(volume, spacing, origin);
  const auto dims = std::visit([](const auto& g) { return g.dims; }, grid);
  const std::vector<Vec3f> positions = positions_from(coords, dims);
  iso::IsoOptions options;
  options.normals = normals;
  options.positions = positions;
  const TriMesh mesh =
      without_gil([&] { return std::visit([&](const auto& g) { return iso::isosurface(g, iso, options); }, grid); });
  return mesh_arrays(mesh, true);
}

// geods.MinMaxOctree: an octree of any sample type plus the counts of the last query.
class PyOctree {
 public:
  PyOctree(const py::array& volume, std::size_t leaf_cells, const std::array<double, 3>& spacing,
           const std::array<double, 3>& origin) {
    io::AnyGrid3 grid = volume_from(volume, spacing, origin);
    py::gil_scoped_release release;
    tree_ = std::visit(
        [&](auto& g) -> AnyTree {
          using T = typename std::decay_t<decltype(g)>::value_type;
          return std::make_shared<const iso::MinMaxOctree<T>>(std::move(g), leaf_cells);
        },
        grid);
  }

  py::tuple isosurface(double iso, bool normals, const py::object& coords, const std::string& sharing) {
    const iso::VertexSharing mode = iso::parse_vertex_sharing(sharing);
    const auto dims = std::visit([](const auto& t) { return t->volume().dims; }, tree_);
    const std::vector<Vec3f> positions = positions_from(coords, dims);
    iso::OctreeIsoResult r;
    {
      py::gil_scoped_release release;
      iso::IsoOptions options;
      options.normals = normals;
      options.positions = positions;
      r = std::visit([&](const auto& t) { return t->isosurface(iso, options, mode); }, tree_);
    }
    cells_visited_ = r.cells_visited;
    nodes_visited_ = r.nodes_visited;
    return mesh_arrays(r.mesh, true);
  }

  py::dict stats() const {
    return stats_dict(std::visit([](const auto& t) { return t->stats(); }, tree_));
  }
  void validate() const {
    std::visit([](const auto& t) { t->validate(); }, tree_);
  }

  void save(const std::filesystem::path& path) const {
    py::gil_scoped_release release;
    std::visit([&](const auto& t) { t->save(path); }, tree_);
  }
  static PyOctree load(const std::filesystem::path& path) {
    py::gil_scoped_release release;
    switch (iso::read_min_max_octree_scalar(path)) {
      case DType::u8: return PyOctree(load_tree<std::uint8_t>(path));
      case DType::u16: return PyOctree(load_tree<std::uint16_t>(path));
      case DType::i16: return PyOctree(load_tree<std::int16_t>(path));
      case DType::f32: return PyOctree(load_tree<float>(path));
      case DType::f64: return PyOctree(load_tree<double>(path));
      default: throw Error(path.string() + ": a min/max octree of an unsupported sample type");
    }
  }

  std::optional<std::size_t> cells_visited() const { return cells_visited_; }
  std::optional<std::size_t> nodes_visited() const { return nodes_visited_; }

 private:
  using AnyTree = std::variant<std::shared_ptr<const iso::MinMaxOctree<std::uint8_t>>,
                               std::shared_ptr<const iso::MinMaxOctree<std::uint16_t>>,
                               std::shared_ptr<const iso::MinMaxOctree<std::int16_t>>,
                               std::shared_ptr<const iso::MinMaxOctree<float>>,
                               std::shared_ptr<const iso::MinMaxOctree<double>>>;
  explicit PyOctree(AnyTree tree) : tree_(std::move(tree)) {}
  template <typename T>
  static AnyTree load_tree(const std::filesystem::path& path) {
    return std::make_shared<const iso::MinMaxOctree<T>>(iso::MinMaxOctree<T>::load(path));
  }

  AnyTree tree_;
  std::optional<std::size_t> cells_visited_, nodes_visited_;
};

}  // namespace

void bind_iso(py::module_& m) {
  const std::array<double, 3> ones{1, 1, 1}, zeros{0, 0, 0};
  m.def("isosurface", &isosurface_py, py::arg("volume"), py::arg("t"), py::arg("spacing") = ones,
        py::arg("origin") = zeros, py::arg("normals") = true, py::arg("coords") = py::none(),
        R"doc(Isosurface {value = t} of a volume by marching cubes -> (V, F, N).

volume is a 3-D array indexed [z, y, x] (x fastest, as geods.read_volume
returns it); sample (i, j, k) = volume[k, j, i] sits at origin + (i, j, k) *
spacing, with spacing and origin given as (x, y, z). Samples >= t are inside.
V: float32 (n, 3) vertices, F: int32 (m, 3) triangles oriented from inside to
outside, N: float32 (n, 3) unit normals from the field gradient (shape (0, 3)
with normals=False). A surface that does not reach the volume's border is a
closed, consistently oriented 2-manifold (ambiguous faces resolved by the
asymptotic decider). coords, a float (nz, ny, nx, 3) array of sample
positions, makes the grid curvilinear (spacing and origin are then unused).
Raises geods.Error for a non-finite t, NaN samples or mismatched coords.)doc");
  py::class_<PyOctree>(m, "MinMaxOctree", R"doc(Min/max octree over the cells of a volume (seed §2.4).

Built once, then isosurface(t) for many t visits only the nodes whose
min < t <= max. The volume is copied; axis order, spacing and origin as for
geods.isosurface. leaf_cells: cells per leaf along each axis, 1 to 32 (1: one
cell per leaf, the textbook octree).)doc")
      .def(py::init<const py::array&, std::size_t, const std::array<double, 3>&, const std::array<double, 3>&>(),
           py::arg("volume"), py::arg("leaf_cells") = iso::MinMaxOctree<float>::kDefaultLeafCells,
           py::arg("spacing") = ones, py::arg("origin") = zeros,
           "volume: (nz, ny, nx) of uint8, uint16, int16 or float32; spacing and origin (x, y, z)")
      .def("isosurface", &PyOctree::isosurface, py::arg("t"), py::arg("normals") = true,
           py::arg("coords") = py::none(), py::arg("sharing") = "block_masks",
           "(V, F, N) exactly as geods.isosurface(volume, t) gives them (in another order). sharing: how the\n"
           "cells around a grid edge share its vertex, 'block_masks' (bit masks per crossed leaf, the default)\n"
           "or 'hash_table' (the edge hash table of seed 2.4); 'blocks' and 'hash' are deprecated spellings.")
      .def_property_readonly("cells_visited", &PyOctree::cells_visited,
                             "Cells examined by the last isosurface() call (None before the first).")
      .def_property_readonly("nodes_visited", &PyOctree::nodes_visited,
                             "Octree nodes tested by the last isosurface() call (None before the first).")
      .def("stats", &PyOctree::stats, "dict: nodes, levels, leaf_cells, cells, bytes")
      .def("validate", &PyOctree::validate, "Checks every node's min/max; raises geods.Error if one is wrong.")
      .def("save", &PyOctree::save, py::arg("path"),
           "Writes the octree and its volume to a geods archive (the file format of every structure).")
      .def_static("load", &PyOctree::load, py::arg("path"),
                  "Reads an octree written by save() (any sample type): the samples and the min/max arrays are\n"
                  "read in place from the mapped file (no copy). Raises ValueError for a truncated, corrupt or\n"
                  "other file.");
}

}  // namespace geods::python
