// geods: the slab structure of Theorem 8 (default), walking in the Delaunay
// graph (GEODS_NEAREST_WALK) or the k-d tree (GEODS_NEAREST_KDTREE); the
// Voronoi diagram (with its Delaunay triangulation) is part of the build time.
#include <geods/spatial/kd_tree.hpp>
#include <geods/voronoi/post_office.hpp>
#include <geods/voronoi/voronoi2.hpp>

#include "nearest_driver.hpp"

namespace {

using geods::Vec2d;

#if defined(GEODS_NEAREST_KDTREE)
struct Geods {
  static constexpr const char* anchor = "geods-kdtree";
  using Index = geods::spatial::KdTree<double, 2>;
  static std::unique_ptr<Index> build(const double* xy, std::size_t n) {
    return std::make_unique<Index>(geods::spatial::PointView<double>(xy, n, 2));
  }
  static std::uint32_t nearest(const Index& tree, const double* q) {
    geods::spatial::Neighbor<double> out;
    tree.query_into(std::span<const double>(q, 2), {1}, &out);
    return out.index;
  }
};
#else
std::vector<Vec2d> to_points(const double* xy, std::size_t n) {
  std::vector<Vec2d> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = {xy[2 * i], xy[2 * i + 1]};
  return p;
}

template <typename Locator>
struct Diagram {
  explicit Diagram(const double* xy, std::size_t n) : voronoi(to_points(xy, n)), locator(voronoi) {}
  geods::voronoi::Voronoi2 voronoi;
  Locator locator;
};
struct Geods {
#if defined(GEODS_NEAREST_WALK)
  static constexpr const char* anchor = "geods-walk";
  using Index = Diagram<geods::voronoi::WalkLocator>;
#else
  static constexpr const char* anchor = "geods";
  using Index = Diagram<geods::voronoi::SlabLocator>;
#endif
  static std::unique_ptr<Index> build(const double* xy, std::size_t n) { return std::make_unique<Index>(xy, n); }
  static std::uint32_t nearest(const Index& index, const double* q) { return index.locator.nearest(Vec2d(q[0], q[1])); }
};
#endif

}  // namespace

int main(int argc, char** argv) { return compare::nearest::run<Geods>(argc, argv); }
