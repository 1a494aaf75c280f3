// voro++ 0.4.6 (Debian's voro++-dev) on the vor3 workload: a container over the unit cube with
// about 5 points per block (the size its documentation recommends), every cell computed with
// its neighbours (voronoicell_neighbor) and kept as geods keeps it: corners, face loops, the
// neighbour across each face, volume and centroid. Single-threaded (voro++ has no threads).
#include <voro++/voro++.hh>

#include "vor3_driver.hpp"

struct Voropp {
  static constexpr const char* anchor = "voropp";
  struct Cell {
    std::vector<double> vertices;
    std::vector<int> face_vertices, neighbors;
    double volume = 0, centroid[3] = {0, 0, 0};
  };
  static vor3::Result cells(const std::vector<double>& xyz, std::size_t n) {
    const int blocks = std::max(1, int(std::cbrt(double(n) / 5.0)));
    voro::container con(0, 1, 0, 1, 0, 1, blocks, blocks, blocks, false, false, false, 8);
    for (std::size_t i = 0; i < n; ++i) con.put(int(i), xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    std::vector<Cell> cells(n);
    voro::c_loop_all loop(con);
    voro::voronoicell_neighbor c;
    vor3::Result r;
    if (loop.start()) do {
        if (!con.compute_cell(c, loop)) continue;
        double x, y, z;
        loop.pos(x, y, z);
        Cell& cell = cells[std::size_t(loop.pid())];
        c.vertices(x, y, z, cell.vertices);
        c.face_vertices(cell.face_vertices);
        c.neighbors(cell.neighbors);
        cell.volume = c.volume();
        c.centroid(cell.centroid[0], cell.centroid[1], cell.centroid[2]);
        ++r.cells;
        r.faces += cell.neighbors.size();
        r.vertices += cell.vertices.size() / 3;
        r.volume += cell.volume;
      } while (loop.inc());
    compare::do_not_optimize(cells.data());
    return r;
  }
};

int main(int argc, char** argv) { return vor3::run<Voropp>(argc, argv); }
