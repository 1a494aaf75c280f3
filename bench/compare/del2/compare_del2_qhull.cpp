// Qhull 2020.2 (reentrant C library) Delaunay triangulation: the lower hull of the points lifted
// to the paraboloid, options "d Qbb Qc Qz Q12 Qt" (scipy.spatial.Delaunay's: scaled last
// coordinate, coplanar points kept, a point at infinity against co-circular input, triangulated
// output). Qhull's arithmetic is floating point with merging of nearly coplanar facets, not
// exact predicates.
extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <cstdio>

#include "del2_driver.hpp"

struct Qhull {
  static constexpr const char* workload = "del2";
  static constexpr int max_reps = 1;  // about 20-50 s per run on 1M points: one run
  static constexpr const char* anchor = "qhull";
  static del2::Result triangulate(const std::vector<double>& xy, std::size_t n) {
    qhT qh_storage;
    qhT* qh = &qh_storage;
    qh_zero(qh, stderr);
    std::vector<coordT> coords(xy.begin(), xy.end());  // qhull may scale them in place (Qbb)
    char options[] = "qhull d Qbb Qc Qz Q12 Qt";
    del2::Result result;
    if (qh_new_qhull(qh, 2, static_cast<int>(n), coords.data(), False, options, nullptr, stderr) == 0) {
      std::vector<char> is_vertex(n, 0);
      facetT* facet;
      vertexT *vertex, **vertexp;
      FORALLfacets {
        if (facet->upperdelaunay) continue;
        ++result.triangles;
        FOREACHvertex_(facet->vertices) {
          const int id = qh_pointid(qh, vertex->point);
          if (id >= 0 && static_cast<std::size_t>(id) < n) is_vertex[static_cast<std::size_t>(id)] = 1;
        }
        // A lower facet next to an upper one (or none) has its edge on the hull.
        facetT *neighbor, **neighborp;
        FOREACHneighbor_(facet) if (neighbor->upperdelaunay)++ result.hull;
      }
      for (char v : is_vertex) result.vertices += v;
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong, totlong;
    qh_memfreeshort(qh, &curlong, &totlong);
    return result;
  }
};

int main(int argc, char** argv) { return del2::run<Qhull>(argc, argv); }
