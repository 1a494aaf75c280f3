// Derives the marching-cubes table: the contour segments on the six faces
// (one per face, two on an ambiguous face as the decision says) are chained
// into closed loops on the cube's surface, and each loop is triangulated on
// its own. Faces of neighbouring cells see the same segments, so the surface
// is closed; a loop is never cut by a diagonal between two points of one face,
// so no mesh edge lies in a face shared with the neighbour cell.
#include "geods/iso/case_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/vec.hpp"
#include "cell.hpp"

namespace geods::iso {
namespace {

int edge_between(int a, int b) {
  const int d = a ^ b;
  const int axis = d == 1 ? 0 : d == 2 ? 1 : 2;
  const int lo = std::min(a, b);
  int bits[3] = {lo & 1, (lo >> 1) & 1, (lo >> 2) & 1};
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
  return 4 * axis + bits[a1] + 2 * bits[a2];
}

Vec3d corner_position(int c) { return Vec3d(c & 1, (c >> 1) & 1, (c >> 2) & 1); }

Vec3d edge_midpoint(int e) {
  const auto [a, b] = edge_corners(e);
  return 0.5 * (corner_position(a) + corner_position(b));
}

bool edges_share_face(int e1, int e2) {
  for (int f = 0; f < 6; ++f) {
    const auto c = face_corners(f);
    int found = 0;
    for (int q = 0; q < 4; ++q) {
      const int e = edge_between(c[q], c[(q + 1) % 4]);
      found += (e == e1) + (e == e2);
    }
    if (found == 2) return true;
  }
  return false;
}

// Triangulates one loop of edge points (in its orientation: inside on the
// left seen from outside the cube) with the shortest total diagonal length,
// never using a diagonal between two points of one face (the neighbour cell
// could use it too). Appends the triangles, oriented from inside to outside;
// false if no such triangulation exists.
bool triangulate_loop(const std::vector<int>& loop, std::vector<std::uint8_t>& out) {
  const int k = int(loop.size());
  const double inf = std::numeric_limits<double>::infinity();
  auto weight = [&](int i, int j) {
    if (j == i + 1 || (i == 0 && j == k - 1)) return 0.0;
    if (edges_share_face(loop[i], loop[j])) return inf;
    return (edge_midpoint(loop[i]) - edge_midpoint(loop[j])).norm();
  };
  std::vector<double> cost(k * k, 0.0);
  std::vector<int> split(k * k, -1);
  for (int len = 2; len < k; ++len) {
    for (int i = 0; i + len < k; ++i) {
      const int j = i + len;
      double best = inf;
      for (int m = i + 1; m < j; ++m) {
        const double c = cost[i * k + m] + cost[m * k + j] + weight(i, m) + weight(m, j);
        if (c < best) best = c, split[i * k + j] = m;
      }
      cost[i * k + j] = best;
    }
  }
  if (!(cost[k - 1] < inf)) return false;
  std::vector<std::pair<int, int>> stack = {{0, k - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int m = split[i * k + j];
    // Loop order gives normals towards the inside corners; reversed here.
    out.push_back(std::uint8_t(loop[i]));
    out.push_back(std::uint8_t(loop[j]));
    out.push_back(std::uint8_t(loop[m]));
    stack.push_back({m, j});
    stack.push_back({i, m});
  }
  return true;
}

struct CaseEntry {
  std::vector<std::uint8_t> triangles;
  std::vector<std::uint16_t> centres;  // edge masks of the loops fanned around a centre vertex
};

// Triangles (edge triples) of case c with face decisions `joined`.
CaseEntry derive_case(int c, int joined) {
  auto inside = [c](int corner) { return (c >> corner) & 1; };
  int next[12];
  std::fill(next, next + 12, -1);
  int incoming[12] = {};
  auto add_segment = [&](int f, int ep, int eq) {
    const int axis = f / 2;
    Vec3d n = Vec3d::Zero();
    n[axis] = (f & 1) ? 1.0 : -1.0;
    const auto [a, b] = edge_corners(ep);
    const Vec3d p = edge_midpoint(ep), q = edge_midpoint(eq);
    const Vec3d x = corner_position(inside(a) ? a : b);
    // Inside on the left of the segment seen from outside the cube.
    if (n.dot((q - p).cross(x - p)) < 0) std::swap(ep, eq);
    if (next[ep] != -1) throw Error("iso: case table: two segments leave one edge point");
    next[ep] = eq;
    ++incoming[eq];
  };
  for (int f = 0; f < 6; ++f) {
    const auto fc = face_corners(f);
    int in[4], e[4], n_in = 0;
    for (int q = 0; q < 4; ++q) in[q] = inside(fc[q]), n_in += in[q];
    for (int q = 0; q < 4; ++q) e[q] = edge_between(fc[q], fc[(q + 1) % 4]);
    if (n_in == 0 || n_in == 4) continue;
    if (n_in == 2 && in[0] == in[2]) {
      // Cut off the corners that are not joined: the outside ones if the
      // inside corners are joined through the face, else the inside ones.
      const int cut = ((joined >> f) & 1) ? 0 : 1;
      for (int q = 0; q < 4; ++q)
        if (in[q] == cut) add_segment(f, e[(q + 3) % 4], e[q]);
      continue;
    }
    int crossing[2], n_cross = 0;
    for (int q = 0; q < 4; ++q)
      if (in[q] != in[(q + 1) % 4]) crossing[n_cross++] = e[q];
    add_segment(f, crossing[0], crossing[1]);
  }
  CaseEntry entry;
  bool done[12] = {};
  for (int start = 0; start < 12; ++start) {
    if (next[start] == -1 || done[start]) continue;
    std::vector<int> loop;
    for (int e = start; !done[e]; e = next[e]) {
      if (next[e] == -1 || incoming[e] != 1) throw Error("iso: case table: open contour");
      done[e] = true;
      loop.push_back(e);
    }
    if (triangulate_loop(loop, entry.triangles)) continue;
    // A fan around a vertex inside the cell (the mean of the loop's points).
    const std::uint8_t centre = std::uint8_t(12 + entry.centres.size());
    std::uint16_t mask = 0;
    for (std::size_t i = 0; i < loop.size(); ++i) {
      mask |= std::uint16_t(1 << loop[i]);
      entry.triangles.push_back(centre);
      entry.triangles.push_back(std::uint8_t(loop[(i + 1) % loop.size()]));
      entry.triangles.push_back(std::uint8_t(loop[i]));
    }
    entry.centres.push_back(mask);
  }
  if (entry.centres.size() > kMaxCentres) throw Error("iso: case table: too many centre vertices in one cell");
  return entry;
}

struct Table {
  std::uint8_t ambiguous[256];
  std::vector<std::uint32_t> offsets;  // 256 * 64 + 1
  std::vector<std::uint8_t> edges;
  std::vector<std::uint16_t> centres;  // kMaxCentres per entry, 0 if unused
  int max_triangles = 0;

  Table() {
    offsets.reserve(256 * 64 + 1);
    for (int c = 0; c < 256; ++c) {
      ambiguous[c] = 0;
      for (int f = 0; f < 6; ++f) {
        const auto fc = face_corners(f);
        const int in0 = (c >> fc[0]) & 1, in1 = (c >> fc[1]) & 1, in2 = (c >> fc[2]) & 1, in3 = (c >> fc[3]) & 1;
        if (in0 == in2 && in1 == in3 && in0 != in1) ambiguous[c] |= std::uint8_t(1 << f);
      }
    }
    for (int c = 0; c < 256; ++c) {
      std::vector<CaseEntry> derived(64);  // by the decisions of the ambiguous faces only
      for (int joined = 0; joined < 64; ++joined) {
        offsets.push_back(std::uint32_t(edges.size()));
        const int key = joined & ambiguous[c];
        if (key == joined) derived[key] = derive_case(c, key);
        const CaseEntry& e = derived[key];
        edges.insert(edges.end(), e.triangles.begin(), e.triangles.end());
        max_triangles = std::max(max_triangles, int(e.triangles.size() / 3));
        for (std::size_t i = 0; i < kMaxCentres; ++i) centres.push_back(i < e.centres.size() ? e.centres[i] : 0);
      }
    }
    offsets.push_back(std::uint32_t(edges.size()));
  }
};

const Table& table() {
  static const Table t;
  return t;
}

}  // namespace

std::array<int, 2> edge_corners(int e) {
  const int axis = e / 4, r = e % 4;
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
  const int lo = ((r & 1) << a1) | ((r >> 1) << a2);
  return {lo, lo | (1 << axis)};
}

std::array<int, 4> face_corners(int f) {
  const int axis = f / 2, side = f & 1;
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  auto corner = [&](int cu, int cv) { return (side << axis) | (cu << u) | (cv << v); };
  return {corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)};
}

std::uint8_t ambiguous_faces(int c) { return table().ambiguous[c & 255]; }

std::span<const std::uint8_t> case_triangles(int c, std::uint8_t joined) {
  const Table& t = table();
  const std::size_t i = std::size_t(c & 255) * 64 + (joined & t.ambiguous[c & 255]);
  return {t.edges.data() + t.offsets[i], t.edges.data() + t.offsets[i + 1]};
}

std::span<const std::uint16_t> case_centres(int c, std::uint8_t joined) {
  const Table& t = table();
  const std::size_t i = std::size_t(c & 255) * 64 + (joined & t.ambiguous[c & 255]);
  const std::uint16_t* first = t.centres.data() + i * kMaxCentres;
  std::size_t n = 0;
  while (n < kMaxCentres && first[n] != 0) ++n;
  return {first, n};
}

int max_case_triangles() { return table().max_triangles; }

detail::CaseTableView detail::case_table_view() {
  const Table& t = table();
  return {t.ambiguous, t.offsets.data(), t.edges.data(), t.centres.data()};
}

}  // namespace geods::iso
