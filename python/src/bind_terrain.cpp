// Python bindings of geods::terrain: Terrain (4-8 refinement, strips, TINs, mapped files).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <optional>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/terrain/stats_fields.hpp"
#include "geods/terrain/terrain.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

terrain::HeightField field_from(const py::object& heights, const std::array<double, 2>& spacing) {
  if (py::isinstance<py::str>(heights) || py::hasattr(heights, "__fspath__")) {
    terrain::HeightField f = terrain::read_height_field(py::cast<std::filesystem::path>(heights));
    f.spacing = spacing;
    return f;
  }
  const auto a = Rows<float>::ensure(heights);
  if (!a || a.ndim() != 2) throw Error("Terrain: heights must be a 2-D array (rows = y) or a file name");
  return terrain::make_height_field(std::span<const float>(a.data(), std::size_t(a.size())), std::size_t(a.shape(1)),
                                    std::size_t(a.shape(0)), spacing);
}

terrain::Refinement refinement_of(std::optional<double> max_error, const std::optional<py::dict>& camera,
                                  std::optional<double> pixel_error) {
  terrain::Refinement r;
  r.max_error = max_error;
  if (camera) {
    terrain::TerrainView v;
    const py::dict& c = *camera;
    for (const auto& item : c) {
      const std::string key = py::cast<std::string>(item.first);
      if (key != "eye" && key != "target" && key != "up" && key != "fov" && key != "size")
        throw Error("Terrain: unknown camera key '" + key + "' (eye, target, up, fov, size)");
    }
    if (!c.contains("eye") || !c.contains("target")) throw Error("Terrain: camera needs 'eye' and 'target'");
    v.camera.eye = point_of<float, 3>(c["eye"], "camera eye");
    v.camera.target = point_of<float, 3>(c["target"], "camera target");
    v.camera.up = c.contains("up") ? point_of<float, 3>(c["up"], "camera up") : Vec3f(0, 0, 1);
    v.camera.vertical_fov_deg = c.contains("fov") ? py::cast<float>(c["fov"]) : 60.0f;
    if (c.contains("size")) {
      const auto size = py::cast<std::array<int, 2>>(c["size"]);
      v.width = size[0], v.height = size[1];
    }
    r.view = v;
    r.pixel_error = pixel_error.value_or(1.0);
  } else if (pixel_error) {
    throw Error("Terrain: pixel_error needs a camera");
  }
  return r;
}

terrain::TerrainMesh refined(const terrain::Terrain& t, std::optional<double> max_error,
                             const std::optional<py::dict>& camera, std::optional<double> pixel_error,
                             std::uint32_t tiles) {
  const terrain::Refinement r = refinement_of(max_error, camera, pixel_error);
  return without_gil([&] { return t.refine_tiles(r, tiles); });
}

py::tuple mesh_tuple(const terrain::TerrainMesh& m) {
  TriMesh t;
  t.vertices = m.vertices;
  t.triangles = m.triangles;
  return mesh_arrays(t, false);
}

}  // namespace

void bind_terrain(py::module_& m) {
  py::class_<terrain::Terrain>(m, "Terrain",
                               "Terrain level of detail (Lindstrom-Pascucci 4-8 hierarchy) over a height field.")
      .def(py::init([](const py::object& heights, std::array<double, 2> spacing, double z_scale,
                       const std::string& layout) {
             terrain::TerrainOptions o;
             o.z_scale = z_scale;
             if (layout == "interleaved") o.layout = terrain::Layout::interleaved;
             else if (layout != "matrix")
               throw Error("Terrain: layout must be 'interleaved' or 'matrix', got '" + layout + "'");
             terrain::HeightField f = field_from(heights, spacing);
             return without_gil([&] { return terrain::Terrain(std::move(f), o); });
           }),
           py::arg("heights"), py::arg("spacing") = std::array<double, 2>{1, 1}, py::arg("z_scale") = 1.0,
           py::arg("layout") = "matrix",
           "Builds the hierarchy of a 2-D array of heights, (ny, nx) of any float or int dtype (rows = y; NaN = missing, filled from the nearest "
           "valid sample) or of a height-field file (.png, .bmp, .npy, .ter, GeoTIFF...). layout: 'matrix' (the faster in memory) or "
           "'interleaved'; save() writes the interleaved layout either way.")
      .def(
          "refine",
          [](const terrain::Terrain& t, std::optional<double> max_error, std::optional<py::dict> camera,
             std::optional<double> pixel_error, std::uint32_t tiles) {
            return mesh_tuple(refined(t, max_error, camera, pixel_error, tiles));
          },
          py::arg("max_error") = py::none(), py::arg("camera") = py::none(), py::arg("pixel_error") = py::none(),
          py::arg("tiles") = 1,
          "(V float32 (n, 3), F int32 (m, 3)): the crack-free mesh within max_error of every sample, and/or the "
          "view-dependent one for camera = {'eye', 'target', 'up', 'fov', 'size'} and pixel_error (default 1).")
      .def(
          "strip",
          [](const terrain::Terrain& t, std::optional<double> max_error, std::optional<py::dict> camera,
             std::optional<double> pixel_error, std::uint32_t tiles) {
            return index_array(refined(t, max_error, camera, pixel_error, tiles).strip);
          },
          py::arg("max_error") = py::none(), py::arg("camera") = py::none(), py::arg("pixel_error") = py::none(),
          py::arg("tiles") = 1,
          "The same mesh as one generalized triangle strip: int64 (k,) indices into refine()'s V (degenerate "
          "triangles join and turn it; triangle k is counter-clockwise for even k).")
      .def(
          "tin",
          [](const terrain::Terrain& t, double max_error, std::uint32_t tiles) {
            return mesh_tuple(without_gil([&] { return t.tin(max_error, tiles); }));
          },
          py::arg("max_error"), py::arg("tiles") = 1,
          "(V, F): a greedy-insertion Delaunay TIN within max_error of every sample (tiles x tiles, crack-free).")
      .def_property_readonly("width", &terrain::Terrain::width)
      .def_property_readonly("height", &terrain::Terrain::height)
      .def("stats", [](const terrain::Terrain& t) { return stats_dict(t.stats()); }, "dict of the TerrainStats fields")
      .def("save", &terrain::Terrain::save, py::arg("path"), "Writes the terrain in the interleaved layout (memory-mapped by load()).")
      .def_static(
          "load", [](const std::filesystem::path& path) { return terrain::Terrain::load(path); }, py::arg("path"),
          "Maps a terrain written by save(): its vertex records are read in place.");
  m.def(
      "tin_tile",
      [](const py::object& heights, double max_error, std::optional<double> border_limit) {
        const auto a = Rows<float>::ensure(heights);
        if (!a || a.ndim() != 2) throw Error("tin_tile: heights must be a 2-D array (rows = y)");
        const std::span<const float> z(a.data(), std::size_t(a.size()));
        if (!border_limit) {
          const auto [lo, hi] = z.empty() ? std::pair{0.0f, 0.0f} : std::pair{*std::min_element(z.begin(), z.end()),
                                                                               *std::max_element(z.begin(), z.end())};
          border_limit = terrain::tin_border_limit(max_error, lo, hi);
        }
        return mesh_tuple(without_gil([&] {
          return terrain::tin_tile(z, std::size_t(a.shape(1)), std::size_t(a.shape(0)), max_error, *border_limit);
        }));
      },
      py::arg("heights"), py::arg("max_error"), py::arg("border_limit") = py::none(),
      "(V, F): one tile of Terrain.tin computed on its own from the tile's block of heights (2-D, rows = y,\n"
      "finite): vertices at the block's sample coordinates (x, y, z). border_limit: the sides' tolerance,\n"
      "tin_border_limit(max_error, lo, hi) of the WHOLE field (default: of this block); with it, the tile\n"
      "[x0, x1] x [y0, y1] of Terrain(h).tin(max_error, tiles) is this mesh of h[y0:y1+1, x0:x1+1] shifted\n"
      "by (x0, y0) (geods.dask.terrain_tiles).");
  m.def("tin_border_limit", &terrain::tin_border_limit, py::arg("max_error"), py::arg("lo"), py::arg("hi"),
        "The side tolerance of Terrain.tin for a field whose samples span [lo, hi] (a little below max_error).");
}

}  // namespace geods::python
