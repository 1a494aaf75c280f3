// Python bindings of geods::collide: CollisionMesh, collide, distance.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "geods/collide/collide.hpp"
#include "geods/collide/stats_fields.hpp"
#include "stats_dict.hpp"
#include "without_gil.hpp"

namespace geods::python {
namespace {

using collide::CollisionMesh;
using collide::Posed;

// None (identity), 7 numbers (qw, qx, qy, qz, tx, ty, tz) or a 4 x 4 rigid matrix.
Posed pose_of(const py::handle& x, const std::string& what) {
  if (x.is_none()) return Posed{};
  const Rows<double> a = py::cast<Rows<double>>(x);
  if (a.size() == 7 && a.ndim() == 1) return Posed::from_row(a.data());
  if (a.ndim() == 2 && a.shape(0) == 4 && a.shape(1) == 4) {
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = a.at(i, j);
    if (!r.allFinite()) throw Error(what + ": the pose is not finite (NaN or infinity)");
    Posed p;
    p.rotation = Eigen::Quaterniond(r);
    p.translation = Vec3d(a.at(0, 3), a.at(1, 3), a.at(2, 3));
    return p;
  }
  throw Error(what + ": a pose is None, 7 numbers (qw, qx, qy, qz, tx, ty, tz) or a 4 x 4 matrix");
}

}  // namespace

void bind_collide(py::module_& m) {
  py::class_<CollisionMesh, std::shared_ptr<CollisionMesh>>(
      m, "CollisionMesh", "A triangle mesh with its bounding volume hierarchy, for collide() and distance()")
      .def(py::init([](const Rows<float>& v, const Rows<std::int64_t>& f, const std::string& bv, int leaf_size,
                       const std::string& builder) {
             collide::CollisionMeshOptions o;
             o.bv = collide::parse_collision_volume(bv);
             o.leaf_size = leaf_size;
             o.builder = bvh::parse_builder(builder);
             const TriMesh mesh = mesh_from_arrays(v, f, "CollisionMesh");
             return without_gil([&] { return std::make_shared<CollisionMesh>(mesh, o); });
           }),
           py::arg("V"), py::arg("F"), py::arg("bv") = "obb", py::arg("leaf_size") = 2, py::arg("builder") = "sah",
           "V: float32 (n, 3) vertices, F: int64 (m, 3) triangles; bv: aabb, sphere, kdop6, kdop14, kdop18, kdop26, obb, "
           "obb_hull, boxtree, rss")
      .def_property_readonly("num_triangles", &CollisionMesh::num_triangles)
      .def_property_readonly("bv", [](const CollisionMesh& c) { return std::string(to_string(c.options().bv)); });

  py::class_<collide::CollideResult>(m, "CollideResult", "What collide() found: colliding, pairs, stats; true if colliding")
      .def_readonly("colliding", &collide::CollideResult::colliding)
      .def_property_readonly("pairs",
                             [](const collide::CollideResult& r) {
                               std::vector<std::uint32_t> ids;
                               for (const auto& c : r.pairs) ids.push_back(c.a), ids.push_back(c.b);
                               return index_array(ids, {py::ssize_t(r.pairs.size()), 2});
                             },
                             "(k, 2) int64: triangle of a, triangle of b")
      .def_property_readonly("stats", [](const collide::CollideResult& r) { return stats_dict(r.stats); })
      .def("__bool__", [](const collide::CollideResult& r) { return r.colliding; });

  m.def(
      "collide",
      [](const CollisionMesh& a, const py::object& pose_a, const CollisionMesh& b, const py::object& pose_b,
         const std::string& mode, const std::string& descend) {
        const Posed pa = pose_of(pose_a, "collide pose_a"), pb = pose_of(pose_b, "collide pose_b");
        const collide::CollideRequest request{collide::parse_collide_mode(mode), collide::parse_descend_rule(descend)};
        return without_gil([&] { return collide::collide(a, pa, b, pb, request); });
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), py::arg("mode") = "first",
      py::arg("descend") = "larger",
      "Whether (mode='first') or where (mode='all': every intersecting triangle pair) the meshes intersect. "
      "Poses: None, (qw, qx, qy, qz, tx, ty, tz) or a 4 x 4 matrix.");

  m.def(
      "distance",
      [](const CollisionMesh& a, const py::object& pose_a, const CollisionMesh& b, const py::object& pose_b,
         const py::object& within, const std::string& descend) {
        const Posed pa = pose_of(pose_a, "distance pose_a"), pb = pose_of(pose_b, "distance pose_b");
        collide::DistanceRequest request;
        request.descend = collide::parse_descend_rule(descend);
        if (!within.is_none()) request.within = py::cast<double>(within);
        const collide::DistanceResult r = without_gil([&] { return collide::distance(a, pa, b, pb, request); });
        return py::make_tuple(r.distance, points_array(std::vector<Vec3d>{r.point_a}).attr("reshape")(3),
                              points_array(std::vector<Vec3d>{r.point_b}).attr("reshape")(3));
      },
      py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), py::arg("within") = py::none(),
      py::arg("descend") = "larger",
      "(d, p_a, p_b): least distance between the meshes and the closest points (world coordinates); with "
      "within=d stops at the first pair within d (then d is an upper bound).");
}

}  // namespace geods::python
