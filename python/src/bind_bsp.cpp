// Python bindings of geods::bsp: BspTree (classify, visibility_order, first_hits, stats, save/load) and csg.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <limits>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/bsp/csg.hpp"
#include "geods/bsp/stats_fields.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

// Double-precision meshes (the snapping grid is finer than float for large extents).
bsp::Triangles triangles_from_arrays(const Rows<double>& v, const Rows<std::int64_t>& f, const std::string& what) {
  if (v.ndim() != 2 || v.shape(1) != 3) throw Error(what + ": V must be an (n, 3) array");
  if (f.ndim() != 2 || f.shape(1) != 3) throw Error(what + ": F must be an (m, 3) array");
  bsp::Triangles t;
  t.vertices.resize(std::size_t(v.shape(0)));
  for (std::size_t i = 0; i < t.vertices.size(); ++i) t.vertices[i] = Eigen::Map<const Vec3d>(v.data() + 3 * i);
  t.triangles.resize(std::size_t(f.shape(0)));
  for (std::size_t i = 0; i < t.triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const std::int64_t k = f.data()[3 * i + std::size_t(c)];
      if (k < 0 || k >= v.shape(0))
        throw Error(what + ": F[" + std::to_string(i) + "] has vertex index " + std::to_string(k) + " out of range");
      t.triangles[i][std::size_t(c)] = std::uint32_t(k);
    }
  return t;
}

bsp::RayQuery ray_query(const py::handle& origins, const py::handle& directions, const std::string& what) {
  bsp::RayQuery q;
  q.origins = points_of<double, 3>(origins, what + " origins");
  q.directions = points_of<double, 3>(directions, what + " directions");
  if (q.origins.size() != q.directions.size())
    throw Error(what + ": " + std::to_string(q.origins.size()) + " origins but " + std::to_string(q.directions.size()) +
                " directions");
  return q;
}

bsp::BuildOptions build_options(const std::string& heuristic, double alpha, double beta, std::uint32_t k,
                                std::uint64_t seed, const py::object& rays) {
  bsp::BuildOptions o;
  o.heuristic = bsp::parse_heuristic(heuristic);
  o.alpha = alpha, o.beta = beta, o.k = k, o.seed = seed;
  if (!rays.is_none()) {
    const py::tuple t = rays.cast<py::tuple>();
    if (t.size() != 2) throw Error("BspTree: rays must be a pair (origins, directions)");
    o.rays = ray_query(t[0], t[1], "BspTree rays");
  }
  return o;
}

py::tuple triangles_arrays(const bsp::Triangles& m) {
  py::array_t<double> v(std::vector<py::ssize_t>{py::ssize_t(m.vertices.size()), 3});
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    for (int c = 0; c < 3; ++c) v.mutable_data()[3 * i + std::size_t(c)] = m.vertices[i][c];
  std::vector<std::uint32_t> f;
  f.reserve(m.triangles.size() * 3);
  for (const auto& t : m.triangles) f.insert(f.end(), t.begin(), t.end());
  return py::make_tuple(v, index_array(f, {py::ssize_t(m.triangles.size()), 3}));
}

}  // namespace

void bind_bsp(py::module_& m) {
  const bsp::BuildOptions d;
  py::class_<bsp::BspTree>(m, "BspTree", R"doc(BSP tree of a triangle mesh (seed §3).

Auto-partition by the cost heuristic of equation (5) (heuristic="cost": the k
largest polygons scored by 1 + |S-|^alpha + |S+|^alpha + beta * splits), k random
polygons with the fewest splits ("random"), or balanced axis-aligned planes
("balanced"). Vertices are snapped to an integer grid (2^19 steps each side of
the box's centre) and every side decision is exact. Leaves are inside/outside
for a closed, outward-oriented mesh. heuristic="custom" builds the customized
BSP of §3.4.3 for a sample of rays (rays=(origins, directions)): polygons
scored by Area times the sample's sin^2 of the ray-plane angle over the rays
passing near them, a random one of the k best at each node.)doc")
      .def(py::init([](const Rows<double>& v, const Rows<std::int64_t>& f, const std::string& heuristic, double alpha,
                       double beta, std::uint32_t k, std::uint64_t seed, const py::object& rays) {
             const bsp::Triangles t = triangles_from_arrays(v, f, "BspTree");
             const bsp::BuildOptions o = build_options(heuristic, alpha, beta, k, seed, rays);
             return without_gil([&] { return bsp::BspTree(t.vertices, t.triangles, o); });
           }),
           py::arg("V"), py::arg("F"), py::arg("heuristic") = "cost", py::arg("alpha") = d.alpha,
           py::arg("beta") = d.beta, py::arg("k") = d.k, py::arg("seed") = d.seed, py::arg("rays") = py::none(),
           "V: float64 (n, 3) vertices, F: int64 (m, 3) triangles; heuristic: cost, random, balanced or custom; "
           "rays: (origins float64 (r, 3), directions float64 (r, 3)), the sample of custom")
      .def(
          "classify",
          [](const bsp::BspTree& t, const py::handle& points) {
            const PointRows<double> rows = point_rows<double>(points, 3, "classify points");
            py::array_t<std::int8_t> out(py::ssize_t(rows.count));
            for (std::size_t i = 0; i < rows.count; ++i) out.mutable_data()[i] = std::int8_t(t.classify(rows.point<3>(i)));
            if (rows.single) return py::object(py::int_(out.data()[0]));
            return py::object(out);
          },
          py::arg("points"), "-1 inside, +1 outside, 0 on the boundary (exact for the snapped mesh) of points (n, 3) or one (x, y, z): int8 (n,) or an int")
      .def(
          "visibility_order",
          [](const bsp::BspTree& t, const py::handle& eye, bool back_to_front) {
            const std::vector<std::uint32_t> order = t.visibility_order(point_of<double, 3>(eye, "visibility_order eye"), back_to_front);
            std::vector<std::uint32_t> tri(order.size());
            for (std::size_t i = 0; i < order.size(); ++i) tri[i] = t.fragments()[order[i]].source;
            return index_array(tri);
          },
          py::arg("eye"), py::arg("back_to_front") = true,
          "Input triangle of each fragment, in visibility order from eye = (x, y, z): int64 (fragments,) (a split "
          "triangle appears once per fragment)")
      .def(
          "first_hits",
          [](const bsp::BspTree& t, const py::handle& origins, const py::handle& directions, double t_max, bool stats) {
            bsp::RayQuery q = ray_query(origins, directions, "first_hits");
            q.t_max = t_max;
            const bsp::RayQueryResult r = without_gil([&] { return t.first_hits(q); });
            py::array_t<double> dist(py::ssize_t(r.t.size()));
            std::copy(r.t.begin(), r.t.end(), dist.mutable_data());
            py::tuple out = py::make_tuple(dist, index_array(r.triangle));
            if (!stats) return py::object(out);
            return py::object(py::make_tuple(out[0], out[1], stats_dict(r.stats)));
          },
          py::arg("origins"), py::arg("directions"), py::arg("t_max") = std::numeric_limits<double>::infinity(),
          py::arg("stats") = false,
          "First hits of rays origins + t directions (float64 (n, 3) each), 0 <= t <= t_max: (t float64 (n,), "
          "triangle int64 (n,)), inf and -1 on a miss (and a stats dict with stats=True: rays, hits, "
          "nodes_per_ray, tests_per_ray, query_s)")
      .def("save", [](const bsp::BspTree& t, const std::filesystem::path& path) { t.save(path); }, py::arg("path"),
           "Writes the tree (grid, planes, nodes, fragments) to a geods archive.")
      .def_static(
          "load", [](const std::filesystem::path& path) { return bsp::BspTree::load(path); }, py::arg("path"),
          "Reads a tree written by save() (nodes mapped in place); raises geods.Error for a bad file.")
      .def("stats", [](const bsp::BspTree& t) { return stats_dict(t.stats()); },
           "nodes, leaves, depth, polygons, fragments, expected_cost (equation (4)), build_s")
      .def("validate", &bsp::BspTree::validate, "Checks every invariant; raises geods.Error if one fails.");

  m.def(
      "csg",
      [](const Rows<double>& va, const Rows<std::int64_t>& fa, const Rows<double>& vb, const Rows<std::int64_t>& fb,
         const std::string& op, const std::string& heuristic, bool stats, const std::string& method) {
        const bsp::Triangles a = triangles_from_arrays(va, fa, "csg A");
        const bsp::Triangles b = triangles_from_arrays(vb, fb, "csg B");
        const bsp::CsgOp o = bsp::parse_csg_op(op);
        bsp::BuildOptions options;
        options.heuristic = bsp::parse_heuristic(heuristic);
        const bsp::CsgMethod me = bsp::parse_csg_method(method);
        const bsp::CsgResult r = without_gil([&] { return bsp::csg(a, b, o, options, me); });
        py::tuple vf = triangles_arrays(r.mesh);
        if (!stats) return py::object(vf);
        return py::object(py::make_tuple(vf[0], vf[1], stats_dict(r.stats)));
      },
      py::arg("VA"), py::arg("FA"), py::arg("VB"), py::arg("FB"), py::arg("op"), py::arg("heuristic") = "cost",
      py::arg("stats") = false, py::arg("method") = "local",
      R"doc(A op B for closed, outward-oriented meshes; op is "union", "intersection",
"difference" (A minus B) or "xor"; method "local" (cuts only near the other operand)
or "bsp_merge" (merges the operands' BSP trees, seed §3.3). Returns (V float64 (n, 3), F int64 (m, 3)), a
closed, consistently oriented mesh (and a stats dict with stats=True: vertices,
triangles, closed, volume, volume_a, volume_b, bsp_nodes, pieces, t_junctions, compute_s).)doc");
}

}  // namespace geods::python
