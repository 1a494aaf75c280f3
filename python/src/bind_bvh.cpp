// Python bindings of the bvh module: geods.TriangleBvh (alias: Bvh).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <limits>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "arrays.hpp"
#include "geods/bvh/stats_fields.hpp"
#include "geods/bvh/triangle_bvh.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "stats_dict.hpp"

namespace py = pybind11;

namespace geods::python {
namespace {

class PyBvh {
 public:
  PyBvh(const Rows<float>& v, const Rows<std::int64_t>& f, const std::string& builder, const std::string& bv,
        int leaf_size, int arity) {
    const TriMesh mesh = mesh_from_arrays(v, f, "TriangleBvh");
    bvh::BuildOptions options;
    options.builder = bvh::parse_builder(builder);
    options.bv = bvh::parse_bounding_volume(bv);
    options.leaf_size = leaf_size;
    options.arity = arity;
    builder_ = builder;
    bv_ = bv;
    py::gil_scoped_release release;
    bvh_ = bvh::TriangleBvh::build(mesh, options);
  }
  // A loaded hierarchy reports its options by their canonical names.
  explicit PyBvh(bvh::TriangleBvh bvh)
      : bvh_(std::move(bvh)),
        builder_(bvh::to_string(bvh_.options().builder)),
        bv_(bvh::to_string(bvh_.options().bv)) {}

  void save(const std::filesystem::path& path) const { bvh_.save(path); }
  static PyBvh load(const std::filesystem::path& path) {
    py::gil_scoped_release release;
    return PyBvh(bvh::TriangleBvh::load(path));
  }

  py::tuple intersect(const Rows<float>& origins, const Rows<float>& directions, const Rows<float>& tmax) const {
    const std::vector<Ray3f> r = rays_from_arrays(origins, directions, tmax, "TriangleBvh");
    HitArrays hits(r.size());
    {
      py::gil_scoped_release release;
      parallel_for_each_index(0, r.size(), [&](std::size_t i) { hits.set(i, bvh_.intersect(r[i])); }, 256);
    }
    return hits.tuple();
  }

  py::array_t<bool> occluded(const Rows<float>& origins, const Rows<float>& directions, const Rows<float>& tmax) const {
    const std::vector<Ray3f> r = rays_from_arrays(origins, directions, tmax, "TriangleBvh");
    py::array_t<bool> out(py::ssize_t(r.size()));
    bool* po = out.mutable_data();
    py::gil_scoped_release release;
    parallel_for_each_index(0, r.size(), [&](std::size_t i) { po[i] = bvh_.occluded(r[i]); }, 256);
    return out;
  }

  // TriangleBvh::intersect_packets (packets of packet_size consecutive rays, in parallel).
  py::tuple intersect_packets(const Rows<float>& origins, const Rows<float>& directions, const Rows<float>& tmax,
                              int packet_size) const {
    const std::vector<Ray3f> r = rays_from_arrays(origins, directions, tmax, "TriangleBvh.intersect_packets");
    HitArrays hits(r.size());
    {
      py::gil_scoped_release release;
      std::vector<RayHit> out(r.size());
      bvh_.intersect_packets(r, out, packet_size);
      for (std::size_t i = 0; i < r.size(); ++i) hits.set(i, out[i]);
    }
    return hits.tuple();
  }

  py::array_t<bool> occluded_packets(const Rows<float>& origins, const Rows<float>& directions,
                                     const Rows<float>& tmax, int packet_size) const {
    const std::vector<Ray3f> r = rays_from_arrays(origins, directions, tmax, "TriangleBvh.occluded_packets");
    std::vector<std::uint8_t> o(r.size());
    {
      py::gil_scoped_release release;
      bvh_.occluded_packets(r, o, packet_size);
    }
    py::array_t<bool> out(py::ssize_t(r.size()));
    std::copy(o.begin(), o.end(), out.mutable_data());
    return out;
  }

  py::tuple closest_point(const py::handle& points) const {
    const PointRows<float> rows = point_rows<float>(points, 3, "TriangleBvh.closest_point points", false);
    const std::size_t n = rows.count;
    py::array_t<float> q({py::ssize_t(n), py::ssize_t(3)});
    py::array_t<std::int64_t> prim{py::ssize_t(n)};
    py::array_t<float> dist{py::ssize_t(n)};
    float *pq = q.mutable_data(), *pd = dist.mutable_data();
    std::int64_t* pp = prim.mutable_data();
    {
      py::gil_scoped_release release;
      parallel_for_each_index(0, n, [&](std::size_t i) {
        const bvh::ClosestPoint c = bvh_.closest_point(rows.point<3>(i));
        for (int a = 0; a < 3; ++a) pq[3 * i + std::size_t(a)] = c.prim == RayHit::no_hit ? NAN : c.point[a];
        pp[i] = index_value(c.prim);
        pd[i] = c.distance;
      }, 64);
    }
    return py::make_tuple(q, prim, dist);
  }

  py::array_t<bool> contains(const py::handle& points) const {
    const PointRows<float> rows = point_rows<float>(points, 3, "TriangleBvh.contains points", false);
    py::array_t<bool> out{py::ssize_t(rows.count)};
    bool* po = out.mutable_data();
    py::gil_scoped_release release;
    parallel_for_each_index(0, rows.count, [&](std::size_t i) { po[i] = bvh_.contains(rows.point<3>(i)); }, 64);
    return out;
  }

  py::array_t<std::int64_t> cull_box(const py::handle& lo, const py::handle& hi) const {
    const AABB3f box(point_of<float, 3>(lo, "TriangleBvh.cull_box lo"), point_of<float, 3>(hi, "TriangleBvh.cull_box hi"));
    std::vector<std::uint32_t> ids;
    {
      py::gil_scoped_release release;
      ids = bvh_.cull_box(box);
    }
    return index_array(ids);
  }

  // planes: (k, 4) rows (nx, ny, nz, offset) of n.x = offset, n pointing into the frustum.
  py::array_t<std::int64_t> cull_frustum(const Rows<float>& planes) const {
    if (planes.ndim() != 2 || planes.shape(1) != 4)
      throw Error("TriangleBvh.cull_frustum: planes must be a (k, 4) array of rows (nx, ny, nz, offset)");
    std::vector<Plane3f> ps;
    const float* p = planes.data();
    for (py::ssize_t i = 0; i < planes.shape(0); ++i, p += 4) {
      const Vec3f n(p[0], p[1], p[2]);
      const float len = n.norm();
      if (!(len > 0) || !std::isfinite(len) || !std::isfinite(p[3]))
        throw Error("TriangleBvh.cull_frustum: plane " + std::to_string(i) + " has a zero or non-finite normal or offset");
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
    py::dict d;  // the build options as given (like the CLI's report), then the stats
    d["builder"] = builder_;
    d["bv"] = bv_;
    d["arity"] = bvh_.options().arity;
    d["leaf_size"] = bvh_.options().leaf_size;
    for (const auto& [k, v] : stats_dict(s)) d[k] = v;
    return d;
  }

  void validate() const { bvh_.validate(); }

 private:
  bvh::TriangleBvh bvh_;
  std::string builder_, bv_;
};

}  // namespace

void bind_bvh(py::module_& m) {
  const float inf = std::numeric_limits<float>::infinity();
  py::class_<PyBvh>(m, "TriangleBvh",
                    "Bounding volume hierarchy over the triangles (V, F) of a mesh (float32): C++ bvh::TriangleBvh. "
                    "geods.Bvh is its deprecated older name.")
      .def(py::init<const Rows<float>&, const Rows<std::int64_t>&, const std::string&, const std::string&, int, int>(),
           py::arg("V"), py::arg("F"), py::arg("builder") = "sah", py::arg("bv") = "aabb", py::arg("leaf_size") = 8,
           py::arg("arity") = 4,
           "V: float32 (n, 3) vertices, F: int64 (m, 3) triangles; "
           "builder: sah, median, pca, bottom_up, tiling, insertion, boxtree ('bottomup': deprecated); "
           "bv: aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, obb_hull, rss; arity 2, 4 or 8")
      .def("intersect", &PyBvh::intersect, py::arg("origins"), py::arg("directions"), py::arg("tmax") = inf,
           "Closest hits of rays origins, directions float32 (n, 3): (t float32 (n,), prim int64 (n,), u, v float32 (n,)); "
           "t = inf and prim = -1 on a miss. Rays in parallel.")
      .def("occluded", &PyBvh::occluded, py::arg("origins"), py::arg("directions"), py::arg("tmax") = inf,
           "Whether each ray (origins, directions float32 (n, 3)) hits anything with t in [0, tmax]: bool (n,).")
      .def("intersect_packets", &PyBvh::intersect_packets, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = inf, py::arg("packet_size") = bvh::kPacketSize,
           "intersect() with the rays in packets of packet_size (8 or 16) consecutive rays traversed together "
           "(give coherent rays, e.g. the pixels of 4 x 2 or 4 x 4 tiles, next to each other): the same hits, bit "
           "for bit. origins, directions float32 (n, 3) -> (t float32 (n,), prim int64 (n,), u, v float32 (n,)).")
      .def("occluded_packets", &PyBvh::occluded_packets, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = inf, py::arg("packet_size") = bvh::kPacketSize,
           "occluded() with the rays in packets of packet_size (8 or 16) consecutive rays: origins, directions "
           "float32 (n, 3) -> bool (n,).")
      .def("closest_point", &PyBvh::closest_point, py::arg("points"),
           "Closest points of the mesh to points (n, 3): (points float32 (n, 3), prim int64 (n,), distance float32 (n,)).")
      .def("contains", &PyBvh::contains, py::arg("points"),
           "Whether each point of points (n, 3) is inside the (closed) mesh, bool (n,): majority of ray parities.")
      .def("cull_box", &PyBvh::cull_box, py::arg("lo"), py::arg("hi"),
           "Indices (int64 (k,)) of the triangles that intersect the box [lo, hi] (corners (x, y, z)), sorted.")
      .def("cull_frustum", &PyBvh::cull_frustum, py::arg("planes"),
           "Indices (int64 (j,)) of the triangles not entirely behind one of the planes, sorted; planes (k, 4): rows "
           "(nx, ny, nz, offset) of n.x = offset with n pointing into the frustum (conservative culling).")
      .def("stats", &PyBvh::stats,
           "dict: builder, bv, arity, leaf_size, triangles, nodes, leaves, depth, bytes, sah_cost, "
           "tightness_volume, tightness_hausdorff")
      .def("validate", &PyBvh::validate, "Checks every invariant; raises geods.Error if one fails.")
      .def("save", &PyBvh::save, py::arg("path"), "Writes the hierarchy with its triangles to a binary file.")
      .def_static("load", &PyBvh::load, py::arg("path"),
                  "Maps a file written by save() (read in place; the mesh is not needed).");
  m.attr("Bvh") = m.attr("TriangleBvh");  // deprecated: the name before Python took the C++ names
}

}  // namespace geods::python
