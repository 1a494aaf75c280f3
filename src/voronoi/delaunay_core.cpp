// The non-template steps of DelaunayCore (the first triangle, triangle slots) and DelaunayView's walk.
#include "geods/voronoi/delaunay_core.hpp"

namespace geods::voronoi {

bool DelaunayCore::make_first_triangle() {
  vert.clear();
  twin.clear();
  free_triangles.clear();
  const std::uint32_t m = std::uint32_t(coords.size());
  if (m == 0) return false;
  const std::uint32_t a = 0;
  std::uint32_t b = 1;
  while (b < m && at(b) == at(a)) ++b;
  if (b == m) return false;
  std::uint32_t c = b + 1;
  double side = 0;
  while (c < m && (side = orient2d(at(a), at(b), at(c))) == 0) ++c;
  if (c == m) return false;
  if (side < 0) std::swap(b, c);
  // The finite triangle (a, b, c) and a ghost triangle behind each of its edges.
  vert.reserve(6 * std::size_t(m) + 12);
  twin.reserve(6 * std::size_t(m) + 12);
  vert = {a, b, c, b, a, ghost, c, b, ghost, a, c, ghost};
  twin.assign(12, none);
  link(0, 3);
  link(1, 6);
  link(2, 9);
  link(4, 11);
  link(7, 5);
  link(10, 8);
  last_triangle = 0;
  return true;
}

std::uint32_t DelaunayCore::new_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  std::uint32_t t;
  if (!free_triangles.empty()) {
    t = free_triangles.back();
    free_triangles.pop_back();
  } else {
    t = std::uint32_t(vert.size() / 3);
    vert.resize(vert.size() + 3);
    twin.resize(twin.size() + 3);
  }
  vert[3 * t] = a, vert[3 * t + 1] = b, vert[3 * t + 2] = c;
  return t;
}

void DelaunayCore::free_triangle(std::uint32_t t) {
  vert[3 * t] = vert[3 * t + 1] = vert[3 * t + 2] = none;
  free_triangles.push_back(t);
}

DelaunayView::Location DelaunayView::walk(const Vec2d& p, std::uint32_t t, std::size_t* steps) const {
  if (is_ghost_triangle(t))  // start from the finite triangle beside it
    for (std::uint32_t e = 3 * t; e < 3 * t + 3; ++e)
      if (vert[e] != ghost && vert[next(e)] != ghost) {
        t = twin[e] / 3;
        break;
      }
  std::uint32_t from = none;  // the half-edge we entered t through: p lies strictly inside it
  std::uint32_t random = 2463534242u;
  std::size_t count = 0;
  for (;;) {
    ++count;
    // A random first edge makes the walk terminate on any triangulation (stochastic walk).
    random ^= random << 13, random ^= random >> 17, random ^= random << 5;
    const std::uint32_t first = random % 3;
    std::uint32_t zero[2], zeros = 0;
    bool moved = false;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t e = 3 * t + (first + k) % 3;
      if (e == from) continue;
      const double side = orient2d(at(vert[e]), at(vert[next(e)]), p);
      if (side < 0) {
        const std::uint32_t f = twin[e];
        if (is_ghost_triangle(f / 3)) {
          if (steps) *steps += count;
          return {Where::outside, f};
        }
        from = f;
        t = f / 3;
        moved = true;
        break;
      }
      if (side == 0) zero[zeros++] = e;
    }
    if (moved) continue;
    if (steps) *steps += count;
    if (zeros == 0) return {Where::inside, 3 * t};
    if (zeros == 1) return {Where::on_edge, zero[0]};
    // p is the vertex shared by the two edges.
    return {Where::on_vertex, next(zero[0]) == zero[1] ? zero[1] : zero[0]};
  }
}

}  // namespace geods::voronoi
