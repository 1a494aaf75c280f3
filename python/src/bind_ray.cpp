// Python bindings of the ray module: geods.RayAccelerator and geods.render.
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
#include "mesh_arrays.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/ray/accelerator.hpp"
#include "geods/ray/render.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

template <typename T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

// Rays from (n, 3) origins and directions and a tmax that is one value or n.
std::vector<Ray3f> rays_from_arrays(const CArray<float>& origins, const CArray<float>& directions,
                                    const CArray<float>& tmax) {
  if (origins.ndim() != 2 || origins.shape(1) != 3) throw Error("RayAccelerator: origins must be an (n, 3) array");
  if (directions.ndim() != 2 || directions.shape(1) != 3 || directions.shape(0) != origins.shape(0))
    throw Error("RayAccelerator: directions must be an (n, 3) array like origins");
  const auto n = std::size_t(origins.shape(0));
  if (tmax.size() != 1 && std::size_t(tmax.size()) != n)
    throw Error("RayAccelerator: tmax must be one number or one per ray");
  std::vector<Ray3f> rays(n);
  const float *o = origins.data(), *d = directions.data(), *t = tmax.data();
  for (std::size_t i = 0; i < n; ++i) {
    rays[i].origin = Vec3f(o[3 * i], o[3 * i + 1], o[3 * i + 2]);
    rays[i].direction = Vec3f(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
    rays[i].tmax = t[tmax.size() == 1 ? 0 : i];
  }
  return rays;
}

class PyRayAccelerator {
 public:
  PyRayAccelerator(const CArray<float>& v, const CArray<std::int64_t>& f, const std::string& kind) {
    const TriMesh mesh = mesh_from_arrays(v, f, "RayAccelerator");
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

  py::tuple intersect(const CArray<float>& origins, const CArray<float>& directions, const CArray<float>& tmax) const {
    const std::vector<Ray3f> rays = rays_from_arrays(origins, directions, tmax);
    const auto n = py::ssize_t(rays.size());
    py::array_t<float> t(n), u(n), v(n);
    py::array_t<std::int64_t> prim(n);
    float *pt = t.mutable_data(), *pu = u.mutable_data(), *pv = v.mutable_data();
    std::int64_t* pp = prim.mutable_data();
    {
      py::gil_scoped_release release;
      parallel_for(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
        ray::RayCache cache;
        for (std::size_t i = b; i < e; ++i) {
          const RayHit hit = accel_->intersect(rays[i], cache);
          pt[i] = hit.t;
          pp[i] = hit.hit() ? std::int64_t(hit.prim) : -1;
          pu[i] = hit.u;
          pv[i] = hit.v;
        }
      });
    }
    return py::make_tuple(t, prim, u, v);
  }

  py::array_t<bool> occluded(const CArray<float>& origins, const CArray<float>& directions,
                             const CArray<float>& tmax) const {
    const std::vector<Ray3f> rays = rays_from_arrays(origins, directions, tmax);
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
    const ray::AcceleratorStats s = accel_->stats();
    py::dict d;
    d["kind"] = s.kind;
    d["triangles"] = s.triangles;
    d["nodes"] = s.nodes;
    d["leaves"] = s.leaves;
    d["references"] = s.references;
    d["depth"] = s.depth;
    d["bytes"] = s.bytes;
    d["build_s"] = s.build_s;
    if (s.kind == "grid") d["resolution"] = py::make_tuple(s.resolution[0], s.resolution[1], s.resolution[2]);
    return d;
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

py::array_t<std::uint8_t> render_py(const CArray<float>& v, const CArray<std::int64_t>& f, int width, int height,
                                    const std::optional<std::vector<float>>& camera, const std::string& accel,
                                    bool shadows) {
  const TriMesh mesh = mesh_from_arrays(v, f, "render");
  ray::RenderOptions options;
  options.width = width;
  options.height = height;
  options.shadows = shadows;
  options.accel = ray::parse_accelerator_kind(accel);
  if (camera) options.camera = camera_from_sequence(*camera);
  ray::RenderResult result;
  {
    py::gil_scoped_release release;
    result = ray::render(mesh, options);
  }
  py::array_t<std::uint8_t> image({py::ssize_t(result.image.height), py::ssize_t(result.image.width), py::ssize_t(3)});
  std::copy(result.image.data.begin(), result.image.data.end(), image.mutable_data());
  return image;
}

}  // namespace

void bind_ray(py::module_& m) {
  const float inf = std::numeric_limits<float>::infinity();
  py::class_<PyRayAccelerator>(m, "RayAccelerator",
                               "A ray accelerator over a triangle mesh: 'bvh', 'grid' (uniform grid with mailboxes), "
                               "'octree' (Revelles' parametric traversal) or 'rays5d' (5D ray classification).")
      .def(py::init<const CArray<float>&, const CArray<std::int64_t>&, const std::string&>(), py::arg("V"),
           py::arg("F"), py::arg("kind") = "bvh")
      .def("intersect", &PyRayAccelerator::intersect, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = CArray<float>(py::ssize_t(1), &inf),
           "Closest hits of (n, 3) rays: (t, prim, u, v); t = inf and prim = -1 on a miss. tmax: one value or n.")
      .def("occluded", &PyRayAccelerator::occluded, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = CArray<float>(py::ssize_t(1), &inf), "Whether each ray hits anything before tmax.")
      .def("stats", &PyRayAccelerator::stats, "Nodes, leaves, triangle references, depth, bytes, build_s.")
      .def("validate", &PyRayAccelerator::validate, "Checks the structure's invariants; raises ValueError if broken.")
      .def("save", &PyRayAccelerator::save, py::arg("path"),
           "Writes the accelerator with its triangles to a binary file ('rays5d': triangles and options only).")
      .def_static("load", &PyRayAccelerator::load, py::arg("path"),
                  "Maps a file written by save(), of any kind (read in place; the mesh is not needed).")
      .def_property_readonly("kind", &PyRayAccelerator::kind)
      .def_property_readonly("build_s", &PyRayAccelerator::build_s);
  m.def("render", &render_py, py::arg("V"), py::arg("F"), py::arg("width") = 512, py::arg("height") = 512,
        py::arg("camera") = py::none(), py::arg("accel") = "bvh", py::arg("shadows") = false,
        "Ray-traces the mesh (Lambert shading, optional hard shadows) into an (height, width, 3) uint8 image. "
        "camera: (ex, ey, ez, tx, ty, tz, ux, uy, uz[, fov]); default a three-quarter view.");
}

}  // namespace geods::python
