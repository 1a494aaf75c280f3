// nanoflann's KDTreeSingleIndexAdaptor (L2, dimension 2 at compile time, leaf size 10) on the nearest inputs.
#include <nanoflann.hpp>

#include "nearest_driver.hpp"

namespace {

// The sites in place as an n x 2 row-major double array.
struct Sites {
  const double* xy;
  std::size_t n;
  std::size_t kdtree_get_point_count() const { return n; }
  double kdtree_get_pt(std::size_t i, std::size_t d) const { return xy[2 * i + d]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};

struct Nanoflann {
  static constexpr const char* anchor = "nanoflann";
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Sites>, Sites, 2, std::uint32_t>;
  struct Index {
    Sites sites;
    Tree tree;
    Index(const double* xy, std::size_t n) : sites{xy, n}, tree(2, sites, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}
  };
  static std::unique_ptr<Index> build(const double* xy, std::size_t n) { return std::make_unique<Index>(xy, n); }
  static std::uint32_t nearest(const Index& index, const double* q) {
    std::uint32_t i = 0;
    double d = 0;
    nanoflann::KNNResultSet<double, std::uint32_t> result(1);
    result.init(&i, &d);
    index.tree.findNeighbors(result, q, nanoflann::SearchParams());
    return i;
  }
};

}  // namespace

int main(int argc, char** argv) { return compare::nearest::run<Nanoflann>(argc, argv); }
