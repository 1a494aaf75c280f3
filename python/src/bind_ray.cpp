// Python bindings of the ray module: geods.Accelerator (alias: RayAccelerator) and geods.render.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "arrays.hpp"
#include "without_gil.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/ray/accelerator.hpp"
#include "geods/ray/render.hpp"
#include "geods/ray/stats_fields.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

class PyRayAccelerator {
 public:
  PyRayAccelerator(const Rows<float>& v, const Rows<std::int64_t>& f, const std::string& kind) {
    const TriMesh mesh = mesh_from_arrays(v, f, "Accelerator");
    const ray::AcceleratorKind k = ray::parse_accelerator_kind(kind);
    py::gil_scoped_release release;
    accel_ = ray::make_accelerator(mesh, k);
  }
  explicit PyRayAccelerator(std::unique_ptr<ray::Accelerator> accel) : accel_(std::move(accel)) {}

  void save(const std::filesystem::path& path) const { accel_->save(path); }
  static PyRayAccelerator load(const std::filesystem::path& path) {
    py::gil_scoped_release release;
    return PyRayAccelerator(ray::load_accelerator(path));
  }

  py::tuple intersect(const Rows<float>& origins, const Rows<float>& directions, const Rows<float>& tmax) const {
    const std::vector<Ray3f> rays = rays_from_arrays(origins, directions, tmax, "Accelerator");
    HitArrays hits(rays.size());
    {
      py::gil_scoped_release release;
      parallel_for(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
        ray::RayCache cache;
        for (std::size_t i = b; i < e; ++i) hits.set(i, accel_->intersect(rays[i], cache));
      });
    }
    return hits.tuple();
  }

  py::array_t<bool> occluded(const Rows<float>& origins, const Rows<float>& directions,
                             const Rows<float>& tmax) const {
    const std::vector<Ray3f> rays = rays_from_arrays(origins, directions, tmax, "Accelerator");
    py::array_t<bool> out(py::ssize_t(rays.size()));
    bool* po = out.mutable_data();
    {
      py::gil_scoped_release release;
      parallel_for(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
        ray::RayCache cache;
        for (std::size_t i = b; i < e; ++i) po[i] = accel_->occluded(rays[i], cache);
      });
    }
    return out;
  }

  py::dict stats() const {
    return stats_dict(accel_->stats());
  }

  void validate() const { accel_->validate(); }
  std::string kind() const { return std::string(ray::to_string(accel_->kind())); }
  double build_s() const { return accel_->build_s(); }

 private:
  std::unique_ptr<ray::Accelerator> accel_;
};

ray::Camera camera_from_sequence(const std::vector<float>& values) {
  if (values.size() != 9 && values.size() != 10)
    throw Error("render: camera must be (ex, ey, ez, tx, ty, tz, ux, uy, uz[, fov])");
  ray::Camera camera{{values[0], values[1], values[2]}, {values[3], values[4], values[5]},
                     {values[6], values[7], values[8]}};
  if (values.size() == 10) camera.vertical_fov_deg = values[9];
  camera.check();
  return camera;
}

py::array_t<std::uint8_t> render_py(const Rows<float>& v, const Rows<std::int64_t>& f, int width, int height,
                                    const std::optional<std::vector<float>>& camera, const std::string& accel,
                                    bool shadows, bool packets) {
  const TriMesh mesh = mesh_from_arrays(v, f, "render");
  ray::RenderOptions options;
  options.width = width;
  options.height = height;
  options.shadows = shadows;
  options.packets = packets;
  options.accel = ray::parse_accelerator_kind(accel);
  if (camera) options.camera = camera_from_sequence(*camera);
  const ray::RenderResult result = without_gil([&] { return ray::render(mesh, options); });
  return image_array(result.image);
}

}  // namespace

void bind_ray(py::module_& m) {
  const float inf = std::numeric_limits<float>::infinity();
  py::class_<PyRayAccelerator>(m, "Accelerator",
                               "A ray accelerator over a triangle mesh (C++ ray::Accelerator): 'bvh', 'grid' (uniform "
                               "grid with mailboxes), 'octree' (Revelles' parametric traversal) or 'rays5d' (5D ray "
                               "classification). geods.RayAccelerator is its deprecated older name.")
      .def(py::init<const Rows<float>&, const Rows<std::int64_t>&, const std::string&>(), py::arg("V"),
           py::arg("F"), py::arg("kind") = "bvh",
           "V: float32 (n, 3) vertices, F: int64 (m, 3) triangles; kind: bvh, grid, octree or rays5d")
      .def("intersect", &PyRayAccelerator::intersect, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = Rows<float>(py::ssize_t(1), &inf),
           "Closest hits of (n, 3) rays: (t, prim, u, v); t = inf and prim = -1 on a miss. tmax: one value or n.")
      .def("occluded", &PyRayAccelerator::occluded, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = Rows<float>(py::ssize_t(1), &inf), "Whether each ray hits anything before tmax: bool (n,) of rays origins, directions float32 (n, 3); tmax: one value or n.")
      .def("stats", &PyRayAccelerator::stats, "Nodes, leaves, triangle references, depth, bytes, build_s.")
      .def("validate", &PyRayAccelerator::validate, "Checks the structure's invariants; raises ValueError if broken.")
      .def("save", &PyRayAccelerator::save, py::arg("path"),
           "Writes the accelerator with its triangles to a binary file ('rays5d': triangles and options only).")
      .def_static("load", &PyRayAccelerator::load, py::arg("path"),
                  "Maps a file written by save(), of any kind (read in place; the mesh is not needed).")
      .def_property_readonly("kind", &PyRayAccelerator::kind)
      .def_property_readonly("build_s", &PyRayAccelerator::build_s);
  m.attr("RayAccelerator") = m.attr("Accelerator");  // deprecated: the name before Python took the C++ names
  m.def("render", &render_py, py::arg("V"), py::arg("F"), py::arg("width") = 512, py::arg("height") = 512,
        py::arg("camera") = py::none(), py::arg("accel") = "bvh", py::arg("shadows") = false,
        py::arg("packets") = true,
        "Ray-traces the mesh (Lambert shading, optional hard shadows) into an (height, width, 3) uint8 image. "
        "camera: (ex, ey, ez, tx, ty, tz, ux, uy, uz[, fov]); default a three-quarter view. packets: rays in "
        "packets of 4 x 4 pixels (the same image as packets=False, one ray at a time).");
}

}  // namespace geods::python
