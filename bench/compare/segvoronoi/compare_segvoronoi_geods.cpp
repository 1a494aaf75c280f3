// geods::voronoi::SegmentVoronoi (Fortune's sweep for segment sites on the 2^25 snap) on the
// segvoronoi inputs; the conversion of the integer segments to double rows is timed.
#include "geods/voronoi/segment_voronoi.hpp"
#include "segvoronoi_driver.hpp"

struct Geods {
  static constexpr const char* anchor = "geods";
  static constexpr int max_reps = 100;
  static segvoronoi::Result build(const segvoronoi::Segments& segments) {
    std::vector<double> rows;
    rows.reserve(4 * segments.size());
    for (const auto& s : segments) rows.insert(rows.end(), {double(s[0]), double(s[1]), double(s[2]), double(s[3])});
    const geods::voronoi::SegmentVoronoi v({}, rows);
    return {v.vertices().size(), v.edges().size()};
  }
};

int main(int argc, char** argv) { return segvoronoi::run<Geods>(argc, argv); }
