// FCL 0.7: BVHModel<OBBRSSd> (or AABBd with GEODS_FCL_AABB) of mesh_100k
// (FCL's default top-down split), shared by both objects; fcl::collide with
// one contact (first) or all contacts, fcl::distance (OBBRSS only). With AABBs
// FCL moves every vertex of B and refits its tree at each query (its AABBs do
// not rotate): about 0.1 s per pose, so only every 10th pose is timed.
#include <fcl/fcl.h>

#include <memory>

#include "collide_driver.hpp"

#ifdef GEODS_FCL_AABB
using BV = fcl::AABBd;
constexpr const char* kAnchor = "fcl_aabb";
#else
using BV = fcl::OBBRSSd;
constexpr const char* kAnchor = "fcl_obbrss";
#endif

using Model = fcl::BVHModel<BV>;
struct Objects {
  explicit Objects(const std::shared_ptr<Model>& m) : a(m, fcl::Transform3d::Identity()), b(m, fcl::Transform3d::Identity()) {}
  fcl::CollisionObjectd a, b;
};

int main(int argc, char** argv) {
  auto build = [](const collide_bench::Workload& w) {
    std::vector<fcl::Vector3d> v;
    std::vector<fcl::Triangle> t;
    for (std::size_t i = 0; i < w.mesh.vertices(); ++i) v.emplace_back(w.mesh.xyz[3 * i], w.mesh.xyz[3 * i + 1], w.mesh.xyz[3 * i + 2]);
    for (std::size_t i = 0; i < w.mesh.triangles(); ++i) t.emplace_back(w.mesh.tris[3 * i], w.mesh.tris[3 * i + 1], w.mesh.tris[3 * i + 2]);
    auto m = std::make_shared<Model>();
    m->beginModel();
    m->addSubModel(v, t);
    m->endModel();
    // The objects are made once (their constructor scans every vertex for the local box); a query sets B's pose.
    return std::make_shared<Objects>(m);
  };
  auto query = [](const std::shared_ptr<Objects>& o, const std::string& variant, const collide_bench::Workload& w,
                  std::size_t i) {
    const double* p = &w.poses[7 * i];
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = fcl::Quaterniond(p[0], p[1], p[2], p[3]).normalized().toRotationMatrix();
    tf.translation() = fcl::Vector3d(p[4], p[5], p[6]);
    fcl::CollisionObjectd& a = o->a;
    fcl::CollisionObjectd& b = o->b;
    b.setTransform(tf);
    b.computeAABB();
    collide_bench::PoseResult r;
    if (variant == "distance") {
      fcl::DistanceRequestd req(true);
      fcl::DistanceResultd res;
      fcl::distance(&a, &b, req, res);
      r.distance = std::max(0.0, res.min_distance);
      r.colliding = r.distance == 0;
    } else {
      fcl::CollisionRequestd req(variant == "all" ? 100000000 : 1, false);
      fcl::CollisionResultd res;
      fcl::collide(&a, &b, req, res);
      r.colliding = res.isCollision();
      r.pairs = res.numContacts();
    }
    return r;
  };
#ifdef GEODS_FCL_AABB
  return collide_bench::run(argc, argv, kAnchor, build, query, {"first", "all"}, 10);  // every 10th pose: 0.1 s each
#else
  return collide_bench::run(argc, argv, kAnchor, build, query);
#endif
}
