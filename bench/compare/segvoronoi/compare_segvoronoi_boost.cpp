// Boost.Polygon's voronoi_builder (construct_voronoi on int32 segments) on the segvoronoi inputs.
#include <boost/polygon/segment_data.hpp>
#include <boost/polygon/voronoi.hpp>

#include "segvoronoi_driver.hpp"

namespace bp = boost::polygon;

struct Boost {
  static constexpr const char* anchor = "boost";
  static constexpr int max_reps = 100;
  static segvoronoi::Result build(const segvoronoi::Segments& segments) {
    std::vector<bp::segment_data<int>> s;
    s.reserve(segments.size());
    for (const auto& g : segments)
      s.emplace_back(bp::point_data<int>(static_cast<int>(g[0]), static_cast<int>(g[1])),
                     bp::point_data<int>(static_cast<int>(g[2]), static_cast<int>(g[3])));
    bp::voronoi_diagram<double> vd;
    bp::construct_voronoi(s.begin(), s.end(), &vd);
    return {vd.num_vertices(), vd.num_edges() / 2};
  }
};

int main(int argc, char** argv) { return segvoronoi::run<Boost>(argc, argv); }
