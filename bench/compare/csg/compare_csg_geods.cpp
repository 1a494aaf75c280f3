// geods::bsp::csg on the csg workload and the fuzz corpus (csg_driver.hpp). Method: local
// (default) or, with -DGEODS_CSG_MERGE, the BSP merge of the seed (§3.3).
#include "csg_driver.hpp"
#include "geods/bsp/csg.hpp"

#ifdef GEODS_CSG_MERGE
constexpr geods::bsp::CsgMethod kMethod = geods::bsp::CsgMethod::bsp_merge;
constexpr const char* kAnchor = "geods_merge";
#else
constexpr geods::bsp::CsgMethod kMethod = geods::bsp::CsgMethod::local;
constexpr const char* kAnchor = "geods";
#endif

int main(int argc, char** argv) {
  using namespace csg_bench;
  return run(argc, argv, kAnchor, [](const Mesh& a, const Mesh& b, Op op, Mesh& out, double& build_s, double& query_s) {
    geods::bsp::Triangles ta, tb;
    build_s = compare::time_s([&] {
      for (auto [m, t] : {std::pair{&a, &ta}, std::pair{&b, &tb}}) {
        t->vertices.resize(m->vertices());
        for (std::size_t v = 0; v < m->vertices(); ++v) t->vertices[v] = {m->xyz[3 * v], m->xyz[3 * v + 1], m->xyz[3 * v + 2]};
        t->triangles = m->tri;
      }
    });
    const auto gop = op == Op::union_ ? geods::bsp::CsgOp::union_
                     : op == Op::intersection ? geods::bsp::CsgOp::intersection
                                              : geods::bsp::CsgOp::difference;
    geods::bsp::CsgResult r;
    query_s = compare::time_s([&] { r = geods::bsp::csg(ta, tb, gop, {}, kMethod); });
    out.xyz.clear();
    for (const auto& v : r.mesh.vertices) out.xyz.insert(out.xyz.end(), {v[0], v[1], v[2]});
    out.tri = r.mesh.triangles;
    return true;
  });
}
