// Delaunay3: Bowyer-Watson insertion over flat tetrahedron arrays closed by a
// ghost vertex, exact predicates with the lexicographic symbolic perturbation
// (see delaunay3.hpp).
#include "geods/voronoi/delaunay3.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <numeric>
#include <optional>
#include <string>

#include "../core/prefault.hpp"
#include "brio_order.hpp"
#include "delaunay3_mesh.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::voronoi {
namespace {

using detail::prefault;
using detail::prefaulted_vector;
using detail::reserve_prefaulted;

constexpr std::uint32_t kNone = Delaunay3::no_index;

bool same(const Vec3d& a, const Vec3d& b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

// Exact collinearity: the cross product's components are the three projected orientations.
bool collinear(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    const double pa[2] = {a[i], a[j]}, pb[2] = {b[i], b[j]}, pc[2] = {c[i], c[j]};
    if (orient2d(pa, pb, pc) != 0) return false;
  }
  return true;
}

// kFaceEdge[f][j]: for a tetrahedron whose vertex f is the new point p, the
// other two vertices of its face opposite j (j != f), in the order that makes
// (p, x, y) counter-clockwise seen from vertex j's side: the tetrahedron on
// the other side of that face sees the edge as (y, x).
constexpr std::array<std::array<std::array<std::uint8_t, 2>, 4>, 4> kFaceEdge = [] {
  std::array<std::array<std::array<std::uint8_t, 2>, 4>, 4> e{};
  for (int f = 0; f < 4; ++f)
    for (int j = 0; j < 4; ++j) {
      if (j == f) continue;
      const std::array<int, 3> t = j % 2 == 0 ? std::array<int, 3>{(j + 1) % 4, (j + 3) % 4, (j + 2) % 4}
                                              : std::array<int, 3>{(j + 1) % 4, (j + 2) % 4, (j + 3) % 4};
      const int at = t[0] == f ? 0 : t[1] == f ? 1 : 2;
      e[f][j] = {std::uint8_t(t[(at + 1) % 3]), std::uint8_t(t[(at + 2) % 3])};
    }
  return e;
}();

std::string tet_name(std::uint32_t t) { return "tetrahedron slot " + std::to_string(t); }

}  // namespace

// ------------------------------------------------------------------ Mesh steps

bool Tet3Mesh::perturbed_inside(const Vec3d* const q[4], const Vec3d& p) {
  // Devillers-Teillaud / CGAL: rank the five points lexicographically; the
  // sign of the perturbed determinant is that of the first non-zero term, the
  // orientation of the tetrahedron with the highest-ranked point replaced by p.
  const Vec3d* ranked[5] = {q[0], q[1], q[2], q[3], &p};
  std::sort(ranked, ranked + 5, [](const Vec3d* a, const Vec3d* b) { return lex_less(*a, *b); });
  for (int r = 4; r >= 0; --r) {
    if (ranked[r] == &p) return false;
    for (int j = 0; j < 4; ++j)
      if (ranked[r] == q[j]) {
        const Vec3d* s[4] = {q[0], q[1], q[2], q[3]};
        s[j] = &p;
        const double o = orient(*s[0], *s[1], *s[2], *s[3]);
        if (o != 0) return o > 0;
      }
  }
  return false;
}

bool Tet3Mesh::ghost_conflict(const Vec3d* C, const std::uint32_t* T, std::uint32_t t, const Vec3d& p) {
  const std::uint32_t* v = &T[8 * std::size_t(t)];
  const Vec3d* q[4];
  int g = 0;
  for (int k = 0; k < 4; ++k) {
    if (v[k] == kGhost) g = k;
    q[k] = v[k] == kGhost ? &p : &C[v[k]];
  }
  const double o = orient(*q[0], *q[1], *q[2], *q[3]);
  if (o != 0) return o > 0;
  // On the hull face's plane: as the finite tetrahedron behind it (a ghost there is a corrupt
  // mesh, such as a crafted file that load() is checking: no endless recursion).
  const std::uint32_t behind = T[8 * std::size_t(t) + 4 + g] >> 2;
  const std::uint32_t* w = &T[8 * std::size_t(behind)];
  if (((w[0] | w[1] | w[2] | w[3]) & kGhostBit) != 0) return false;
  return conflict(C, T, behind, p);
}

std::uint32_t Tet3Mesh::walk(const Vec3d& p, std::uint32_t t, std::size_t& steps, std::uint32_t& random) const {
  if (const int g = ghost_index(t); g >= 0) t = tets[8 * std::size_t(t) + 4 + g] >> 2;
  std::uint32_t from = 4;  // the face we entered through: p lies strictly beyond it
  for (;;) {
    ++steps;
    const std::uint32_t* v = &tets[8 * std::size_t(t)];
    const Vec3d* q[4] = {&coords[v[0]], &coords[v[1]], &coords[v[2]], &coords[v[3]]};
    random ^= random << 13, random ^= random >> 17, random ^= random << 5;
    const std::uint32_t first = random & 3;
    std::uint32_t next = kNone;
    for (std::uint32_t k = 0; k < 4; ++k) {
      const std::uint32_t f = (first + k) & 3;
      if (f == from) continue;
      const Vec3d* saved = q[f];
      q[f] = &p;
      const double o = orient(*q[0], *q[1], *q[2], *q[3]);
      q[f] = saved;
      if (o < 0) {
        next = tets[8 * std::size_t(t) + 4 + f];
        break;
      }
    }
    if (next == kNone) return t;
    t = next >> 2;
    from = next & 3;
    if (is_ghost(t)) return t;
  }
}

std::uint32_t Tet3Mesh::new_slot() {
  if (!free_slots.empty()) {
    const std::uint32_t s = free_slots.back();
    free_slots.pop_back();
    return s;
  }
  const std::uint32_t s = std::uint32_t(tets.size() / 8);
  tets.resize(tets.size() + 8);
  mark.push_back(0);
  return s;
}

void Tet3Mesh::free_slot(std::uint32_t s) {
  std::fill_n(&tets[8 * std::size_t(s)], 4, kNone);
  free_slots.push_back(s);
}

void Tet3Mesh::make_first(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  tets.clear();
  free_slots.clear();
  mark.clear();
  if (orient(coords[a], coords[b], coords[c], coords[d]) < 0) std::swap(a, b);
  const std::uint32_t v[4] = {a, b, c, d};
  for (std::uint32_t s = 0; s < 5; ++s) new_slot();
  std::copy(v, v + 4, tets.begin());
  // Ghost tetrahedron 1 + i behind face i: v with v[i] replaced by the ghost,
  // then two other entries swapped (an odd permutation: the ghost's side).
  for (int i = 0; i < 4; ++i) {
    std::uint32_t* g = &tets[8 * std::size_t(1 + i)];
    std::copy(v, v + 4, g);
    g[i] = kGhost;
    std::swap(g[(i + 1) % 4], g[(i + 2) % 4]);
  }
  // Link every pair of the five tetrahedra that share a face.
  for (std::uint32_t s = 0; s < 5; ++s)
    for (std::uint32_t f = 0; f < 4; ++f) {
      const std::uint32_t* vs = &tets[8 * s];
      for (std::uint32_t t = 0; t < 5; ++t) {
        if (t == s) continue;
        const std::uint32_t* vt = &tets[8 * t];
        // t shares s's face f if it holds the three other vertices of s
        int shared = 0;
        std::uint32_t missing = 4;
        for (std::uint32_t k = 0; k < 4; ++k) {
          if (std::find(vs, vs + 4, vt[k]) != vs + 4 && vt[k] != vs[f])
            ++shared;
          else
            missing = k;
        }
        if (shared == 3) tets[8 * s + 4 + f] = 4 * t + missing;
      }
    }
  last = 0;
}

std::uint32_t Tet3Mesh::insert(std::uint32_t pv) {
  if (flips) return insert_by_flips(pv);
  const Vec3d& p = coords[pv];
  const std::uint32_t t = walk(p, last, walk_steps, random);
  if (!is_ghost(t))
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t u = tets[8 * std::size_t(t) + k];
      if (same(coords[u], p)) {
        last = t;
        return u;
      }
    }
  // The cavity: the tetrahedra in conflict with p, depth first from t. Raw
  // pointers: nothing below grows the arrays until the new tetrahedra. A
  // cavity slot's mark is `in` with the bits of its faces on the cavity's
  // boundary (set once all four are tested).
  const Vec3d* C = coords.data();
  std::uint32_t* T = tets.data();
  std::uint8_t* M = mark.data();
  constexpr std::uint8_t in = 0x10, out = 2;
  stack.clear();
  cavity.clear();
  boundary.clear();
  stack.push_back(t);
  M[t] = in;
  while (!stack.empty()) {
    const std::uint32_t c = stack.back();
    stack.pop_back();
    cavity.push_back(c);
    const std::uint32_t* adjacent = &T[8 * std::size_t(c) + 4];
    for (std::uint32_t f = 0; f < 4; ++f) {  // the neighbours' records and marks are the cache misses: ask early
      __builtin_prefetch(&T[8 * std::size_t(adjacent[f] >> 2)]);
      __builtin_prefetch(&M[adjacent[f] >> 2]);
    }
    std::uint8_t faces = 0;
    for (std::uint32_t f = 0; f < 4; ++f) {
      const std::uint32_t a = adjacent[f], n = a >> 2;
      const std::uint8_t m = M[n];
      if (m & in) continue;
      if (m != out) {
        if (conflict(C, T, n, p)) {
          M[n] = in;
          stack.push_back(n);
          continue;
        }
        M[n] = out;
      }
      Boundary& b = boundary.emplace_back();
      std::copy_n(&T[8 * std::size_t(c)], 4, b.v);
      b.v[f] = pv;
      b.face = f;
      b.outer = a;
      b.cell = c;
      faces |= std::uint8_t(1u << f);
    }
    M[c] = in | faces;
  }
  conflicts += cavity.size();
  // The new tetrahedra: each boundary face joined to p, in the cavity's slots first.
  if (boundary.size() > cavity.size()) {
    const std::size_t more = boundary.size() - cavity.size();
    for (std::size_t k = 0; k < more; ++k) cavity.push_back(new_slot());
    T = tets.data();
    M = mark.data();
  }
  // The new tetrahedra, then their links to each other: new tetrahedron i
  // (cavity slot c with p for its vertex f) has three faces through p, each
  // with an edge of its boundary face, which one other boundary face shares,
  // the other way round. A small hash table of those directed edges (valid
  // for this insertion by its stamp, so never cleared) finds the pairs: all
  // edges in, then each looks its reverse up (straight-line loops, no
  // unpredictable walk about the edge through the cavity).
  std::uint32_t newest = kNone;
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const Boundary& b = boundary[i];
    const std::uint32_t s = cavity[i];
    std::uint32_t* w = &T[8 * std::size_t(s)];
    std::copy_n(b.v, 4, w);
    w[4 + b.face] = b.outer;
    T[entry(b.outer)] = 4 * s + b.face;
    if (newest == kNone || ((b.v[0] | b.v[1] | b.v[2] | b.v[3]) & kGhostBit) == 0) newest = s;
  }
  const std::size_t edges = 3 * boundary.size();
  std::size_t size = 64;
  while (size < 4 * edges) size *= 2;
  if (edge_table.size() < size) {
    edge_table.assign(size, EdgeEntry{});
    edge_stamp = 0;
  }
  if (++edge_stamp == 0) {  // wrapped: old stamps could match again
    std::fill(edge_table.begin(), edge_table.end(), EdgeEntry{});
    edge_stamp = 1;
  }
  EdgeEntry* table = edge_table.data();
  const std::uint32_t stamp = edge_stamp, mask = std::uint32_t(size - 1);
  const auto hash = [mask](std::uint32_t a, std::uint32_t b) {
    const std::uint32_t h = a * 0x9E3779B1u + b * 0x85EBCA77u;
    return (h ^ (h >> 15)) & mask;
  };
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const Boundary& b = boundary[i];
    const std::uint32_t s = cavity[i];
    for (std::uint32_t j = 0; j < 4; ++j) {
      if (j == b.face) continue;
      const std::uint32_t x = b.v[kFaceEdge[b.face][j][0]], y = b.v[kFaceEdge[b.face][j][1]];
      std::uint32_t h = hash(x, y);
      while (table[h].stamp == stamp) h = (h + 1) & mask;
      table[h] = {x, y, 4 * s + j, stamp};
    }
  }
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const Boundary& b = boundary[i];
    std::uint32_t* w = &T[8 * std::size_t(cavity[i])];
    for (std::uint32_t j = 0; j < 4; ++j) {
      if (j == b.face) continue;
      const std::uint32_t x = b.v[kFaceEdge[b.face][j][0]], y = b.v[kFaceEdge[b.face][j][1]];
      std::uint32_t h = hash(y, x);
      while (table[h].a != y || table[h].b != x || table[h].stamp != stamp) h = (h + 1) & mask;
      w[4 + j] = table[h].adjacency;
    }
  }
  // Marks back to untested: the cavity's slots and the tetrahedra tested around it.
  for (const std::uint32_t c : cavity) M[c] = 0;
  for (const Boundary& b : boundary) M[b.outer >> 2] = 0;
  for (std::size_t i = boundary.size(); i < cavity.size(); ++i) free_slot(cavity[i]);
  last = newest;
  return kNone;
}

// ------------------------------------------------------------------ Delaunay3

Delaunay3::Delaunay3(std::span<const Vec3d> points, Options options) : options_(options) {
  if (points.size() >= (std::size_t(1) << 31))
    throw Error("Delaunay3: " + std::to_string(points.size()) + " points, at most 2^31 - 1 are supported");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i][0]) || !std::isfinite(points[i][1]) || !std::isfinite(points[i][2]))
      throw Error("Delaunay3: point " + std::to_string(i) + " has a NaN or infinite coordinate");
  reserve_prefaulted(points_, points.size());
  points_.assign(points.begin(), points.end());
  build(options);
  publish();
}

void Delaunay3::build(Options options, bool may_split, std::vector<std::uint32_t>* vertex_points) {
  const std::size_t total = points_.size();
  reserve_prefaulted(removed_, total);
  removed_.resize(total, 0);
  reserve_prefaulted(rep_, total);
  rep_.assign(total, kNone);
  tets_.clear();
  free_slots_.clear();
  walk_steps_ = conflicts_ = seam_points_ = 0;
  flip_counts_ = {};
  std::vector<std::uint32_t> active;
  reserve_prefaulted(active, total);
  for (std::size_t i = 0; i < total; ++i)
    if (!removed_[i]) active.push_back(std::uint32_t(i));
  const std::size_t n = active.size();
  if (n == 0) {
    dimension_ = -1;
    return;
  }
  std::size_t free = 0;
  std::vector<std::uint32_t> storage;
  if (may_split && num_threads() > 1 && n >= std::max<std::size_t>(options.parallel_from, 16) &&
      build_split(active, free, storage)) {
    canonicalize(free, std::move(storage));
    return;
  }
  tets_.clear();  // (a parallel build that gave up may have left slots)
  const std::vector<std::uint32_t> order = brio_order(std::span<const Vec3d>(points_), active, options.seed);

  // The first tetrahedron: the earliest four affinely independent points in the order.
  const auto at = [&](std::size_t k) -> const Vec3d& { return points_[order[k]]; };
  std::size_t kb = 1, kc, kd;
  while (kb < n && same(at(kb), at(0))) ++kb;
  for (kc = kb + 1; kc < n && collinear(at(0), at(kb), at(kc)); ++kc) {
  }
  for (kd = kc + 1; kd < n && Tet3Mesh::orient(at(0), at(kb), at(kc), at(kd)) == 0; ++kd) {
  }
  dimension_ = kb >= n ? 0 : kc >= n ? 1 : kd >= n ? 2 : 3;
  if (dimension_ < 3) {
    // No tetrahedra: merge duplicates by sorting.
    std::vector<std::uint32_t> sorted = active;
    std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) {
      return Tet3Mesh::lex_less(points_[a], points_[b]) || (same(points_[a], points_[b]) && a < b);
    });
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t i = sorted[k];
      if (k > 0 && same(points_[i], points_[sorted[k - 1]])) {
        rep_[i] = rep_[sorted[k - 1]];
      } else {
        rep_[i] = i;
      }
    }
    return;
  }

  // The points' coordinates in insertion order (vertex k is order[k]), with
  // the first tetrahedron's corners first, so that insertion reads them sequentially.
  std::vector<std::uint32_t> sequence;
  reserve_prefaulted(sequence, n);
  sequence.assign(order.begin(), order.end());
  std::swap(sequence[1], sequence[kb]);
  std::swap(sequence[2], sequence[kc]);
  std::swap(sequence[3], sequence[kd]);
  std::vector<Vec3d> coords;  // (Vec3d's default constructor leaves it unset: no pass to fill)
  reserve_prefaulted(coords, n);
  coords.resize(n);
  parallel_for(0, n, 1 << 14, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) coords[k] = points_[sequence[k]];
  });
  Tet3Mesh mesh(coords, tets_, free_slots_);
  mesh.flips = options.insertion == Delaunay3Insertion::flips;
  reserve_prefaulted(tets_, 8 * 7 * n + 64);
  reserve_prefaulted(mesh.mark, 7 * n + 16);
  mesh.make_first(0, 1, 2, 3);
  std::vector<std::uint32_t> merged = prefaulted_vector(n, kNone);  // per vertex k: the earlier vertex at the same place
  std::size_t duplicates = 0;
  for (std::size_t k = 4; k < n; ++k) {
    merged[k] = mesh.insert(std::uint32_t(k));
    duplicates += merged[k] != kNone;
  }
  // From here on a vertex is the index of the point it stands for: the first
  // occurrence among equal points.
  std::vector<std::uint32_t> point_of = prefaulted_vector<std::uint32_t>(n);
  for (std::size_t k = 0; k < n; ++k) point_of[k] = merged[k] == kNone ? sequence[k] : kNone;
  for (std::size_t k = 0; k < n; ++k)
    if (merged[k] != kNone) {
      std::uint32_t& first = point_of[merged[k]];
      first = std::min(first, sequence[k]);
    }
  for (std::size_t k = 0; k < n; ++k) rep_[sequence[k]] = point_of[merged[k] == kNone ? k : merged[k]];
  (void)duplicates;
  walk_steps_ = mesh.walk_steps;
  conflicts_ = mesh.conflicts;
  flip_counts_ = mesh.flip_counts;
  last_ = mesh.last;
  if (vertex_points) {
    points_.swap(coords);
    *vertex_points = std::move(point_of);
    return;
  }
  parallel_for(0, tets_.size() / 8, 1 << 14, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t)
      for (int j = 0; j < 4; ++j) {
        std::uint32_t& v = tets_[8 * t + j];
        if ((v & Tet3Mesh::kGhostBit) == 0) v = point_of[v];
      }
  });
  if (may_split) canonicalize(free_slots_.size());  // (the halves and seams of a parallel build need not be)
}

std::uint32_t Delaunay3::insert(const Vec3d& p) {
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    throw Error("Delaunay3.insert: the point has a NaN or infinite coordinate");
  if (points_.size() + 1 >= (std::size_t(1) << 31)) throw Error("Delaunay3.insert: 2^31 - 1 points are the most");
  const std::uint32_t i = std::uint32_t(points_.size());
  points_.push_back(p);
  removed_.push_back(0);
  rep_.push_back(kNone);
  if (dimension_ < 3) {  // the new point may lift the set to a solid: start again
    build(options_);
    publish();
    return i;
  }
  Tet3Mesh mesh(points_, tets_, free_slots_);
  mesh.mark.assign(tets_.size() / 8, 0);
  mesh.last = last_;
  mesh.flips = options_.insertion == Delaunay3Insertion::flips;
  const std::uint32_t existing = mesh.insert(i);
  rep_[i] = existing == kNone ? i : existing;
  walk_steps_ += mesh.walk_steps;
  conflicts_ += mesh.conflicts;
  for (std::size_t k = 0; k < flip_counts_.size(); ++k) flip_counts_[k] += mesh.flip_counts[k];
  last_ = mesh.last;
  publish();
  return i;
}

void Delaunay3::remove(std::uint32_t i) {
  if (i >= points_.size() || removed_[i])
    throw Error("Delaunay3.remove: point " + std::to_string(i) + (i >= points_.size() ? " does not exist" : " was removed"));
  removed_[i] = 1;
  const std::uint32_t v = rep_[i];
  rep_[i] = kNone;
  if (dimension_ < 3) {
    build(options_);
    publish();
    return;
  }
  if (v != i) return;  // a duplicate: its first occurrence stays the vertex
  // Another copy of the point takes the vertex over: the first remaining one.
  std::uint32_t heir = kNone;
  for (std::size_t j = i + 1; j < points_.size() && heir == kNone; ++j)
    if (rep_[j] == i) heir = std::uint32_t(j);
  if (heir != kNone) {
    for (std::size_t j = heir; j < points_.size(); ++j)
      if (rep_[j] == i) rep_[j] = heir;
    for (std::size_t k = 0; k < tets_.size(); k += 8)
      for (int j = 0; j < 4; ++j)
        if (tets_[k + j] == i) tets_[k + j] = heir;
    publish();
    return;
  }
  if (!remove_locally(v)) {
    ++rebuilds_;
    build(options_);
  }
  publish();
}

bool Delaunay3::remove_locally(std::uint32_t v) {
  // The star of v (every slot holding it, ghosts included) and its boundary:
  // per star slot, the face opposite v, seen counter-clockwise from v's side.
  std::vector<std::uint32_t> star = {vertex_slot_[v]}, link;
  for (std::size_t k = 0; k < star.size(); ++k) {
    const std::uint32_t t = star[k];
    for (int j = 0; j < 4; ++j) {
      const std::uint32_t u = tets_[8 * std::size_t(t) + j];
      if (u == v) continue;
      if ((u & Tet3Mesh::kGhostBit) == 0) link.push_back(u);
      const std::uint32_t n = tets_[8 * std::size_t(t) + 4 + j] >> 2;  // across the face opposite u: holds v
      if (std::find(star.begin(), star.end(), n) == star.end()) star.push_back(n);
    }
  }
  std::sort(link.begin(), link.end());
  link.erase(std::unique(link.begin(), link.end()), link.end());
  std::vector<Vec3d> link_points(link.size());
  for (std::size_t k = 0; k < link.size(); ++k) link_points[k] = points_[link[k]];
  const Delaunay3 small(link_points);
  if (small.dimension() < 3) return false;

  RegionFill region;
  for (const std::uint32_t t : star) {
    const std::uint32_t* w = &tets_[8 * std::size_t(t)];
    const int j = int(std::find(w, w + 4, v) - w);
    region.boundary.push_back({RegionFill::face_of(w, j), w[4 + j]});
  }
  if (!region.match(small.tets_, link)) return false;  // not expected: rebuild rather than guess
  // Replace the star by the fill.
  Tet3Mesh mesh(points_, tets_, free_slots_);
  for (const std::uint32_t t : star) mesh.free_slot(t);
  for (const std::uint32_t s : region.fill) region.slot[s] = mesh.new_slot();
  region.write(tets_);
  last_ = region.slot[region.fill.front()];
  return true;
}

RegionFill::Face RegionFill::face_of(const std::uint32_t* vertices, int opposite) {
  const std::array<int, 3> f = Tet3Mesh::face_towards(opposite);
  Face face = {vertices[f[0]], vertices[f[1]], vertices[f[2]]};
  std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());
  return face;
}

bool RegionFill::match(const std::vector<std::uint32_t>& filler, std::span<const std::uint32_t> ids) {
  if (boundary.empty()) return false;
  std::sort(boundary.begin(), boundary.end());
  const std::size_t slots = filler.size() / 8;
  mapped.resize(filler.size());
  slot.assign(slots, kNone);
  outer.assign(4 * slots, kNone);
  fill.clear();
  // Every filler face looked up among the boundary's (a seam's filler has
  // hundreds of thousands): blocks of slots in parallel, each listing its
  // slots with a boundary face, concatenated in slot order.
  constexpr std::size_t kBlock = 1 << 12;
  const std::size_t blocks = (slots + kBlock - 1) / kBlock;
  std::vector<std::vector<std::uint32_t>> found(blocks);
  std::vector<std::size_t> matched(blocks, 0);
  parallel_for_each_index(
      0, blocks,
      [&](std::size_t block) {
        for (std::size_t s = block * kBlock; s < std::min(slots, (block + 1) * kBlock); ++s) {
          for (int j = 0; j < 4; ++j) {
            const std::uint32_t u = filler[8 * s + j];
            mapped[8 * s + j] = (u & Tet3Mesh::kGhostBit) ? u : ids[u];
            mapped[8 * s + 4 + j] = filler[8 * s + 4 + j];
          }
          if (mapped[8 * s] == kNone) continue;
          bool on_boundary = false;
          for (int j = 0; j < 4; ++j) {
            const Face face = face_of(&mapped[8 * s], j);
            const auto it = std::lower_bound(boundary.begin(), boundary.end(), std::pair(face, std::uint32_t(0)));
            if (it == boundary.end() || it->first != face) continue;
            outer[4 * s + j] = it->second;
            ++matched[block];
            on_boundary = true;
          }
          if (on_boundary) found[block].push_back(std::uint32_t(s));
        }
      },
      1);
  for (std::size_t block = 0; block < blocks; ++block)
    for (const std::uint32_t s : found[block]) slot[s] = 0, fill.push_back(s);
  if (std::accumulate(matched.begin(), matched.end(), std::size_t(0)) != boundary.size()) return false;
  for (std::size_t k = 0; k < fill.size(); ++k)
    for (int j = 0; j < 4; ++j) {
      const std::uint32_t s = fill[k], n = mapped[8 * std::size_t(s) + 4 + j] >> 2;
      if (outer[4 * s + j] == kNone && slot[n] == kNone) slot[n] = 0, fill.push_back(n);
    }
  return true;
}

void RegionFill::write(std::vector<std::uint32_t>& tets) const {
  for (const std::uint32_t s : fill) {
    const std::uint32_t t = slot[s];
    std::copy_n(&mapped[8 * std::size_t(s)], 4, &tets[8 * std::size_t(t)]);
    for (std::uint32_t j = 0; j < 4; ++j) {
      const std::uint32_t a = outer[4 * s + j];
      if (a != kNone) {
        tets[8 * std::size_t(t) + 4 + j] = a;
        tets[Tet3Mesh::entry(a)] = 4 * t + j;
      } else {
        const std::uint32_t inner = mapped[8 * std::size_t(s) + 4 + j];
        tets[8 * std::size_t(t) + 4 + j] = 4 * slot[inner >> 2] + (inner & 3);
      }
    }
  }
}

// The slots in a canonical order that depends only on the points (not on
// the insertion order or the thread count), so that every build gives the same
// arrays: each tetrahedron starts at its smallest vertex, then the smallest of
// the other three in its orientation (an even permutation, so it stays
// positive), and the slots are sorted by their vertices; ghosts sort among
// them (the ghost is the largest vertex), free slots go. Memory bound, and the
// vertex ids are random in space, so the sort avoids random access where it
// can: the keys are first streamed into partitions by the high bits of their
// first vertex (a few hundred partitions, each a sequential stream; blocks of
// slots in parallel, each with its own counts), then each partition is sorted
// within cache (a counting sort on the first vertex, then each bucket), and
// the slots are scattered in their own (spatially coherent) order, so that a
// slot's neighbours are mostly in cache.
namespace {
// position[i]: the entry of tetrahedron v that is its canonical entry i: its
// smallest vertex first, then the smallest of the other three, in an even
// permutation of the four (the orientation stays positive).
inline void canonical_positions(const std::uint32_t* v, std::uint8_t position[4]) {
  // The even permutations that bring each index first: (0123), (1032), (2301), (3210); then a rotation of the rest.
  static constexpr std::uint8_t kEven[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
  const int m = int(std::min_element(v, v + 4) - v);
  const std::uint8_t* r = &kEven[m][1];
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (v[r[i]] < v[r[k]]) k = i;
  position[0] = kEven[m][0], position[1] = r[k], position[2] = r[(k + 1) % 3], position[3] = r[(k + 2) % 3];
}
}  // namespace

void Delaunay3::canonicalize(std::size_t free, std::vector<std::uint32_t> storage) {
  const std::size_t slots = tets_.size() / 8;
  const std::size_t n = points_.size();
  // Where entry j of slot s goes (set for every live slot; the only ones read).
  // Left uninitialized, as every entry read is written first.
  const std::unique_ptr<std::array<std::uint8_t, 4>[]> place(new std::array<std::uint8_t, 4>[slots]);
  prefault(place.get(), 4 * slots);
  struct Key {  // a slot's canonical vertices
    std::uint32_t v[4];
    std::uint32_t slot;
  };
  int shift = 0;  // partition of a key: its first vertex >> shift (at most ~1024 vertices each)
  while ((n >> shift) > 1024) ++shift;
  const std::size_t parts = (n >> shift) + 1;
  constexpr std::size_t kBlock = 1 << 13;  // slots per block (fixed: the layout does not depend on the threads)
  const std::size_t blocks = (slots + kBlock - 1) / kBlock;
  if (blocks == 0) {
    free_slots_.clear();
    last_ = 0;
    return;
  }
  std::vector<std::uint32_t> offset(blocks * parts + 1, 0);  // per (partition, block): where its keys start
  std::vector<std::uint32_t> ghosts_in(parts, 0);  // ghost slots per partition
  // The new slots' array, which holds the keys (five words each) until they
  // are sorted: fresh pages are slow to touch on this kind of machine, so the
  // keys take no pages of their own. Allocated (and zeroed) by task 0, the
  // first a thread starts, while the others count, unless `storage` has room.
  std::vector<std::uint32_t> out = std::move(storage);
  const auto put_key = [&](std::size_t i, const Key& key) { std::memcpy(&out[5 * i], &key, sizeof(Key)); };
  const auto key_at = [&](std::size_t i) {
    Key key;
    std::memcpy(&key, &out[5 * i], sizeof(Key));
    return key;
  };
  static_assert(sizeof(Key) == 5 * sizeof(std::uint32_t));
  // The canonical order of each slot's entries, and the keys per partition per block.
  parallel_for_each_index(
      0, blocks + 1,
      [&](std::size_t task) {
        if (task == 0) {
          reserve_prefaulted(out, 8 * (slots - std::min(free, slots)));
          out.resize(8 * (slots - std::min(free, slots)));
          return;
        }
        const std::size_t block = task - 1;
        std::uint32_t* count = &offset[block * parts];
        for (std::size_t s = block * kBlock; s < std::min(slots, (block + 1) * kBlock); ++s) {
          const std::uint32_t* v = &tets_[8 * s];
          if (v[0] == kNone) continue;
          std::uint8_t position[4];
          canonical_positions(v, position);
          for (int i = 0; i < 4; ++i) place[s][position[i]] = std::uint8_t(i);
          ++count[v[position[0]] >> shift];
          if (((v[0] | v[1] | v[2] | v[3]) & Tet3Mesh::kGhostBit) != 0)  // (few: the hull's)
            std::atomic_ref<std::uint32_t>(ghosts_in[v[position[0]] >> shift]).fetch_add(1, std::memory_order_relaxed);
        }
      },
      1);
  // Exclusive prefix in (partition, block) order: the keys of a partition are contiguous.
  {
    std::uint32_t total = 0;
    for (std::size_t p = 0; p < parts; ++p)
      for (std::size_t block = 0; block < blocks; ++block) {
        std::uint32_t& c = offset[block * parts + p];
        const std::uint32_t here = c;
        c = total;
        total += here;
      }
    offset[blocks * parts] = total;
  }
  const std::size_t live = offset[blocks * parts];
  if (out.size() < 8 * live) out.resize(8 * live);  // (`free` was too high)
  // The public arrays (the finite slots in the new order) are written with
  // the sort, from the sorted keys: partition p's first public tetrahedron is
  // its first slot (block 0's start of it) less the ghosts before it.
  std::vector<std::uint32_t> public_first(parts);
  std::size_t ghosts = 0;
  for (std::size_t p = 0; p < parts; ++p) {
    public_first[p] = offset[p] - std::uint32_t(ghosts);
    ghosts += ghosts_in[p];
  }
  // The keys per partition; meanwhile (task 0, the first one a thread
  // starts) the arrays the sort fills are allocated: zeroing them is one
  // thread's work, which the others' keys overlap. (After a parallel build
  // tetrahedra_ already has room, its pages touched.)
  std::vector<std::uint32_t> new_of;
  parallel_for_each_index(
      0, blocks + 1,
      [&](std::size_t task) {
        if (task == 0) {
          reserve_prefaulted(tetrahedra_, 4 * (live - ghosts));
          tetrahedra_.resize(4 * (live - ghosts));
          reserve_prefaulted(public_of_, live);
          public_of_.resize(live);
          reserve_prefaulted(new_of, slots);
          new_of.assign(slots, kNone);
          return;
        }
        const std::size_t block = task - 1;
        std::uint32_t* next = &offset[block * parts];
        for (std::size_t s = block * kBlock; s < std::min(slots, (block + 1) * kBlock); ++s) {
          const std::uint32_t* v = &tets_[8 * s];
          if (v[0] == kNone) continue;
          std::uint8_t position[4];  // (again rather than from place: reads, no stores to forward)
          canonical_positions(v, position);
          const Key key = {{v[position[0]], v[position[1]], v[position[2]], v[position[3]]}, std::uint32_t(s)};
          put_key(next[key.v[0] >> shift]++, key);
        }
      },
      1);
  // offset[block * parts + p] is now the end of (p, block): block 0's start of p + 1 is p's end.
  const auto part_begin = [&](std::size_t p) -> std::size_t {
    return p == 0 ? 0 : offset[(blocks - 1) * parts + p - 1];
  };
  // The sort.
  parallel_for_each_index(
      0, parts,
      [&](std::size_t p) {
        const std::size_t begin = part_begin(p), end = offset[(blocks - 1) * parts + p];
        if (begin == end) return;
        // A counting sort on the first vertex, then each bucket by the other three.
        const std::uint32_t first = std::uint32_t(p << shift);
        const std::size_t width = std::size_t(1) << shift;
        std::vector<std::uint32_t> count(width + 1, 0);
        for (std::size_t t = begin; t < end; ++t) ++count[key_at(t).v[0] - first + 1];
        for (std::size_t i = 0; i < width; ++i) count[i + 1] += count[i];
        std::vector<Key> sorted(end - begin);
        for (std::size_t t = begin; t < end; ++t) {
          const Key key = key_at(t);
          sorted[count[key.v[0] - first]++] = key;
        }
        for (std::size_t i = 0, from = 0; i < width; from = count[i++]) {
          std::sort(sorted.begin() + std::ptrdiff_t(from), sorted.begin() + std::ptrdiff_t(count[i]),
                    [](const Key& a, const Key& b) { return std::lexicographical_compare(a.v + 1, a.v + 4, b.v + 1, b.v + 4); });
        }
        // (random stores: ask for each line some stores ahead, so that the misses overlap)
        constexpr std::size_t kAhead = 16;
        for (std::size_t t = 0; t < std::min(kAhead, sorted.size()); ++t) __builtin_prefetch(&new_of[sorted[t].slot], 1);
        for (std::size_t t = 0; t < sorted.size(); ++t) {
          if (t + kAhead < sorted.size()) __builtin_prefetch(&new_of[sorted[t + kAhead].slot], 1);
          new_of[sorted[t].slot] = std::uint32_t(begin + t);
        }
        std::uint32_t next = public_first[p];
        for (std::size_t t = 0; t < sorted.size(); ++t) {
          const std::uint32_t* v = sorted[t].v;
          if (((v[2] | v[3]) & Tet3Mesh::kGhostBit) == 0) {  // (the ghost, the largest vertex, is never first or second)
            std::copy_n(v, 4, &tetrahedra_[4 * std::size_t(next)]);
            public_of_[begin + t] = next++;
          } else {
            public_of_[begin + t] = kNone;
          }
        }
      },
      1);
  parallel_for(0, slots, 1 << 14, [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::size_t t = new_of[s];
      if (t == kNone) continue;
      for (int j = 0; j < 4; ++j) {
        const std::uint32_t a = tets_[8 * s + 4 + j], u = a >> 2;
        out[8 * t + place[s][j]] = tets_[8 * s + j];
        out[8 * t + 4 + place[s][j]] = 4 * new_of[u] + place[u][a & 3];
      }
    }
  });
  out.resize(8 * live);  // (a shrink: the free slots go)
  tets_.swap(out);
  free_slots_.clear();
  last_ = last_ < slots && new_of[last_] != kNone ? new_of[last_] : 0;
  published_ = true;
}

// The public arrays: the finite slots in slot order (canonical after a build;
// insert and remove reuse and append slots).
void Delaunay3::publish() {
  if (published_) {
    published_ = false;
    index_vertices();
    return;
  }
  const std::size_t slots = tets_.size() / 8;
  public_of_.assign(slots, kNone);
  std::size_t count = 0;
  for (std::size_t s = 0; s < slots; ++s) {
    const std::uint32_t* v = &tets_[8 * s];
    if (((v[0] | v[1] | v[2] | v[3]) & Tet3Mesh::kGhostBit) == 0) public_of_[s] = std::uint32_t(count++);
  }
  tetrahedra_.resize(4 * count);
  parallel_for(0, slots, 1 << 14, [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s)
      if (public_of_[s] != kNone) std::copy_n(&tets_[8 * s], 4, &tetrahedra_[4 * std::size_t(public_of_[s])]);
  });
  index_vertices();
}

std::vector<std::uint32_t> Delaunay3::neighbors() const {
  std::vector<std::uint32_t> out(tetrahedra_.size());
  parallel_for(0, public_of_.size(), 1 << 14, [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::uint32_t t = public_of_[s];
      if (t == kNone) continue;
      for (int k = 0; k < 4; ++k) out[4 * std::size_t(t) + k] = public_of_[tets_[8 * s + 4 + k] >> 2];
    }
  });
  return out;
}

void Delaunay3::index_vertices() {
  // Per vertex the last slot holding it; on several threads, the two halves
  // of the slots at once, the upper one's answer first.
  const std::size_t slots = tets_.size() / 8;
  const auto scan = [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& into) {
    reserve_prefaulted(into, points_.size());
    into.assign(points_.size(), kNone);
    for (std::size_t s = begin; s < end; ++s)
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t v = tets_[8 * s + k];
        if ((v & Tet3Mesh::kGhostBit) == 0) into[v] = std::uint32_t(s);
      }
  };
  if (num_threads() == 1 || slots < (1 << 16)) {
    scan(0, slots, vertex_slot_);
    return;
  }
  std::vector<std::uint32_t> upper;
  parallel_for_each_index(
      0, 2, [&](std::size_t h) { h == 0 ? scan(0, slots / 2, vertex_slot_) : scan(slots / 2, slots, upper); }, 1);
  parallel_for(0, upper.size(), 1 << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v)
      if (upper[v] != kNone) vertex_slot_[v] = upper[v];
  });
}

std::vector<Delaunay3::Triangle> Delaunay3::hull() const {
  std::vector<Triangle> out;
  const std::size_t slots = tets_.size() / 8;
  for (std::size_t s = 0; s < slots; ++s) {
    const std::uint32_t* v = &tets_[8 * s];
    if (v[0] == kNone) continue;
    for (int g = 0; g < 4; ++g)
      if (v[g] == Tet3Mesh::kGhost) {
        // The face opposite the ghost, oriented towards it (outwards of the hull).
        const std::array<int, 3> f = Tet3Mesh::face_towards(g);
        out.push_back({v[f[0]], v[f[1]], v[f[2]]});
      }
  }
  return out;
}

std::size_t Delaunay3::duplicate_count() const {
  std::size_t count = 0;
  for (std::size_t i = 0; i < rep_.size(); ++i) count += rep_[i] != i && rep_[i] != kNone;
  return count;
}

std::uint32_t Delaunay3::start_slot(std::uint32_t hint) const {
  if (hint != kNone && hint < tetrahedron_count()) {
    // the public index's slot: the k-th live finite slot; find it through its vertices
    return vertex_slot_[tetrahedra_[4 * std::size_t(hint)]];
  }
  return last_ < tets_.size() / 8 && tets_[8 * std::size_t(last_)] != kNone ? last_ : vertex_slot_[0];
}

std::uint32_t Delaunay3::locate(const Vec3d& q, std::uint32_t hint) const {
  if (dimension_ < 3) return kNone;
  if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
    throw Error("Delaunay3.locate: the query has a NaN or infinite coordinate");
  Tet3Mesh mesh(const_cast<std::vector<Vec3d>&>(points_), const_cast<std::vector<std::uint32_t>&>(tets_),
                const_cast<std::vector<std::uint32_t>&>(free_slots_));
  std::size_t steps = 0;
  std::uint32_t random = 2463534242u;
  const std::uint32_t t = mesh.walk(q, start_slot(hint), steps, random);
  return mesh.is_ghost(t) ? kNone : public_of_[t];
}

std::vector<std::uint32_t> Delaunay3::vertex_neighbors(std::uint32_t point) const {
  std::vector<std::uint32_t> out;
  if (point >= rep_.size() || rep_[point] != point) return out;
  const std::uint32_t v = point;
  if (dimension_ < 3) return out;
  // The star of v: the slots around it, breadth first across the faces that hold v.
  std::vector<std::uint32_t> stack = {vertex_slot_[v]}, seen = stack;
  while (!stack.empty()) {
    const std::uint32_t t = stack.back();
    stack.pop_back();
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t u = tets_[8 * std::size_t(t) + k];
      if (u == v) continue;
      if ((u & Tet3Mesh::kGhostBit) == 0) out.push_back(u);
      const std::uint32_t n = tets_[8 * std::size_t(t) + 4 + k] >> 2;  // across the face opposite u: holds v
      if (std::find(seen.begin(), seen.end(), n) == seen.end()) {
        seen.push_back(n);
        stack.push_back(n);
      }
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::uint32_t Delaunay3::nearest_vertex(const Vec3d& q) const {
  if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
    throw Error("Delaunay3.nearest_vertex: the query has a NaN or infinite coordinate");
  if (dimension_ < 0) return kNone;
  const auto distance = [&](std::uint32_t v) { return (points_[v] - q).squaredNorm(); };
  std::uint32_t best = kNone;
  if (dimension_ < 3) {
    for (std::uint32_t v = 0; v < points_.size(); ++v)
      if (rep_[v] == v && (best == kNone || distance(v) < distance(best))) best = v;
    return best;
  }
  std::uint32_t slot = start_slot(kNone);
  return nearest_vertex_from(q, slot);
}

std::uint32_t Delaunay3::nearest_vertex_from(const Vec3d& q, std::uint32_t& slot) const {
  const auto distance = [&](std::uint32_t v) { return (points_[v] - q).squaredNorm(); };
  Tet3Mesh mesh(const_cast<std::vector<Vec3d>&>(points_), const_cast<std::vector<std::uint32_t>&>(tets_),
                const_cast<std::vector<std::uint32_t>&>(free_slots_));
  std::size_t steps = 0;
  std::uint32_t random = 2463534242u;
  const std::uint32_t t = slot = mesh.walk(q, slot, steps, random);
  std::uint32_t best = kNone;
  for (int k = 0; k < 4; ++k) {
    const std::uint32_t u = tets_[8 * std::size_t(t) + k];
    if ((u & Tet3Mesh::kGhostBit) == 0 && (best == kNone || distance(u) < distance(best))) best = u;
  }
  // Greedy descent: a vertex none of whose Delaunay neighbours is closer is the nearest.
  for (bool moved = true; moved;) {
    moved = false;
    for (const std::uint32_t u : vertex_neighbors(best)) {
      if (distance(u) < distance(best)) {
        best = u;
        moved = true;
      }
    }
  }
  return best;
}

Delaunay3Stats Delaunay3::stats() const {
  Delaunay3Stats s;
  s.points = points_.size();
  s.duplicates = duplicate_count();
  s.removed = std::size_t(std::count(removed_.begin(), removed_.end(), 1));
  s.rebuilds = rebuilds_;
  s.vertices = s.points - s.duplicates - s.removed;
  s.tetrahedra = tetrahedron_count();
  for (std::size_t k = 0; k < tets_.size(); k += 8)
    s.hull_triangles += std::count(&tets_[k], &tets_[k] + 4, Tet3Mesh::kGhost);
  s.dimension = dimension_ < 0 ? 0 : std::size_t(dimension_);
  s.walk_steps = walk_steps_;
  s.conflicts = conflicts_;
  s.seam_points = seam_points_;
  s.flips_14 = flip_counts_[Tet3Mesh::flip_14], s.flips_23 = flip_counts_[Tet3Mesh::flip_23];
  s.flips_32 = flip_counts_[Tet3Mesh::flip_32], s.flips_44 = flip_counts_[Tet3Mesh::flip_44];
  s.splits = flip_counts_[Tet3Mesh::flip_split], s.hull_inserts = flip_counts_[Tet3Mesh::flip_hull];
  s.unflippable = flip_counts_[Tet3Mesh::flip_unflippable], s.flip_repairs = flip_counts_[Tet3Mesh::flip_repair];
  const auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  s.bytes = bytes(points_) + bytes(rep_) +
            bytes(tets_) + bytes(removed_) + bytes(vertex_slot_) + bytes(free_slots_) + bytes(tetrahedra_) + bytes(public_of_);
  return s;
}

void Delaunay3::validate() const {
  const std::size_t n = points_.size();
  if (rep_.size() != n || removed_.size() != n) throw Error("Delaunay3: per-point arrays of the wrong size");
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t r = rep_[i];
    if (removed_[i]) {
      if (r != kNone) throw Error("Delaunay3: removed point " + std::to_string(i) + " has a vertex");
      continue;
    }
    if (r > i || rep_[r] != r || removed_[r] || !same(points_[r], points_[i]))
      throw Error("Delaunay3: point " + std::to_string(i) + " has a bad representative");
  }
  if (dimension_ < 3) {
    if (!tetrahedra_.empty()) throw Error("Delaunay3: a lower-dimensional set has tetrahedra");
    return;
  }
  const std::size_t slots = tets_.size() / 8;
  if (tets_.size() % 8) throw Error("Delaunay3: tetrahedron array of the wrong size");
  Tet3Mesh mesh(const_cast<std::vector<Vec3d>&>(points_), const_cast<std::vector<std::uint32_t>&>(tets_),
                const_cast<std::vector<std::uint32_t>&>(free_slots_));
  const std::size_t vertex_count = n;
  std::vector<std::uint8_t> used(vertex_count, 0);
  constexpr std::size_t kBlock = 1 << 14;
  const std::size_t blocks = (slots + kBlock - 1) / kBlock;
  std::vector<std::optional<Error>> errors(blocks);
  std::vector<std::size_t> finite(blocks, 0);
  parallel_for_each_index(
      0, blocks,
      [&](std::size_t block) {
        try {
          for (std::size_t s = block * kBlock; s < std::min(slots, (block + 1) * kBlock); ++s) {
            const std::uint32_t* v = &tets_[8 * s];
            if (v[0] == kNone) continue;
            int ghosts = 0;
            for (int k = 0; k < 4; ++k) {
              if (v[k] == Tet3Mesh::kGhost)
                ++ghosts;
              else if (v[k] >= vertex_count || rep_[v[k]] != v[k])
                throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) + " has a vertex that is not a representative");
              else
                used[v[k]] = 1;  // benign race: every writer stores 1
            }
            if (ghosts > 1) throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) + " has two ghost vertices");
            for (std::uint32_t f = 0; f < 4; ++f) {
              const std::uint32_t a = tets_[8 * s + 4 + f];
              if ((a >> 2) >= slots || tets_[8 * std::size_t(a >> 2)] == kNone || tets_[Tet3Mesh::entry(a)] != 4 * s + f)
                throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) + " face " + std::to_string(f) +
                            ": neighbour not mutual");
              for (std::uint32_t k = 0; k < 4; ++k) {
                if (k == f) continue;
                const std::uint32_t* w = &tets_[8 * std::size_t(a >> 2)];
                if (std::find(w, w + 4, v[k]) == w + 4 || w[a & 3] == v[k])
                  throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) + " face " + std::to_string(f) +
                              ": neighbour does not share the face");
              }
              const std::uint32_t opposite = tets_[Tet3Mesh::opposite(a)];
              if (opposite == Tet3Mesh::kGhost) continue;
              const Vec3d& p = points_[opposite];
              if (ghosts == 0) {
                const double s_exact = mesh.in_sphere(points_[v[0]], points_[v[1]], points_[v[2]], points_[v[3]], p);
                if (s_exact > 0)
                  throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) +
                              ": the opposite vertex of a neighbour is inside its circumsphere");
              }
              if (mesh.in_conflict(std::uint32_t(s), p))
                throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) + " face " + std::to_string(f) +
                            (ghosts ? ": the hull is not convex there" : ": not Delaunay after the perturbation"));
            }
            if (ghosts == 0) {
              if (Tet3Mesh::orient(points_[v[0]], points_[v[1]], points_[v[2]], points_[v[3]]) <= 0)
                throw Error("Delaunay3: " + tet_name(std::uint32_t(s)) + " is not positively oriented");
              ++finite[block];
            }
          }
        } catch (const Error& e) {
          errors[block] = e;
        }
      },
      1);
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    if (errors[b]) throw *errors[b];
    total += finite[b];
  }
  for (std::size_t u = 0; u < vertex_count; ++u)
    if (!used[u] && rep_[u] == u) throw Error("Delaunay3: point " + std::to_string(u) + " is in no tetrahedron");
  if (total != tetrahedron_count()) throw Error("Delaunay3: the public tetrahedra are not the finite ones");
  for (std::size_t s = 0; s < slots; ++s) {
    const std::uint32_t t = public_of_[s];
    if (t == kNone) continue;
    for (int k = 0; k < 4; ++k)
      if (tetrahedra_[4 * std::size_t(t) + k] != tets_[8 * s + k])
        throw Error("Delaunay3: public tetrahedron " + std::to_string(t) + " differs from its slot");
  }
}

}  // namespace geods::voronoi
