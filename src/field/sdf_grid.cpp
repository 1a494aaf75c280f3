#include "geods/field/sdf_grid.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "geods/bvh/traversal.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::field {
namespace {

constexpr std::size_t kTile = 8;   // samples along a tile's side
constexpr std::size_t kBlock = 4;  // samples along a block's side (within a tile)
constexpr float kInf = std::numeric_limits<float>::infinity();

using bvh::BvhTriangle;

// A box of samples [lo, hi) of the grid, its 8 corners (sample positions) and centre.
struct SampleBox {
  std::array<std::size_t, 3> lo, hi;
  std::array<Vec3f, 8> corners;
  Vec3f centre;
  float radius;  // half the diagonal

  SampleBox(const Grid3Geometry& grid, std::array<std::size_t, 3> l, std::array<std::size_t, 3> h) : lo(l), hi(h) {
    const Vec3f a = grid.position(lo[0], lo[1], lo[2]), b = grid.position(hi[0] - 1, hi[1] - 1, hi[2] - 1);
    for (int k = 0; k < 8; ++k) corners[k] = Vec3f(k & 1 ? b.x() : a.x(), k & 2 ? b.y() : a.y(), k & 4 ? b.z() : a.z());
    centre = 0.5f * (a + b);
    radius = 0.5f * (b - a).norm();
  }
  std::size_t samples() const { return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
};

// The closest face of a list to a point.
struct Closest {
  float d2 = kInf;
  std::uint32_t leaf = kNoIndex;  // leaf-order index
  std::uint32_t slot = 0;                    // position in the list
  TriangleRegion region = TriangleRegion::face;
  Vec3f point = Vec3f::Zero();
};

class GridSolver {
 public:
  GridSolver(const MeshDistance& mesh, const Grid3Geometry& grid, const SdfGridOptions& options)
      : mesh_(mesh), grid_(grid), options_(options), tris_(mesh.triangles().data()),
        ids_(mesh.bvh().triangle_ids().data()) {
    const std::size_t n = mesh.triangles().size();
    spheres_.resize(n);
    parallel_for_each_index(0, n, [&](std::size_t i) {
      const BvhTriangle& t = tris_[i];
      const Vec3f c = (t.a + t.b + t.c) / 3.0f;
      const float r = std::sqrt(std::max({(t.a - c).squaredNorm(), (t.b - c).squaredNorm(), (t.c - c).squaredNorm()}));
      spheres_[i] = Vec4f(c.x(), c.y(), c.z(), r * (1 + 1e-6f) + 1e-30f);
    });
    // Float rounding of distances is below this (relative to the scene's size).
    const AABB3f mb = std::visit([](const auto& v) { return bvh::bounds(v[0]); }, mesh.bvh().volumes());
    const AABB3f gb = grid.bounds();
    const float scale = std::max({mb.lo.cwiseAbs().maxCoeff(), mb.hi.cwiseAbs().maxCoeff(), gb.lo.cwiseAbs().maxCoeff(),
                                  gb.hi.cwiseAbs().maxCoeff(), 1e-30f});
    margin_ = 1e-6f * scale;
    const float h = grid.spacing.minCoeff();
    band_ = std::isfinite(options.band) ? float(options.band) * h : kInf;
  }

  // One tile: the samples of [lo, hi) into out (and faces).
  void tile(const SampleBox& box, float* out, std::uint32_t* faces, SdfGridStats& stats) const {
    const MeshPointDistance centre = mesh_.query(box.centre, SignMethod::none);
    const std::size_t nx = box.hi[0] - box.lo[0], ny = box.hi[1] - box.lo[1], nz = box.hi[2] - box.lo[2];
    std::array<float, kTile * kTile * kTile> ud;  // unsigned distances (inf: outside the band)
    std::array<Closest, kTile * kTile * kTile> best;
    ud.fill(kInf);
    const auto local = [&](std::size_t i, std::size_t j, std::size_t k) {
      return (i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - box.lo[2]));
    };
    if (!(centre.distance - box.radius > band_ + margin_)) {
      std::vector<std::uint32_t> tile_list, block_list;
      gather(box, centre.closest, tile_list);
      for (std::size_t bz = box.lo[2]; bz < box.hi[2]; bz += kBlock)
        for (std::size_t by = box.lo[1]; by < box.hi[1]; by += kBlock)
          for (std::size_t bx = box.lo[0]; bx < box.hi[0]; bx += kBlock) {
            const SampleBox block(grid_, {bx, by, bz},
                                  {std::min(bx + kBlock, box.hi[0]), std::min(by + kBlock, box.hi[1]),
                                   std::min(bz + kBlock, box.hi[2])});
            const Closest c = closest_in(tile_list, block.centre, 0);
            if (std::sqrt(c.d2) - block.radius > band_ + margin_) continue;
            filter(tile_list, block, c.point, block_list);
            stats.candidates_per_sample += double(block_list.size()) * double(block.samples());
            std::uint32_t seed = 0;  // the previous sample's closest face
            for (std::size_t k = block.lo[2]; k < block.hi[2]; ++k)
              for (std::size_t j = block.lo[1]; j < block.hi[1]; ++j)
                for (std::size_t i = block.lo[0]; i < block.hi[0]; ++i) {
                  const Closest s = closest_in(block_list, grid_.position(i, j, k), seed);
                  seed = s.slot;
                  const float d = std::sqrt(s.d2);
                  if (d > band_) continue;
                  ud[local(i, j, k)] = d;
                  best[local(i, j, k)] = s;
                  ++stats.in_band;
                }
          }
    } else {
      ++stats.tiles_outside;
    }

    // Signs, in scan order, each from an earlier neighbour in the tile when no surface can lie between them.
    const bool propagate = options_.sign == SignMethod::none || mesh_.closed();
    std::array<std::uint8_t, kTile * kTile * kTile> inside{};
    const float hx = grid_.spacing.x(), hy = grid_.spacing.y(), hz = grid_.spacing.z();
    for (std::size_t k = box.lo[2]; k < box.hi[2]; ++k)
      for (std::size_t j = box.lo[1]; j < box.hi[1]; ++j)
        for (std::size_t i = box.lo[0]; i < box.hi[0]; ++i) {
          const std::size_t l = local(i, j, k), g = grid_.index(i, j, k);
          const float d = ud[l];
          const Closest& c = best[l];
          if (faces) faces[g] = d < kInf ? ids_[c.leaf] : kNoIndex;
          bool in = false;
          const auto apart = [&](std::size_t n, float h) { return d + ud[n] > h * (1 + 1e-5f) + 2 * margin_; };
          if (options_.sign == SignMethod::none) {
          } else if (options_.sign == SignMethod::pseudonormal && d < kInf) {
            const std::uint32_t face = ids_[c.leaf];
            in = (grid_.position(i, j, k) - c.point).dot(mesh_.pseudonormal(face, c.region)) < 0;
          } else if (propagate && i > box.lo[0] && apart(l - 1, hx)) {
            in = inside[l - 1];
          } else if (propagate && j > box.lo[1] && apart(l - nx, hy)) {
            in = inside[l - nx];
          } else if (propagate && k > box.lo[2] && apart(l - nx * ny, hz)) {
            in = inside[l - nx * ny];
          } else {
            const Vec3f p = grid_.position(i, j, k);
            if (options_.sign == SignMethod::winding) {
              in = mesh_.winding_number(p) > 0.5;
              ++stats.winding_numbers;
            } else {
              in = mesh_.inside_by_pseudonormal(p, mesh_.query(p, SignMethod::none));
            }
          }
          inside[l] = in;
          out[g] = in ? -d : d;
        }
    (void)nz;
  }

 private:
  // Whether leaf triangle t may be closest to a point of the box whose corners
  // are each at most sqrt(bound2[k]) from the surface point the bounds come from.
  bool may_be_closest(std::uint32_t t, const std::array<Vec3f, 8>& corners, const std::array<float, 8>& bound2) const {
    const Vec4f& s = spheres_[t];
    const BvhTriangle& tri = tris_[t];
    for (int k = 0; k < 8; ++k) {
      const float lb = (corners[k] - s.head<3>()).norm() - s.w();
      if (lb > 0 && lb * lb > bound2[k]) continue;
      if ((closest_point_on_triangle(corners[k], tri.a, tri.b, tri.c) - corners[k]).squaredNorm() <= bound2[k])
        return true;
    }
    return false;
  }

  std::array<float, 8> bounds_from(const SampleBox& box, const Vec3f& q) const {
    std::array<float, 8> bound2;
    for (int k = 0; k < 8; ++k) {
      const float b = (box.corners[k] - q).norm() * (1 + 1e-5f) + margin_;
      bound2[k] = b * b;
    }
    return bound2;
  }

  // The faces that may be closest to a sample of the box, q being a surface point.
  void gather(const SampleBox& box, const Vec3f& q, std::vector<std::uint32_t>& out) const {
    out.clear();
    const std::array<float, 8> bound2 = bounds_from(box, q);
    const bvh::Topology& topo = mesh_.bvh().topology();
    std::visit(
        [&](const auto& volumes) {
          bvh::TraversalStack<bvh::NodeRef> stack(
              bvh::traversal_stack_size(topo.depth(), mesh_.bvh().options().arity));
          bvh::traverse_topology<false>(
              topo, 0, stack,
              [&](std::uint32_t node, float&) {
                for (int k = 0; k < 8; ++k)
                  if (bvh::squared_distance(volumes[node], box.corners[k]) <= bound2[k]) return true;
                return false;
              },
              [&](const bvh::TopoNode& node) {
                for (std::uint32_t i = node.prim_first; i < node.prim_first + node.prim_count; ++i)
                  if (may_be_closest(i, box.corners, bound2)) out.push_back(i);
              },
              [](float) { return true; });
        },
        mesh_.bvh().volumes());
  }

  void filter(const std::vector<std::uint32_t>& in, const SampleBox& box, const Vec3f& q,
              std::vector<std::uint32_t>& out) const {
    out.clear();
    const std::array<float, 8> bound2 = bounds_from(box, q);
    for (const std::uint32_t t : in)
      if (may_be_closest(t, box.corners, bound2)) out.push_back(t);
  }

  // The closest face of `list` to p (ties: the smallest face index), starting
  // from list[seed]: a face whose bounding sphere is farther than the best
  // distance so far is skipped.
  Closest closest_in(const std::vector<std::uint32_t>& list, const Vec3f& p, std::uint32_t seed) const {
    Closest best;
    if (list.empty()) return best;
    const auto test = [&](std::uint32_t slot) {
      const std::uint32_t t = list[slot];
      const BvhTriangle& tri = tris_[t];
      TriangleRegion region;
      const Vec3f q = closest_point_on_triangle(p, tri.a, tri.b, tri.c, region);
      const float d2 = (q - p).squaredNorm();
      if (d2 < best.d2 || (d2 == best.d2 && (best.leaf == kNoIndex || ids_[t] < ids_[best.leaf])))
        best = {d2, t, slot, region, q};
    };
    test(seed < list.size() ? seed : 0);
    float reach = std::sqrt(best.d2);
    for (std::uint32_t slot = 0; slot < list.size(); ++slot) {
      const Vec4f& s = spheres_[list[slot]];
      const float r = reach + s.w();
      if ((p - s.head<3>()).squaredNorm() > r * r) continue;
      const float before = best.d2;
      test(slot);
      if (best.d2 != before) reach = std::sqrt(best.d2);
    }
    return best;
  }

  const MeshDistance& mesh_;
  const Grid3Geometry& grid_;
  const SdfGridOptions& options_;
  const BvhTriangle* tris_;
  const std::uint32_t* ids_;
  std::vector<Vec4f> spheres_;  // per leaf triangle: centroid and radius
  float margin_ = 0;
  float band_ = kInf;
};

}  // namespace

Grid3Geometry sdf_grid_geometry(const AABB3f& box, std::size_t res, double spacing, double padding) {
  if (box.empty() || !box.lo.allFinite() || !box.hi.allFinite())
    throw Error("sdf grid: the box to sample is empty or not finite");
  if (!std::isfinite(padding) || padding < 0) throw Error(fmt::format("sdf grid: padding must be >= 0, got {}", padding));
  const Vec3d ext = (box.hi - box.lo).cast<double>();
  const double longest = ext.maxCoeff();
  double h = spacing;
  if (spacing == 0) {
    if (double(res) <= 2 * padding)
      throw Error(fmt::format("sdf grid: {} samples leave nothing inside a padding of {} on each side", res, padding));
    if (!(longest > 0)) throw Error("sdf grid: the box has no extent; give a spacing instead of a resolution");
    h = longest / (double(res) - 2 * padding);
  }
  if (!std::isfinite(h) || !(h > 0)) throw Error(fmt::format("sdf grid: spacing must be finite and > 0, got {}", h));
  Grid3Geometry g;
  const Vec3d centre = 0.5 * (box.lo + box.hi).cast<double>();
  double samples = 1;
  for (int a = 0; a < 3; ++a) {
    const double n = std::max(1.0, std::ceil((ext[a] + 2 * padding * h) / h - 1e-6));
    if (n > double(1u << 30)) throw Error(fmt::format("sdf grid: {} samples along an axis is too many", n));
    samples *= n;
    g.dims[a] = std::size_t(n);
    g.origin[a] = float(centre[a] - 0.5 * n * h + 0.5 * h);
  }
  if (samples > double(std::size_t(1) << 40))
    throw Error(fmt::format("sdf grid: {} samples is too many", samples));
  g.spacing = Vec3f::Constant(float(h));
  return g;
}

SdfGrid sdf_grid(const MeshDistance& mesh, const Grid3Geometry& grid, const SdfGridOptions& options) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(grid.spacing[a]) || !(grid.spacing[a] > 0))
      throw Error(fmt::format("sdf grid: spacing must be finite and > 0, got {} along {}", grid.spacing[a], char('x' + a)));
    if (!std::isfinite(grid.origin[a])) throw Error("sdf grid: the origin is not finite");
  }
  if (std::isnan(options.band) || !(options.band >= 0))
    throw Error(fmt::format("sdf grid: the band must be >= 0 samples, got {}", options.band));
  if (!grid.bounds().hi.allFinite()) throw Error("sdf grid: the grid reaches beyond float range");
  const std::size_t n = Grid3<float>::checked_size(grid.dims[0], grid.dims[1], grid.dims[2]);
  // Refuse before allocating what the machine cannot hold.
  const double bytes = double(n) * (options.faces ? 8.0 : 4.0);
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (memory > 0 && bytes > memory)
    throw Error(fmt::format("sdf grid: {} x {} x {} samples need {:.1f} GB, more than this machine's {:.1f} GB",
                            grid.dims[0], grid.dims[1], grid.dims[2], bytes / 1e9, memory / 1e9));

  SdfGrid result;
  static_cast<Grid3Geometry&>(result.distance) = grid;
  result.distance.data.resize(n);
  if (options.faces) result.faces.resize(n);
  result.stats.samples = n;
  if (n == 0) return result;
  const GridSolver solver(mesh, grid, options);
  std::array<std::size_t, 3> tiles;
  for (int a = 0; a < 3; ++a) tiles[a] = (grid.dims[a] + kTile - 1) / kTile;
  const std::size_t num_tiles = tiles[0] * tiles[1] * tiles[2];
  result.stats.tiles = num_tiles;
  std::atomic<std::size_t> in_band{0}, outside{0}, windings{0};
  std::atomic<std::uint64_t> candidates{0};
  parallel_for_each_index(
      0, num_tiles,
      [&](std::size_t t) {
        const std::array<std::size_t, 3> c{t % tiles[0], t / tiles[0] % tiles[1], t / (tiles[0] * tiles[1])};
        std::array<std::size_t, 3> lo, hi;
        for (int a = 0; a < 3; ++a) lo[a] = c[a] * kTile, hi[a] = std::min(lo[a] + kTile, grid.dims[a]);
        SdfGridStats s;
        solver.tile(SampleBox(grid, lo, hi), result.distance.data.data(), options.faces ? result.faces.data() : nullptr,
                    s);
        in_band += s.in_band;
        outside += s.tiles_outside;
        windings += s.winding_numbers;
        candidates += std::uint64_t(s.candidates_per_sample);
      },
      1);
  result.stats.in_band = in_band;
  result.stats.tiles_outside = outside;
  result.stats.winding_numbers = windings;
  result.stats.candidates_per_sample = in_band ? double(candidates) / double(in_band) : 0.0;
  return result;
}

SdfGrid sdf_grid(const TriMesh& mesh, const Grid3Geometry& grid, const SdfGridOptions& options) {
  return sdf_grid(MeshDistance::build(mesh), grid, options);
}

}  // namespace geods::field
