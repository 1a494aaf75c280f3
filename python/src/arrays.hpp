#pragma once
// The one place where numpy arrays become geods inputs and results become
// numpy arrays: point rows in; index, neighbour, point, mesh and hit arrays
// out. A missing index (the library's kNoIndex, uint32 max, or kNoId) is -1,
// a missing distance inf, as numpy users expect.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <array>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/image.hpp"
#include "geods/core/ray.hpp"
#include "geods/core/ray_triangle.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/core/vec.hpp"
#include "geods/io/volume_io.hpp"
#include "geods/spatial/point_view.hpp"

namespace geods::python {

namespace py = pybind11;

/// A C-order array of T, converted from any numeric input (lists too).
template <typename T>
using Rows = py::array_t<T, py::array::c_style | py::array::forcecast>;

// ------------------------------------------------------------------ in

/// Points given as one point (d,) or as rows (m, d) of T.
template <typename T>
struct PointRows {
  Rows<T> array;
  std::size_t count = 0, dim = 0;
  bool single = false;  // given as one point (d,)

  const T* data() const { return array.data(); }
  spatial::PointView<T> view() const { return {array.data(), count, dim}; }
  template <int Dim>
  Vec<T, Dim> point(std::size_t i) const {
    return Eigen::Map<const Vec<T, Dim>>(array.data() + i * Dim);
  }
};

/// `x` as points of dimension `dim`: (dim,) if `allow_single`, else (m, dim) only.
/// Throws geods::Error starting with `what` for anything else.
template <typename T>
PointRows<T> point_rows(const py::handle& x, std::size_t dim, const std::string& what, bool allow_single = true) {
  auto a = Rows<T>::ensure(x);
  if (!a) throw Error(what + ": expected an array of numbers");
  if (allow_single && a.ndim() == 1 && std::size_t(a.shape(0)) == dim) return {a, 1, dim, true};
  if (a.ndim() == 2 && std::size_t(a.shape(1)) == dim) return {a, std::size_t(a.shape(0)), dim, false};
  const std::string d = std::to_string(dim);
  throw Error(what + ": expected shape " + (allow_single ? "(" + d + ",) or " : "") + "(m, " + d + ")");
}

/// One point of Dim coordinates, (Dim,).
template <typename T, int Dim>
Vec<T, Dim> point_of(const py::handle& x, const std::string& what) {
  const auto a = Rows<T>::ensure(x);
  if (!a || a.ndim() != 1 || a.shape(0) != Dim)
    throw Error(what + ": expected a point of shape (" + std::to_string(Dim) + ",)");
  return Eigen::Map<const Vec<T, Dim>>(a.data());
}

/// Rows (n, Dim) as a vector of points (a copy, for the structures that keep their own).
template <typename T, int Dim>
std::vector<Vec<T, Dim>> points_of(const py::handle& x, const std::string& what, bool* single = nullptr) {
  const PointRows<T> rows = point_rows<T>(x, Dim, what, single != nullptr);
  if (single) *single = rows.single;
  std::vector<Vec<T, Dim>> out(rows.count);
  for (std::size_t i = 0; i < rows.count; ++i) out[i] = rows.template point<Dim>(i);
  return out;
}

/// A TriMesh from V (n, 3) floats and F (m, 3) integer vertex indices; `what`
/// names the caller in the geods::Error raised for a wrong shape or an index out of range.
inline TriMesh mesh_from_arrays(const Rows<float>& v, const Rows<std::int64_t>& f, const std::string& what) {
  if (v.ndim() != 2 || v.shape(1) != 3) throw Error(what + ": V must be an (n, 3) array");
  if (f.ndim() != 2 || f.shape(1) != 3) throw Error(what + ": F must be an (m, 3) array");
  TriMesh mesh;
  mesh.vertices.resize(std::size_t(v.shape(0)));
  if (!mesh.vertices.empty()) std::memcpy(static_cast<void*>(mesh.vertices.data()), v.data(), mesh.vertices.size() * sizeof(Vec3f));
  mesh.triangles.resize(std::size_t(f.shape(0)));
  const std::int64_t* idx = f.data();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::int64_t i = idx[3 * t + std::size_t(c)];
      if (i < 0 || i >= v.shape(0))
        throw Error(what + ": F[" + std::to_string(t) + "] has vertex index " + std::to_string(i) + " out of range (" +
                    std::to_string(v.shape(0)) + " vertices)");
      mesh.triangles[t][std::size_t(c)] = std::uint32_t(i);
    }
  return mesh;
}

/// Rays from (n, 3) origins and directions and a tmax that is one value or n; `what` names the caller.
inline std::vector<Ray3f> rays_from_arrays(const Rows<float>& origins, const Rows<float>& directions,
                                           const Rows<float>& tmax, const std::string& what) {
  if (origins.ndim() != 2 || origins.shape(1) != 3) throw Error(what + ": origins must be an (n, 3) array");
  if (directions.ndim() != 2 || directions.shape(1) != 3 || directions.shape(0) != origins.shape(0))
    throw Error(what + ": directions must be an (n, 3) array like origins");
  const auto n = std::size_t(origins.shape(0));
  if (tmax.size() != 1 && std::size_t(tmax.size()) != n) throw Error(what + ": tmax must be one number or one per ray");
  std::vector<Ray3f> rays(n);
  const float *o = origins.data(), *d = directions.data(), *t = tmax.data();
  for (std::size_t i = 0; i < n; ++i) {
    rays[i].origin = Vec3f(o[3 * i], o[3 * i + 1], o[3 * i + 2]);
    rays[i].direction = Vec3f(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
    rays[i].tmax = t[tmax.size() == 1 ? 0 : i];
  }
  return rays;
}

/// A (nz, ny, nx) array as a volume of its own sample type (x fastest, as
/// io::read_volume maps .npy files): uint8, uint16, int16, float32, float64 as
/// they are; bool as uint8, int8 as int16, other integers as float64. Copied.
inline io::AnyGrid3 volume_from_array(const py::array& array, const std::array<double, 3>& spacing,
                                      const std::array<double, 3>& origin, const std::string& what) {
  if (array.ndim() != 3) throw Error(what + ": the volume must be a 3-D array (nz, ny, nx)");
  auto grid = [&]<typename T>(T) -> io::AnyGrid3 {
    const auto a = Rows<T>::ensure(array);
    Grid3<T> g;
    g.dims = {std::size_t(a.shape(2)), std::size_t(a.shape(1)), std::size_t(a.shape(0))};
    g.data.assign(a.data(), a.data() + a.size());
    g.spacing = Vec3d(spacing[0], spacing[1], spacing[2]).cast<float>();
    g.origin = Vec3d(origin[0], origin[1], origin[2]).cast<float>();
    return g;
  };
  const py::dtype dt = array.dtype();
  if (dt.equal(py::dtype::of<std::uint8_t>()) || dt.kind() == 'b') return grid(std::uint8_t{});
  if (dt.equal(py::dtype::of<std::uint16_t>())) return grid(std::uint16_t{});
  if (dt.equal(py::dtype::of<std::int16_t>()) || dt.equal(py::dtype::of<std::int8_t>())) return grid(std::int16_t{});
  if (dt.equal(py::dtype::of<float>())) return grid(float{});
  if (dt.equal(py::dtype::of<double>()) || dt.kind() == 'i' || dt.kind() == 'u') return grid(double{});
  throw Error(what + ": unsupported dtype " + py::cast<std::string>(py::repr(dt)));
}

/// An (h, w) or (h, w, c) uint8 array as an image of c channels (a copy);
/// `what` names the caller in the geods::Error raised for another shape.
template <typename T = std::uint8_t>
Image<T> image_from_array(const Rows<T>& a, const std::string& what) {
  if (a.ndim() != 2 && a.ndim() != 3)
    throw Error(what + ": expected an (h, w) or (h, w, c) " + std::string(py::str(py::object(py::dtype::of<T>()))) + " array");
  Image<T> im;
  im.height = std::size_t(a.shape(0));
  im.width = std::size_t(a.shape(1));
  im.channels = a.ndim() == 3 ? std::size_t(a.shape(2)) : 1;
  im.data.assign(a.data(), a.data() + a.size());
  return im;
}

// ------------------------------------------------------------------ out

/// A copy of `data` shaped `shape` (as many values as the shape holds).
template <typename T>
py::array_t<T> copy_array(const T* data, std::vector<py::ssize_t> shape) {
  py::array_t<T> a(shape);
  if (a.size() > 0) std::memcpy(a.mutable_data(), data, std::size_t(a.size()) * sizeof(T));
  return a;
}

/// The indices (or ids, or counts) as an int64 array of `shape` (flat when
/// empty); the "no index" value of their type (uint32 max: kNoIndex,
/// RayHit::no_hit, Delaunay2::no_edge; uint64 max: kNoId) becomes -1.
template <typename I>
py::array_t<std::int64_t> index_array(std::span<const I> ids, std::vector<py::ssize_t> shape = {}) {
  static_assert(std::is_unsigned_v<I>, "index_array: unsigned indices");
  if (shape.empty()) shape = {py::ssize_t(ids.size())};
  py::array_t<std::int64_t> out(shape);
  std::int64_t* o = out.mutable_data();
  const I* in = ids.data();
  const std::size_t n = ids.size();
  // Branch-free (all bits set for none), so the loop vectorizes.
  for (std::size_t i = 0; i < n; ++i)
    o[i] = std::int64_t(in[i]) | -std::int64_t(in[i] == std::numeric_limits<I>::max());
  return out;
}
template <typename I>
py::array_t<std::int64_t> index_array(const std::vector<I>& ids, std::vector<py::ssize_t> shape = {}) {
  return index_array(std::span<const I>(ids), std::move(shape));
}

/// One index as Python wants it: -1 for none.
template <typename I>
std::int64_t index_value(I i) {
  return i == std::numeric_limits<I>::max() ? -1 : std::int64_t(i);
}

/// 0/1 flags as a bool array.
inline py::array_t<bool> bool_array(std::span<const std::uint8_t> flags) {
  py::array_t<bool> out(py::ssize_t(flags.size()));
  bool* o = out.mutable_data();
  for (std::size_t i = 0; i < flags.size(); ++i) o[i] = flags[i] != 0;
  return out;
}

/// Points as an (n, Dim) float array of their scalar type.
template <typename T, int Dim>
py::array_t<T> points_array(std::span<const Vec<T, Dim>> points) {
  return copy_array(points.empty() ? nullptr : points[0].data(), {py::ssize_t(points.size()), py::ssize_t(Dim)});
}
template <typename T, int Dim>
py::array_t<T> points_array(const std::vector<Vec<T, Dim>>& points) {
  return points_array(std::span<const Vec<T, Dim>>(points));
}

/// k-NN results (k per query, sorted; `index` the member that holds the
/// index or id) as (distances float64, indices int64), each (m, k), or (k,)
/// for a single query; missing neighbours are inf and -1.
template <typename Neighbor, typename Index>
py::tuple neighbor_arrays(std::span<const Neighbor> result, std::size_t m, std::size_t k, bool single,
                          Index Neighbor::*index) {
  py::array_t<double> distances(std::vector<py::ssize_t>{py::ssize_t(m), py::ssize_t(k)});
  py::array_t<std::int64_t> indices(std::vector<py::ssize_t>{py::ssize_t(m), py::ssize_t(k)});
  double* d = distances.mutable_data();
  std::int64_t* idx = indices.mutable_data();
  for (std::size_t i = 0; i < m * k; ++i) {
    const bool missing = i >= result.size() || result[i].*index == std::numeric_limits<Index>::max();
    d[i] = missing ? std::numeric_limits<double>::infinity() : std::sqrt(double(result[i].squared_distance));
    idx[i] = missing ? -1 : std::int64_t(result[i].*index);
  }
  if (single) return py::make_tuple(distances.reshape({py::ssize_t(k)}), indices.reshape({py::ssize_t(k)}));
  return py::make_tuple(distances, indices);
}

/// Radius-search results: one int64 index array per query, a list of them
/// unless a single query was given.
template <typename Neighbor, typename Index>
py::object neighbor_lists(const std::vector<std::vector<Neighbor>>& result, bool single, Index Neighbor::*index) {
  py::list out;
  for (const auto& neighbors : result) {
    py::array_t<std::int64_t> ids(py::ssize_t(neighbors.size()));
    std::int64_t* p = ids.mutable_data();
    for (std::size_t i = 0; i < neighbors.size(); ++i) p[i] = std::int64_t(neighbors[i].*index);
    out.append(ids);
  }
  if (single) return out[0];
  return out;
}

/// (V float32 (n, 3), F int32 (m, 3) or int64 beyond 2^31 vertices) and, with
/// `normals`, N float32 (n, 3) (shape (0, 3) when the mesh has none).
inline py::tuple mesh_arrays(const TriMesh& mesh, bool normals) {
  const auto nv = py::ssize_t(mesh.num_vertices()), nf = py::ssize_t(mesh.num_triangles());
  const py::array_t<float> v = copy_array(mesh.vertices.empty() ? nullptr : mesh.vertices[0].data(), {nv, 3});
  py::object f;
  if (mesh.num_vertices() <= std::size_t(std::numeric_limits<std::int32_t>::max())) {
    f = copy_array(reinterpret_cast<const std::int32_t*>(mesh.triangles.data()), {nf, 3});
  } else {
    f = index_array(std::span<const std::uint32_t>(mesh.triangles.empty() ? nullptr : mesh.triangles[0].data(),
                                                   3 * mesh.triangles.size()),
                    {nf, 3});
  }
  if (!normals) return py::make_tuple(v, f);
  const py::array_t<float> n =
      copy_array(mesh.normals.empty() ? nullptr : mesh.normals[0].data(), {mesh.normals.empty() ? 0 : nv, 3});
  return py::make_tuple(v, f, n);
}

/// An image as uint8 (h, w) for one channel, (h, w, c) otherwise.
inline py::array_t<std::uint8_t> image_array(const Image<std::uint8_t>& im) {
  const auto h = py::ssize_t(im.height), w = py::ssize_t(im.width), c = py::ssize_t(im.channels);
  return im.channels == 1 ? copy_array(im.data.data(), {h, w}) : copy_array(im.data.data(), {h, w, c});
}

/// Closest hits of n rays as numpy arrays: t (inf on a miss), prim (-1), u, v.
struct HitArrays {
  py::array_t<float> t, u, v;
  py::array_t<std::int64_t> prim;

  explicit HitArrays(std::size_t n)
      : t(py::ssize_t(n)), u(py::ssize_t(n)), v(py::ssize_t(n)), prim(py::ssize_t(n)),
        pt_(t.mutable_data()), pu_(u.mutable_data()), pv_(v.mutable_data()), pp_(prim.mutable_data()) {}
  /// Thread-safe for distinct i (called with the GIL released).
  void set(std::size_t i, const RayHit& h) {
    pt_[i] = h.hit() ? h.t : std::numeric_limits<float>::infinity();
    pp_[i] = index_value(h.prim);
    pu_[i] = h.u;
    pv_[i] = h.v;
  }
  py::tuple tuple() const { return py::make_tuple(t, prim, u, v); }

 private:
  float *pt_, *pu_, *pv_;
  std::int64_t* pp_;
};

}  // namespace geods::python
