#include "geods/ray/uniform_grid.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "mailbox.hpp"
#include "box_margin.hpp"
#include "geods/core/triangle_box.hpp"
#include "geods/core/triangle.hpp"

namespace geods::ray {

namespace {

// Cells per axis for about `cells` cubic cells over a box of extent e (see the header).
Vec3i grid_resolution(const Vec3f& e, double cells, std::uint32_t max_resolution) {
  std::array<bool, 3> flat = {false, false, false};
  Vec3i res = Vec3i::Ones();
  for (int round = 0; round < 3; ++round) {
    double volume = 1;
    int active = 0;
    for (int a = 0; a < 3; ++a)
      if (!flat[a]) volume *= double(e[a]), ++active;
    if (active == 0) break;
    const double side = std::pow(volume / std::max(cells, 1.0), 1.0 / active);
    bool changed = false;
    for (int a = 0; a < 3; ++a) {
      if (flat[a]) continue;
      const double n = double(e[a]) / side;
      if (n < 1) flat[a] = changed = true;
      res[a] = int(std::clamp(std::lround(n), 1L, long(std::max<std::uint32_t>(max_resolution, 1))));
    }
    if (!changed) break;
    for (int a = 0; a < 3; ++a)
      if (flat[a]) res[a] = 1;
  }
  return res;
}

}  // namespace

std::unique_ptr<UniformGrid> UniformGrid::build(const TriMesh& mesh, const AcceleratorOptions& options) {
  if (!(options.grid_density > 0) || !std::isfinite(options.grid_density))
    throw Error("uniform grid: grid_density must be a positive number");
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<UniformGrid> grid(new UniformGrid(mesh));
  UniformGrid& g = *grid;
  const std::size_t n = g.num_triangles();
  g.set_cells();
  g.resolution_ = grid_resolution(g.grid_bounds_.extent(),
                                  double(options.grid_density) * double(std::max<std::size_t>(n, 1)),
                                  options.grid_max_resolution);
  g.set_cells();
  const std::size_t cells = std::size_t(g.resolution_.prod());

  // The cells each triangle overlaps, gathered per fixed chunk of triangles so
  // that concatenating the chunks gives the same order for any thread count.
  constexpr std::size_t kChunk = 4096;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<std::array<std::uint32_t, 2>>> pairs(chunks);  // (cell, triangle)
  parallel_for_each_index(0, chunks, [&](std::size_t c) {
    auto& out = pairs[c];
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
      const Vec3f* corners = &g.corners_[3 * i];
      const AABB3f box = detail::widened(triangle_bounds(corners[0], corners[1], corners[2]), g.margin_);
      Vec3i lo, hi;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::clamp(int(std::floor((box.lo[a] - g.grid_bounds_.lo[a]) * g.inv_cell_size_[a])), 0,
                           g.resolution_[a] - 1);
        hi[a] = std::clamp(int(std::floor((box.hi[a] - g.grid_bounds_.lo[a]) * g.inv_cell_size_[a])), 0,
                           g.resolution_[a] - 1);
      }
      const bool single = lo == hi;
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            if (!single) {
              const Vec3f cell_lo = g.grid_bounds_.lo + Vec3f(float(x), float(y), float(z)).cwiseProduct(g.cell_size_);
              const AABB3f cell_box(cell_lo, cell_lo + g.cell_size_);
              if (!triangle_box_overlap(corners[0], corners[1], corners[2],
                                                 detail::widened(cell_box, g.margin_)))
                continue;
            }
            out.push_back({std::uint32_t(g.cell_index(x, y, z)), std::uint32_t(i)});
          }
    }
  }, 1);

  // Counting sort by cell; within a cell the triangles stay in increasing order.
  // Each thread takes a range of cells and reads every pair: the pairs are read
  // in order, the counts and cursors (the cache misses) are shared out.
  const std::size_t ranges = std::size_t(std::max(num_threads(), 1));
  auto by_cell_range = [&](auto&& visit) {
    parallel_for_each_index(0, ranges, [&](std::size_t r) {
      const std::size_t first = cells * r / ranges, last = cells * (r + 1) / ranges;
      for (const auto& chunk : pairs)
        for (const auto& [cell, tri] : chunk)
          if (cell >= first && cell < last) visit(cell, tri);
    }, 1);
  };
  std::vector<std::uint32_t> cell_begin(cells + 1, 0);
  by_cell_range([&](std::uint32_t cell, std::uint32_t) { ++cell_begin[cell + 1]; });
  std::partial_sum(cell_begin.begin(), cell_begin.end(), cell_begin.begin());
  if (cell_begin.back() >= RayHit::no_hit) throw Error("uniform grid: more than 2^32 triangle references");
  std::vector<std::uint32_t> cell_triangles(cell_begin.back());
  std::vector<std::uint32_t> cursor(cell_begin.begin(), cell_begin.end() - 1);
  by_cell_range([&](std::uint32_t cell, std::uint32_t tri) { cell_triangles[cursor[cell]++] = tri; });
  g.cell_begin_ = std::move(cell_begin);
  g.cell_triangles_ = std::move(cell_triangles);
  g.build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return grid;
}

void UniformGrid::set_cells() {
  grid_bounds_ = num_triangles() == 0 ? AABB3f(Vec3f::Zero(), Vec3f::Ones()) : detail::widened(bounds_, margin_);
  cell_size_ = grid_bounds_.extent().cwiseQuotient(resolution_.cast<float>());
  inv_cell_size_ = cell_size_.cwiseInverse();
}

void UniformGrid::save(const std::filesystem::path& path) const {
  ArchiveWriter out(kArchiveKind, kArchiveVersion);
  add_sections(out);
  out.add_value("resolution", resolution_);
  out.add("cell_begin", cell_begin_);
  out.add("cell_triangles", cell_triangles_);
  out.write(path);
}

std::unique_ptr<UniformGrid> UniformGrid::load(const std::filesystem::path& path) {
  const Archive in = Archive::open(path, kArchiveKind, kArchiveVersion);
  std::unique_ptr<UniformGrid> grid(new UniformGrid(in));
  UniformGrid& g = *grid;
  g.resolution_ = in.value<Vec3i>("resolution");
  g.cell_begin_ = in.array<std::uint32_t>("cell_begin");
  g.cell_triangles_ = in.array<std::uint32_t>("cell_triangles");
  // The cell count, without overflow, before validate() multiplies it out.
  std::uint64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    if (g.resolution_[a] < 1 || std::uint64_t(g.resolution_[a]) > g.cell_begin_.size())
      throw in.error(fmt::format("bad grid resolution {} x {} x {}", g.resolution_[0], g.resolution_[1],
                                 g.resolution_[2]));
    cells *= std::uint64_t(g.resolution_[a]);
    if (cells >= g.cell_begin_.size()) break;
  }
  if (cells + 1 != g.cell_begin_.size()) throw in.error("the cell offsets do not match the grid resolution");
  g.set_cells();
  in.check([&] { g.validate(); });
  return grid;
}

std::span<const std::uint32_t> UniformGrid::cell(int x, int y, int z) const {
  if (x < 0 || y < 0 || z < 0 || x >= resolution_[0] || y >= resolution_[1] || z >= resolution_[2])
    throw Error(fmt::format("uniform grid: cell ({}, {}, {}) out of range", x, y, z));
  const std::size_t c = cell_index(x, y, z);
  return {cell_triangles_.data() + cell_begin_[c], cell_begin_[c + 1] - cell_begin_[c]};
}

template <bool AnyHit>
std::uint32_t UniformGrid::traverse(const Ray3f& ray, RayHit& best) const {
  const Vec3f inv_dir = ray.direction.cwiseInverse();
  const auto [t0, t1] = ray_box_interval(ray, inv_dir, grid_bounds_);
  if (!(t0 <= t1)) return RayHit::no_hit;
  // Amanatides-Woo: the cell of the entry point, then for each axis the ray
  // parameter of the next cell boundary; step along the axis whose boundary is nearest.
  const Vec3f entry = ray.at(t0);
  Vec3i cell, step;
  Vec3f next_t;
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(int(std::floor((entry[a] - grid_bounds_.lo[a]) * inv_cell_size_[a])), 0,
                         resolution_[a] - 1);
    step[a] = ray.direction[a] > 0 ? 1 : (ray.direction[a] < 0 ? -1 : 0);
  }
  // The boundary parameter is computed from the boundary's coordinate each
  // time (not accumulated), so its error does not grow along the ray.
  auto boundary_t = [&](int a) {
    if (step[a] == 0) return std::numeric_limits<float>::infinity();
    const float x = grid_bounds_.lo[a] + float(cell[a] + (step[a] > 0)) * cell_size_[a];
    return (x - ray.origin[a]) * inv_dir[a];
  };
  for (int a = 0; a < 3; ++a) next_t[a] = boundary_t(a);

  const RayTriangleTest<float> test(ray);
  detail::Mailbox mailbox;
  for (;;) {
    const std::size_t c = cell_index(cell[0], cell[1], cell[2]);
    for (std::uint32_t k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
      const std::uint32_t prim = cell_triangles_[k];
      if (mailbox.seen(prim)) continue;
      if constexpr (AnyHit) {
        if (test_any(test, prim, ray.tmin, ray.tmax)) return prim;
      } else {
        test_closest(test, prim, ray.tmin, best);
      }
    }
    int axis = 0;
    if (next_t[1] < next_t[axis]) axis = 1;
    if (next_t[2] < next_t[axis]) axis = 2;
    const float exit_t = next_t[axis];
    // A hit before the cell's exit cannot be beaten by a triangle of a later cell
    // (for the any-hit case best.t is ray.tmax: nothing beyond it counts).
    if (best.t <= exit_t || exit_t > t1) break;
    cell[axis] += step[axis];
    if (cell[axis] < 0 || cell[axis] >= resolution_[axis]) break;
    next_t[axis] = boundary_t(axis);
  }
  return best.prim;
}

RayHit UniformGrid::closest_hit(const Ray3f& ray, RayCache&) const {
  RayHit best;
  best.t = ray.tmax;
  traverse<false>(ray, best);
  return best;
}

std::uint32_t UniformGrid::any_hit(const Ray3f& ray, RayCache&) const {
  RayHit bound;
  bound.t = ray.tmax;
  return traverse<true>(ray, bound);
}

AcceleratorStats UniformGrid::stats() const {
  AcceleratorStats s;
  s.kind = "grid";
  s.triangles = num_triangles();
  s.nodes = cell_begin_.size() - 1;
  for (std::size_t c = 0; c + 1 < cell_begin_.size(); ++c) s.leaves += cell_begin_[c + 1] > cell_begin_[c];
  s.references = cell_triangles_.size();
  s.bytes = (cell_begin_.size() + cell_triangles_.size()) * sizeof(std::uint32_t) + corners_.size() * sizeof(Vec3f);
  s.build_s = build_s_;
  for (int a = 0; a < 3; ++a) s.resolution[a] = std::uint32_t(resolution_[a]);
  return s;
}

void UniformGrid::validate() const {
  const std::size_t cells = std::size_t(resolution_.prod());
  if (cell_begin_.size() != cells + 1 || cell_begin_.front() != 0 || cell_begin_.back() != cell_triangles_.size())
    throw Error("uniform grid: cell offsets do not match the cell count");
  for (std::size_t c = 0; c < cells; ++c) {
    if (cell_begin_[c] > cell_begin_[c + 1]) throw Error(fmt::format("uniform grid: cell {} has a negative size", c));
    for (std::uint32_t k = cell_begin_[c]; k < cell_begin_[c + 1]; ++k) {
      if (cell_triangles_[k] >= num_triangles())
        throw Error(fmt::format("uniform grid: cell {} lists triangle {} of {}", c, cell_triangles_[k], num_triangles()));
      if (k > cell_begin_[c] && cell_triangles_[k - 1] >= cell_triangles_[k])
        throw Error(fmt::format("uniform grid: cell {} is not sorted", c));
    }
  }
  // Every triangle is listed in the cell of each of its corners (they lie on it).
  for (std::size_t i = 0; i < num_triangles(); ++i)
    for (int k = 0; k < 3; ++k) {
      const Vec3f& p = corners_[3 * i + k];
      Vec3i q;
      for (int a = 0; a < 3; ++a)
        q[a] = std::clamp(int(std::floor((p[a] - grid_bounds_.lo[a]) * inv_cell_size_[a])), 0, resolution_[a] - 1);
      const auto list = cell(q[0], q[1], q[2]);
      if (!std::binary_search(list.begin(), list.end(), std::uint32_t(i)))
        throw Error(fmt::format("uniform grid: triangle {} is missing from the cell of its corner {}", i, k));
    }
}

}  // namespace geods::ray
