// Vertex removal by flipping Delaunay ears away, then cutting the vertex out at degree 3.
#include "vertex_removal.hpp"

#include <vector>

namespace geods::voronoi {
namespace {
constexpr std::uint32_t kGhost = DelaunayCore::ghost;
constexpr auto next = DelaunayCore::next;
constexpr auto prev = DelaunayCore::prev;
}  // namespace

bool remove_vertex(DelaunayCore& core, std::uint32_t v) {
  NoHooks plain;
  const auto& vert = core.vert;
  const auto& twin = core.twin;
  const auto at = [&](std::uint32_t i) -> const Vec2d& { return core.at(i); };
  std::uint32_t e = core.vertex_edge[v];
  std::vector<std::uint32_t> star, link_vertices;
  for (;;) {
    star.clear();
    link_vertices.clear();
    std::uint32_t h = e;
    do {
      star.push_back(h);
      link_vertices.push_back(vert[next(h)]);
      h = twin[prev(h)];
    } while (h != e);
    const std::size_t degree = star.size();
    if (degree == 3) break;
    bool flipped = false;
    for (std::size_t i = 0; i < degree && !flipped; ++i) {
      const std::uint32_t a = link_vertices[(i + degree - 1) % degree], b = link_vertices[i],
                          c = link_vertices[(i + 1) % degree];
      if (b == kGhost) continue;
      // The flip of v-b must be a flip of a convex quadrilateral.
      bool valid;
      if (a == kGhost)
        valid = orient2d(at(v), at(c), at(b)) < 0;
      else if (c == kGhost)
        valid = orient2d(at(a), at(v), at(b)) < 0;
      else
        valid = orient2d(at(a), at(b), at(c)) > 0 && orient2d(at(v), at(a), at(c)) > 0;
      if (!valid) continue;
      bool empty = true;
      for (std::size_t j = 0; j < degree && empty; ++j) {
        const std::uint32_t x = link_vertices[j];
        if (x == kGhost || x == a || x == b || x == c) continue;
        empty = !core.circle_holds(a, b, c, at(x));  // (a, b, c) is a Delaunay ear
      }
      if (!empty) continue;
      core.flip(star[i], plain);  // star[i] = v -> b becomes v -> a
      e = star[i];
      flipped = true;
    }
    if (!flipped) return false;
  }
  // Degree 3: (v, w0, w1), (v, w1, w2), (v, w2, w0) become (w2, w0, w1).
  const std::uint32_t h0 = star[0], h1 = star[1], h2 = star[2];
  const std::uint32_t outer1 = twin[next(h1)], outer2 = twin[next(h2)];
  core.vert[h0] = link_vertices[2];
  core.link(h0, outer2);
  core.link(prev(h0), outer1);
  core.free_triangle(h1 / 3);
  core.free_triangle(h2 / 3);
  core.last_triangle = h0 / 3;
  return true;
}

}  // namespace geods::voronoi
