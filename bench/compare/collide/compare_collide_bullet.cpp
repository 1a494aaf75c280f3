// Bullet 3.24 (Debian libbullet-dev, single precision): GImpact, Bullet's
// mesh-mesh collision of concave triangle meshes (btBvhTriangleMeshShape
// collides only with convex shapes). Both objects are btGImpactMeshShape over
// one btTriangleIndexVertexArray of mesh_100k (each with its own GImpact box
// tree, margin 0), collided by btGImpactCollisionAlgorithm through
// btCollisionWorld::contactPairTest, which hands every contact point it finds
// to the callback (no manifold reduction), with the triangle index on each side.
//
// What Bullet reports is contact points, not triangle pairs: `first` is
// whether a pose gives a contact point (Bullet cannot stop at the first one:
// the same full query runs), `all` counts the distinct (triangle of A,
// triangle of B) pairs among the points. GImpact's triangle test (separating
// axes in float, clipping) is not exact, so its colliding poses and pairs may
// differ from the exact ones. No distance query between meshes.
#include <btBulletCollisionCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "collide_driver.hpp"

namespace {

struct Scene {
  std::vector<int> indices;
  std::vector<btScalar> vertices;
  std::unique_ptr<btTriangleIndexVertexArray> mesh;
  std::unique_ptr<btGImpactMeshShape> shape_a, shape_b;
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btCollisionWorld> world;
  btCollisionObject a, b;
};

struct Pairs : btCollisionWorld::ContactResultCallback {
  std::vector<std::pair<int, int>> pairs;
  btScalar addSingleResult(btManifoldPoint&, const btCollisionObjectWrapper*, int, int index0,
                           const btCollisionObjectWrapper*, int, int index1) override {
    pairs.emplace_back(index0, index1);
    return 0;
  }
};

}  // namespace

int main(int argc, char** argv) {
  auto build = [](const collide_bench::Workload& w) {
    auto s = std::make_shared<Scene>();
    s->indices.assign(w.mesh.tris.begin(), w.mesh.tris.end());
    s->vertices.assign(w.mesh.xyz.begin(), w.mesh.xyz.end());
    s->mesh = std::make_unique<btTriangleIndexVertexArray>(int(w.mesh.triangles()), s->indices.data(), 3 * int(sizeof(int)),
                                                          int(w.mesh.vertices()), s->vertices.data(),
                                                          3 * int(sizeof(btScalar)));
    for (auto* shape : {&s->shape_a, &s->shape_b}) {
      *shape = std::make_unique<btGImpactMeshShape>(s->mesh.get());
      (*shape)->setMargin(0);
      (*shape)->updateBound();  // builds the box tree
    }
    s->config = std::make_unique<btDefaultCollisionConfiguration>();
    s->dispatcher = std::make_unique<btCollisionDispatcher>(s->config.get());
    btGImpactCollisionAlgorithm::registerAlgorithm(s->dispatcher.get());
    // contactPairTest dispatches through the closest-points table, which registerAlgorithm leaves alone.
    static btGImpactCollisionAlgorithm::CreateFunc gimpact;
    for (int i = 0; i < MAX_BROADPHASE_COLLISION_TYPES; ++i) {
      s->dispatcher->registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, i, &gimpact);
      s->dispatcher->registerClosestPointsCreateFunc(i, GIMPACT_SHAPE_PROXYTYPE, &gimpact);
    }
    s->broadphase = std::make_unique<btDbvtBroadphase>();
    s->world = std::make_unique<btCollisionWorld>(s->dispatcher.get(), s->broadphase.get(), s->config.get());
    s->a.setCollisionShape(s->shape_a.get());
    s->b.setCollisionShape(s->shape_b.get());
    s->a.setWorldTransform(btTransform::getIdentity());
    return s;
  };
  auto query = [](const std::shared_ptr<Scene>& s, const std::string& variant, const collide_bench::Workload& w,
                  std::size_t i) {
    const double* p = &w.poses[7 * i];
    btQuaternion q{btScalar(p[1]), btScalar(p[2]), btScalar(p[3]), btScalar(p[0])};  // (x, y, z, w)
    q.normalize();
    s->b.setWorldTransform(btTransform(q, btVector3(btScalar(p[4]), btScalar(p[5]), btScalar(p[6]))));
    Pairs found;
    s->world->contactPairTest(&s->a, &s->b, found);
    collide_bench::PoseResult r;
    r.colliding = !found.pairs.empty();
    if (variant == "all") {
      std::sort(found.pairs.begin(), found.pairs.end());
      r.pairs = std::size_t(std::unique(found.pairs.begin(), found.pairs.end()) - found.pairs.begin());
    }
    return r;
  };
  return collide_bench::run(argc, argv, "bullet_gimpact", build, query, {"first", "all"});
}
