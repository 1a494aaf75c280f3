// Delaunay3's parallel build: the two halves of the set (split at the median
// x) tetrahedralized at the same time, their certainly-Delaunay tetrahedra
// kept, the seam between them refilled from the seam vertices' own
// tetrahedralization (see delaunay3.hpp).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <optional>
#include <utility>

#include "../core/prefault.hpp"
#include "delaunay3_mesh.hpp"
#include "geods/core/aabb.hpp"
#include "geods/core/parallel.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/voronoi/delaunay3.hpp"

namespace geods::voronoi {
namespace {

constexpr std::uint32_t kNone = Delaunay3::no_index;
constexpr std::uint32_t kGhost = Tet3Mesh::kGhost;

// A convex polytope's vertex graph over its own vertices only (a few thousand:
// an array over every point would be megabytes of fresh pages to clear).
struct HullGraph {
  std::vector<std::uint32_t> vertex;                 // the hull's vertices, ascending
  std::vector<std::vector<std::uint32_t>> adjacent;  // per hull vertex: its neighbours' places in `vertex`

  explicit HullGraph(const std::vector<Delaunay3::Triangle>& faces) {
    for (const Delaunay3::Triangle& t : faces) vertex.insert(vertex.end(), t.begin(), t.end());
    std::sort(vertex.begin(), vertex.end());
    vertex.erase(std::unique(vertex.begin(), vertex.end()), vertex.end());
    adjacent.resize(vertex.size());
    const auto place = [&](std::uint32_t v) {
      return std::uint32_t(std::lower_bound(vertex.begin(), vertex.end(), v) - vertex.begin());
    };
    for (const Delaunay3::Triangle& t : faces)
      for (int k = 0; k < 3; ++k) adjacent[place(t[k])].push_back(place(t[(k + 1) % 3]));
  }

  // The vertex farthest along `direction` (its place): a strict hill climb from
  // place `start` (on a convex polytope a vertex that no neighbour beats is a maximum).
  std::uint32_t extreme(std::span<const Vec3d> points, const Vec3d& direction, std::uint32_t start) const {
    std::uint32_t best = start;
    double value = direction.dot(points[vertex[best]]);
    for (bool moved = true; moved;) {
      moved = false;
      for (const std::uint32_t u : adjacent[best])
        if (const double x = direction.dot(points[vertex[u]]); x > value) {
          best = u, value = x, moved = true;
          break;
        }
    }
    return best;
  }
};

constexpr std::size_t kBlock = 1 << 14;  // slots per block of the parallel passes over a half's slots

// fn(s, out) for every slot s < slots, in blocks in parallel; the blocks'
// outputs concatenated in slot order (the same whatever the threads).
template <class T, class Fn>
std::vector<T> gather_slots(std::size_t slots, const Fn& fn) {
  const std::size_t blocks = (slots + kBlock - 1) / kBlock;
  std::vector<std::vector<T>> part(blocks);
  parallel_for_each_index(
      0, blocks,
      [&](std::size_t b) {
        for (std::size_t s = b * kBlock; s < std::min(slots, (b + 1) * kBlock); ++s) fn(s, part[b]);
      },
      1);
  std::size_t total = 0;
  for (const std::vector<T>& p : part) total += p.size();
  std::vector<T> out;
  out.reserve(total);
  for (const std::vector<T>& p : part) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace

bool Delaunay3::build_split(const std::vector<std::uint32_t>& active, std::size_t& free,
                            std::vector<std::uint32_t>& storage) {
  double scale = 0;
  AABB3d bounds;
  for (const std::uint32_t i : active) {
    bounds.extend(points_[i]);
    scale = std::max({scale, std::abs(points_[i][0]), std::abs(points_[i][1]), std::abs(points_[i][2])});
  }
  const double extent = (bounds.hi - bounds.lo).maxCoeff();
  // Squared distances of the certificates below must stay in double range: else build sequentially.
  if (!(scale < 1e100 && extent > 1e-100)) return false;
  // The halves: x below the median, and the rest (equal points stay together).
  std::vector<double> xs = detail::prefaulted_vector<double>(active.size());
  for (std::size_t k = 0; k < active.size(); ++k) xs[k] = points_[active[k]][0];
  std::nth_element(xs.begin(), xs.begin() + std::ptrdiff_t(xs.size() / 2), xs.end());
  const double split = xs[xs.size() / 2];
  std::array<std::vector<std::uint32_t>, 2> global;  // per half, its points' indices here
  const std::size_t below =
      std::size_t(std::count_if(active.begin(), active.end(), [&](std::uint32_t i) { return points_[i][0] < split; }));
  detail::reserve_prefaulted(global[0], below);
  detail::reserve_prefaulted(global[1], active.size() - below);
  for (const std::uint32_t i : active) global[points_[i][0] < split ? 0 : 1].push_back(i);
  if (global[0].size() < 8 || global[1].size() < 8) return false;
  const double tolerance = 1e-9 * scale;
  // A finite slot's circumsphere: its centre and a radius that covers the
  // rounding; none for slivers, whose centres' rounding the margins do not
  // bound (they go to the seam). Plain doubles: the orientation here only
  // measures flatness.
  struct Sphere {
    Vec3d centre;
    double reach;
  };
  const auto sphere = [&](const Delaunay3& d, const std::uint32_t* v) -> std::optional<Sphere> {
    const Vec3d* C = d.points_.data();
    const Vec3d ab = C[v[1]] - C[v[0]], ac = C[v[2]] - C[v[0]], ad = C[v[3]] - C[v[0]];
    const double det = 2 * ab.dot(ac.cross(ad));
    // (one square root: sqrt is monotone and correctly rounded, so this is the largest edge's norm exactly)
    const double edge = std::sqrt(std::max({ab.squaredNorm(), ac.squaredNorm(), ad.squaredNorm()}));
    if (!(std::abs(det) >= 2e-6 * edge * edge * edge)) return {};
    const Vec3d offset =
        (ab.squaredNorm() * ac.cross(ad) + ac.squaredNorm() * ad.cross(ab) + ad.squaredNorm() * ab.cross(ac)) / det;
    const double radius = offset.norm();
    if (!std::isfinite(radius)) return {};
    return Sphere{C[v[0]] + offset, radius * (1 + 1e-6) + tolerance};
  };
  // state[h][s] of slot s of half h: kept (certainly a (ghost) tetrahedron of
  // the whole set), to the seam, or pending (its sphere crosses the split);
  // hull_face until both halves are built (it needs the other half's hull).
  constexpr std::uint8_t seam_slot = 0, kept = 1, pending = 2, hull_face = 3;
  const double far = 16 * extent / std::cbrt(double(active.size()));  // 16 mean spacings
  std::array<std::vector<std::uint8_t>, 2> valid;
  std::array<std::atomic<double>, 2> beyond{};  // per half: how far its pending spheres reach past the split
  // Per half, its hull's vertex graph (for the extreme points the other half's hull faces ask for).
  std::array<std::optional<HullGraph>, 2> hull_graph;
  // Each half, once built, indexes its hull and classifies its finite slots
  // (which need nothing of the other half) at once: the half built first
  // does not wait for the other, and its thread helps with the other's pass.
  std::array<Delaunay3, 2> half;
  std::array<std::vector<std::uint32_t>, 2> vertex_global;  // per half: its vertices' points here
  // Half 0's slots become the assembled array in place, and half 1's, once
  // dead, the canonical order's new slots: room for every slot in both,
  // prefaulted by the halves' builds (fresh pages are slow to touch, and so
  // both threads touch them at once); and the public tetrahedra's, by the
  // thread that is free first.
  for (int h = 0; h < 2; ++h) half[h].tets_.reserve(8 * 7 * active.size() + 64);
  parallel_for_each_index(
      0, 3,
      [&](std::size_t h) {
        if (h == 2) {
          detail::reserve_prefaulted(tetrahedra_, 4 * 7 * active.size() + 64);
          return;
        }
        Delaunay3& self = half[h];
        self.options_ = options_;
        detail::reserve_prefaulted(self.points_, global[h].size());
        self.points_.resize(global[h].size());
        for (std::size_t k = 0; k < global[h].size(); ++k) self.points_[k] = points_[global[h][k]];
        // (vertices in insertion order: the passes below read their coordinates and global ids in order)
        self.build(options_, false, &vertex_global[h]);
        if (self.dimension_ < 3) return;
        parallel_for(0, vertex_global[h].size(), 1 << 14, [&](std::size_t begin, std::size_t end) {
          for (std::size_t k = begin; k < end; ++k)
            if (vertex_global[h][k] != kNone) vertex_global[h][k] = global[h][vertex_global[h][k]];
        });
        hull_graph[h].emplace(self.hull());
        const std::size_t slots = self.tets_.size() / 8;
        detail::reserve_prefaulted(valid[h], slots);
        valid[h].assign(slots, seam_slot);
        parallel_for(0, slots, 1 << 12, [&](std::size_t begin, std::size_t end) {
          double deepest = 0;
          for (std::size_t s = begin; s < end; ++s) {
            const std::uint32_t* v = &self.tets_[8 * s];
            if (v[0] == kNone) continue;
            if (std::find(v, v + 4, kGhost) != v + 4) {
              valid[h][s] = hull_face;
              continue;
            }
            const auto b = sphere(self, v);
            if (!b) continue;
            const double past = h == 0 ? b->centre[0] + b->reach - split : split - (b->centre[0] - b->reach);
            if (past < 0) {
              valid[h][s] = kept;  // the sphere does not reach the other half's side
            } else if (past <= far) {  // (larger spheres, flat ones by the hull, go to the seam: the slab stays thin)
              valid[h][s] = pending;
              deepest = std::max(deepest, past);
            }
          }
          for (double seen = beyond[h].load(); deepest > seen && !beyond[h].compare_exchange_weak(seen, deepest);) {
          }
        });
      },
      1);
  if (half[0].dimension_ < 3 || half[1].dimension_ < 3) return false;
  // The hull faces: kept if the other half lies strictly inside the face's plane, by a margin.
  for (int h = 0; h < 2; ++h) {
    const Delaunay3& self = half[h];
    const Delaunay3& other = half[1 - h];
    const Vec3d* C = self.points_.data();
    parallel_for(0, valid[h].size(), 1 << 12, [&](std::size_t begin, std::size_t end) {
      std::uint32_t climb = 0;
      for (std::size_t s = begin; s < end; ++s) {
        if (valid[h][s] != hull_face) continue;
        valid[h][s] = seam_slot;
        const std::uint32_t* v = &self.tets_[8 * s];
        const int g = int(std::find(v, v + 4, kGhost) - v);
        const std::array<int, 3> f = Tet3Mesh::face_towards(g);
        const Vec3d &a = C[v[f[0]]], &b = C[v[f[1]]], &c = C[v[f[2]]];
        const Vec3d normal = (b - a).cross(c - a);  // outwards: the face is counter-clockwise seen from the ghost's side
        const double length = normal.norm();
        if (!(length > 0)) continue;
        climb = hull_graph[1 - h]->extreme(other.points_, normal, climb);
        valid[h][s] = normal.dot(other.points_[hull_graph[1 - h]->vertex[climb]] - a) / length < -tolerance ? kept : seam_slot;
      }
    });
  }
  // The pending spheres against the other half's points they can reach: the
  // nearest one (in a k-d tree of those within reach of the split) outside
  // the sphere by a margin, so is every other.
  for (int h = 0; h < 2; ++h) {
    const Delaunay3& other = half[1 - h];
    const double depth = beyond[h] * (1 + 1e-6) + tolerance;
    std::vector<Vec3d> slab;
    for (const Vec3d& p : other.points_)
      if (std::abs(p[0] - split) <= depth) slab.push_back(p);
    if (slab.empty()) slab.push_back(other.points_[0]);
    const spatial::KdTree<double, 3> tree(spatial::PointView<double>(slab[0].data(), slab.size(), 3));
    parallel_for(0, valid[h].size(), 1 << 12, [&](std::size_t begin, std::size_t end) {
      for (std::size_t s = begin; s < end; ++s) {
        if (valid[h][s] != pending) continue;
        const Sphere b = *sphere(half[h], &half[h].tets_[8 * s]);
        const spatial::Neighbor<double> q = tree.query(b.centre, 1).front();
        valid[h][s] = std::sqrt(q.squared_distance) > b.reach * (1 + 1e-6) ? kept : seam_slot;
      }
    });
  }
  // The seam: every vertex of a doubtful slot; its own tetrahedralization.
  std::vector<std::uint32_t> seam;
  for (int h = 0; h < 2; ++h) {
    const std::vector<std::uint32_t> more =
        gather_slots<std::uint32_t>(valid[h].size(), [&](std::size_t s, std::vector<std::uint32_t>& out) {
          const std::uint32_t* v = &half[h].tets_[8 * s];
          if (v[0] == kNone || valid[h][s]) return;
          for (int k = 0; k < 4; ++k)
            if (v[k] != kGhost) out.push_back(vertex_global[h][v[k]]);
        });
    seam.insert(seam.end(), more.begin(), more.end());
  }
  std::sort(seam.begin(), seam.end());
  seam.erase(std::unique(seam.begin(), seam.end()), seam.end());
  if (seam.empty()) return false;
  // The assembled slots: half 0's at their own numbers, in place, then half
  // 1's, then the fill; the seam's slots are left free (the canonical order
  // drops them). The seam's own tetrahedralization (one thread) while the
  // other collects the seam's boundary and makes room for half 1.
  Delaunay3 filler;
  filler.options_ = options_;
  filler.points_.resize(seam.size());
  for (std::size_t k = 0; k < seam.size(); ++k) filler.points_[k] = points_[seam[k]];
  const std::array<std::size_t, 2> base = {0, valid[0].size()};  // per half: its slots' first new number
  RegionFill seam_fill;  // its boundary: the face and the adjacency across it (new numbers)
  const auto to_global = [&](int h, std::uint32_t v) { return v == kGhost ? kGhost : vertex_global[h][v]; };
  const auto collect_boundary = [&] {
    // The seam region's boundary: kept slots' faces towards doubtful ones, seen from the seam's side.
    using BoundaryFace = std::pair<RegionFill::Face, std::uint32_t>;
    for (int h = 0; h < 2; ++h) {
      const std::vector<BoundaryFace> faces =
          gather_slots<BoundaryFace>(valid[h].size(), [&](std::size_t s, std::vector<BoundaryFace>& out) {
            if (!valid[h][s]) return;
            for (std::uint32_t f = 0; f < 4; ++f) {
              const std::uint32_t a = half[h].tets_[8 * s + 4 + f], u = a >> 2;
              if (valid[h][u]) continue;
              std::uint32_t w[4];
              for (int k = 0; k < 4; ++k) w[k] = to_global(h, half[h].tets_[8 * std::size_t(u) + k]);
              out.push_back({RegionFill::face_of(w, int(a & 3)), std::uint32_t(4 * (base[h] + s) + f)});
            }
          });
      seam_fill.boundary.insert(seam_fill.boundary.end(), faces.begin(), faces.end());
    }
    tets_ = std::move(half[0].tets_);
    tets_.resize(8 * (base[1] + valid[1].size()));
  };
  parallel_for_each_index(
      0, 2,
      [&](std::size_t task) {
        if (task == 0) {
          filler.build(options_, false);
        } else {
          collect_boundary();
        }
      },
      1);
  if (filler.dimension_ < 3) return false;

  // Nothing kept next to the seam (a small or flat half), or a face unmatched (not expected): build sequentially.
  if (!seam_fill.match(filler.tets_, seam)) return false;
  std::size_t next = base[1] + valid[1].size();
  for (const std::uint32_t s : seam_fill.fill) seam_fill.slot[s] = std::uint32_t(next++);
  tets_.resize(8 * next);

  // Assemble: kept slots with their vertices global and their adjacencies
  // renumbered (towards the seam: the fill's), the others free; then the fill.
  for (int h = 0; h < 2; ++h)
    parallel_for(0, valid[h].size(), 1 << 14, [&](std::size_t begin, std::size_t end) {
      const std::uint32_t* from = h == 0 ? tets_.data() : half[1].tets_.data();
      for (std::size_t s = begin; s < end; ++s) {
        std::uint32_t* to = &tets_[8 * (base[h] + s)];
        if (!valid[h][s]) {
          std::fill_n(to, 4, kNone);
          continue;
        }
        for (int k = 0; k < 4; ++k) {
          const std::uint32_t a = from[8 * s + 4 + k];
          to[k] = to_global(h, from[8 * s + k]);
          if (valid[h][a >> 2]) to[4 + k] = std::uint32_t(4 * base[h]) + a;
        }
      }
    });
  seam_fill.write(tets_);
  storage = std::move(half[1].tets_);
  free = 0;  // (slots left free: the halves' free and seam slots)
  for (int h = 0; h < 2; ++h) free += std::size_t(std::count(valid[h].begin(), valid[h].end(), seam_slot));
  // Representatives: equal points fall in the same half, whose first occurrence is the first here too.
  for (int h = 0; h < 2; ++h)
    for (std::size_t k = 0; k < global[h].size(); ++k) rep_[global[h][k]] = global[h][half[h].rep_[k]];
  dimension_ = 3;
  walk_steps_ = half[0].walk_steps_ + half[1].walk_steps_ + filler.walk_steps_;
  conflicts_ = half[0].conflicts_ + half[1].conflicts_ + filler.conflicts_;
  seam_points_ = seam.size();
  for (std::size_t k = 0; k < flip_counts_.size(); ++k)
    flip_counts_[k] = half[0].flip_counts_[k] + half[1].flip_counts_[k] + filler.flip_counts_[k];
  last_ = seam_fill.slot[seam_fill.fill.front()];
  return true;
}

}  // namespace geods::voronoi
