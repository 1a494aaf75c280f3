// CGAL 5.5 Segment_Delaunay_graph_2 (filtered traits without intersections, Field_with_sqrt_tag,
// Simple_cartesian<double>; insert_segments with spatial sorting) on the segvoronoi inputs.
#include <CGAL/Segment_Delaunay_graph_2.h>
#include <CGAL/Segment_Delaunay_graph_filtered_traits_2.h>
#include <CGAL/Simple_cartesian.h>

#include "segvoronoi_driver.hpp"

using K = CGAL::Simple_cartesian<double>;
using Gt = CGAL::Segment_Delaunay_graph_filtered_traits_without_intersections_2<K, CGAL::Field_with_sqrt_tag>;
using SDG = CGAL::Segment_Delaunay_graph_2<Gt>;

struct Cgal {
  static constexpr const char* anchor = "cgal";
  static constexpr int max_reps = 100;
  static segvoronoi::Result build(const segvoronoi::Segments& segments) {
    std::vector<Gt::Segment_2> s;
    s.reserve(segments.size());
    for (const auto& g : segments)
      s.emplace_back(Gt::Point_2(double(g[0]), double(g[1])), Gt::Point_2(double(g[2]), double(g[3])));
    SDG sdg;
    sdg.insert_segments(s.begin(), s.end());
    return {sdg.number_of_faces(), sdg.number_of_input_sites()};
  }
};

int main(int argc, char** argv) { return segvoronoi::run<Cgal>(argc, argv); }
