// Python bindings of the bvh module: geods.Bvh.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "index_arrays.hpp"
#include "mesh_arrays.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

template <typename T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

const float* rows3(const CArray<float>& a, const char* what, std::size_t& n) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw Error(std::string("Bvh: ") + what + " must be an (n, 3) array");
  n = std::size_t(a.shape(0));
  return a.data();
}

class PyBvh {
 public:
  PyBvh(const CArray<float>& v, const CArray<std::int64_t>& f, const std::string& builder, const std::string& bv,
        int leaf_size, int arity) {
    const TriMesh mesh = mesh_from_arrays(v, f, "Bvh");
    bvh::BuildOptions options;
    options.builder = bvh::parse_builder(builder);
    options.bv = bvh::parse_bounding_volume(bv);
    options.leaf_size = leaf_size;
    options.arity = arity;
    py::gil_scoped_release release;
    bvh_ = bvh::TriangleBvh::build(mesh, options);
  }
  explicit PyBvh(bvh::TriangleBvh bvh) : bvh_(std::move(bvh)) {}

  void save(const std::filesystem::path& path) const { bvh_.save(path); }
  static PyBvh load(const std::filesystem::path& path) {
    py::gil_scoped_release release;
    return PyBvh(bvh::TriangleBvh::load(path));
  }

  std::vector<Ray3f> rays(const CArray<float>& origins, const CArray<float>& directions, const CArray<float>& tmax) const {
    std::size_t n = 0, m = 0;
    const float* o = rows3(origins, "origins", n);
    const float* d = rows3(directions, "directions", m);
    if (m != n) throw Error("Bvh: directions must have as many rows as origins");
    if (tmax.size() != 1 && std::size_t(tmax.size()) != n) throw Error("Bvh: tmax must be one number or one per ray");
    std::vector<Ray3f> out(n);
    const float* t = tmax.data();
    for (std::size_t i = 0; i < n; ++i) {
      out[i].origin = Vec3f(o[3 * i], o[3 * i + 1], o[3 * i + 2]);
      out[i].direction = Vec3f(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
      out[i].tmax = t[tmax.size() == 1 ? 0 : i];
    }
    return out;
  }

  py::tuple intersect(const CArray<float>& origins, const CArray<float>& directions, const CArray<float>& tmax) const {
    const std::vector<Ray3f> r = rays(origins, directions, tmax);
    const auto n = py::ssize_t(r.size());
    py::array_t<float> t(n), u(n), v(n);
    py::array_t<std::int64_t> prim(n);
    float *pt = t.mutable_data(), *pu = u.mutable_data(), *pv = v.mutable_data();
    std::int64_t* pp = prim.mutable_data();
    {
      py::gil_scoped_release release;
      parallel_for_each_index(0, r.size(), [&](std::size_t i) {
        const RayHit h = bvh_.intersect(r[i]);
        pt[i] = h.hit() ? h.t : std::numeric_limits<float>::infinity();
        pp[i] = h.hit() ? std::int64_t(h.prim) : -1;
        pu[i] = h.u;
        pv[i] = h.v;
      }, 256);
    }
    return py::make_tuple(t, prim, u, v);
  }

  py::array_t<bool> occluded(const CArray<float>& origins, const CArray<float>& directions, const CArray<float>& tmax) const {
    const std::vector<Ray3f> r = rays(origins, directions, tmax);
    py::array_t<bool> out(py::ssize_t(r.size()));
    bool* po = out.mutable_data();
    py::gil_scoped_release release;
    parallel_for_each_index(0, r.size(), [&](std::size_t i) { po[i] = bvh_.occluded(r[i]); }, 256);
    return out;
  }

  py::tuple closest_point(const CArray<float>& points) const {
    std::size_t n = 0;
    const float* p = rows3(points, "points", n);
    py::array_t<float> q({py::ssize_t(n), py::ssize_t(3)});
    py::array_t<std::int64_t> prim{py::ssize_t(n)};
    py::array_t<float> dist{py::ssize_t(n)};
    float *pq = q.mutable_data(), *pd = dist.mutable_data();
    std::int64_t* pp = prim.mutable_data();
    {
      py::gil_scoped_release release;
      parallel_for_each_index(0, n, [&](std::size_t i) {
        const bvh::ClosestPoint c = bvh_.closest_point(Vec3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
        for (int a = 0; a < 3; ++a) pq[3 * i + std::size_t(a)] = c.prim == RayHit::no_hit ? NAN : c.point[a];
        pp[i] = c.prim == RayHit::no_hit ? -1 : std::int64_t(c.prim);
        pd[i] = c.distance;
      }, 64);
    }
    return py::make_tuple(q, prim, dist);
  }

  py::array_t<bool> contains(const CArray<float>& points) const {
    std::size_t n = 0;
    const float* p = rows3(points, "points", n);
    py::array_t<bool> out{py::ssize_t(n)};
    bool* po = out.mutable_data();
    py::gil_scoped_release release;
    parallel_for_each_index(0, n, [&](std::size_t i) {
      po[i] = bvh_.contains(Vec3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
    }, 64);
    return out;
  }

  py::array_t<std::int64_t> cull_box(const CArray<float>& lo, const CArray<float>& hi) const {
    if (lo.size() != 3 || hi.size() != 3) throw Error("Bvh.cull_box: lo and hi are 3 numbers each");
    const AABB3f box(Vec3f(lo.data()[0], lo.data()[1], lo.data()[2]), Vec3f(hi.data()[0], hi.data()[1], hi.data()[2]));
    std::vector<std::uint32_t> ids;
    {
      py::gil_scoped_release release;
      ids = bvh_.cull_box(box);
    }
    return index_array(ids);
  }

  // planes: (k, 4) rows (nx, ny, nz, offset) of n.x = offset, n pointing into the frustum.
  py::array_t<std::int64_t> cull_frustum(const CArray<float>& planes) const {
    if (planes.ndim() != 2 || planes.shape(1) != 4)
      throw Error("Bvh.cull_frustum: planes must be a (k, 4) array of rows (nx, ny, nz, offset)");
    std::vector<Plane3f> ps;
    const float* p = planes.data();
    for (py::ssize_t i = 0; i < planes.shape(0); ++i, p += 4) {
      const Vec3f n(p[0], p[1], p[2]);
      const float len = n.norm();
      if (!(len > 0) || !std::isfinite(len) || !std::isfinite(p[3]))
        throw Error("Bvh.cull_frustum: plane " + std::to_string(i) + " has a zero or non-finite normal or offset");
      ps.push_back({n / len, p[3] / len});
    }
    std::vector<std::uint32_t> ids;
    {
      py::gil_scoped_release release;
      ids = bvh_.cull_frustum(ps);
    }
    return index_array(ids);
  }

  py::dict stats() const {
    bvh::BvhStats s;
    {
      py::gil_scoped_release release;
      s = bvh_.stats();
    }
    py::dict d;
    d["builder"] = std::string(bvh::to_string(bvh_.options().builder));
    d["bv"] = std::string(bvh::to_string(bvh_.options().bv));
    d["arity"] = bvh_.options().arity;
    d["leaf_size"] = bvh_.options().leaf_size;
    d["triangles"] = s.triangles;
    d["nodes"] = s.nodes;
    d["leaves"] = s.leaves;
    d["depth"] = s.depth;
    d["bytes"] = s.bytes;
    d["sah_cost"] = s.sah_cost;
    d["tightness_volume"] = s.tightness_volume;
    d["tightness_hausdorff"] = s.tightness_hausdorff;
    return d;
  }

  void validate() const { bvh_.validate(); }

 private:
  bvh::TriangleBvh bvh_;
};

}  // namespace

void bind_bvh(py::module_& m) {
  const float inf = std::numeric_limits<float>::infinity();
  py::class_<PyBvh>(m, "Bvh", "Bounding volume hierarchy over the triangles (V, F) of a mesh (float32).")
      .def(py::init<const CArray<float>&, const CArray<std::int64_t>&, const std::string&, const std::string&, int, int>(),
           py::arg("V"), py::arg("F"), py::arg("builder") = "sah", py::arg("bv") = "aabb", py::arg("leaf_size") = 8,
           py::arg("arity") = 4,
           "builder: sah, median, pca, bottomup, tiling, insertion, boxtree; "
           "bv: aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, obb_hull; arity 2, 4 or 8")
      .def("intersect", &PyBvh::intersect, py::arg("origins"), py::arg("directions"), py::arg("tmax") = inf,
           "Closest hits: (t, prim, u, v); t = inf and prim = -1 on a miss. Rays in parallel.")
      .def("occluded", &PyBvh::occluded, py::arg("origins"), py::arg("directions"), py::arg("tmax") = inf,
           "Whether each ray hits anything with t in [0, tmax].")
      .def("closest_point", &PyBvh::closest_point, py::arg("points"),
           "Closest points of the mesh: (points (n, 3), prim, distance).")
      .def("contains", &PyBvh::contains, py::arg("points"),
           "Whether each point is inside the (closed) mesh: majority of ray parities.")
      .def("cull_box", &PyBvh::cull_box, py::arg("lo"), py::arg("hi"),
           "Indices of the triangles that intersect the box [lo, hi], sorted.")
      .def("cull_frustum", &PyBvh::cull_frustum, py::arg("planes"),
           "Indices of the triangles not entirely behind one of the planes, sorted; planes (k, 4): rows "
           "(nx, ny, nz, offset) of n.x = offset with n pointing into the frustum (conservative culling).")
      .def("stats", &PyBvh::stats,
           "dict: builder, bv, arity, leaf_size, triangles, nodes, leaves, depth, bytes, sah_cost, "
           "tightness_volume, tightness_hausdorff")
      .def("validate", &PyBvh::validate, "Checks every invariant; raises geods.Error if one fails.")
      .def("save", &PyBvh::save, py::arg("path"), "Writes the hierarchy with its triangles to a binary file.")
      .def_static("load", &PyBvh::load, py::arg("path"),
                  "Maps a file written by save() (read in place; the mesh is not needed).");
}

}  // namespace geods::python
