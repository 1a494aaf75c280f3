// The exhaustive scan: slab by slab in z, with the trimmed row ranges of
// flying edges (Schroeder et al. 2015) so that only the cells next to a side
// change are looked at, and the vertex ids of two planes kept in flat arrays.
#include "geods/iso/marching_cubes.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "../core/prefault.hpp"
#include "cell.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/huge_page_array.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/progress.hpp"

namespace geods::iso {
namespace {

// The range of x edges of one row where the side changes: samples [0, xl] are
// all on the side of sample 0 and samples [xr, nx) on the side of sample nx-1;
// a row on one side only has xl = nx, xr = 0.
struct RowTrim {
  std::uint32_t xl, xr;
  bool uniform() const { return xl > xr; }
};

// Which of the five id arrays (x edges of planes k and k+1, y edges of planes
// k and k+1, z edges of the layer) holds cube edge e, and its offset from the
// cell's (i, j) entry.
constexpr std::uint8_t kEdgeArray[12] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4, 4};

// The arrays a slab scan works in and appends its output to, used by one slab
// at a time and kept for the next: the vertex ids of two planes and a layer, the
// row trims of two planes, and the vertices and triangles of all its slabs. As
// many as slabs run at once, so that the output arrays grow large enough for
// the huge-page allocator, which keeps freed blocks for the next call: a fresh
// 4 KiB page costs microseconds to fault in on a virtual machine (docs/iso.md).
struct ScanArrays {
  template <class U>
  using Buffer = std::vector<U, HugePageAllocator<U>>;
  HugePageArray<std::uint32_t> ids;  // x edges of planes k and k+1, y edges of both, z edges of layer k
  std::vector<RowTrim> trims[2];
  Buffer<Vec3f> positions, normals, centre_positions, centre_normals;
  Buffer<TriMesh::Triangle> triangles;
};

// Hands out ScanArrays, creating one when all are in use.
class ScanArraysPool {
 public:
  ScanArrays* take() {
    const std::lock_guard lock(mutex_);
    if (free_.empty()) return all_.emplace_back(std::make_unique<ScanArrays>()).get();
    ScanArrays* a = free_.back();
    free_.pop_back();
    return a;
  }
  void give_back(ScanArrays* a) {
    const std::lock_guard lock(mutex_);
    free_.push_back(a);
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<ScanArrays>> all_;
  std::vector<ScanArrays*> free_;
};

template <typename T>
class SlabScan {
 public:
  SlabScan(const Grid3View<T>& g, double iso, const IsoOptions& options, bool flip, ScanArrays& arrays)
      : arrays(arrays), first_vertex(arrays.positions.size()), first_centre(arrays.centre_positions.size()),
        first_triangle(arrays.triangles.size()), g_(g), iso_(iso), thr_(iso),
        placer_(g, iso, options.positions, options.normals), flip_(flip), table_(detail::case_table_view()),
        nx_(g.dims[0]), ny_(g.dims[1]) {
    // Left uninitialized: an id is read only for a crossed edge, which was written first.
    const std::size_t plane = nx_ * ny_;
    if (!arrays.ids) {
      arrays.ids = make_huge_page_array<std::uint32_t>(5 * plane, /*touched=*/false);
      // Room for a surface that crosses the volume about twice (two vertices, four
      // triangles per column), up to 8 MiB an array: for a large volume, a kept
      // block from the start.
      const std::size_t most = 4 * geods::detail::kHugePage / 12;  // 12 bytes: a vertex or a triangle
      arrays.positions.reserve(std::min(2 * plane, most));
      if (options.normals) arrays.normals.reserve(std::min(2 * plane, most));
      arrays.triangles.reserve(std::min(4 * plane, most));
    }
    xid_[0] = arrays.ids.get(), xid_[1] = xid_[0] + plane, yid_[0] = xid_[1] + plane, yid_[1] = yid_[0] + plane;
    zid_ = yid_[1] + plane;
    for (auto& t : arrays.trims) t.resize(ny_);
    const std::ptrdiff_t nx = std::ptrdiff_t(nx_);
    const std::ptrdiff_t delta[12] = {0, nx, 0, nx, 0, 1, 0, 1, 0, 1, nx, nx + 1};
    std::copy(delta, delta + 12, edge_delta_);
  }

  // Triangle corners with this bit refer to centre vertices.
  static constexpr std::uint32_t kCentreFlag = 0x80000000u;

  // The slab's output is what it appended to its arrays: edge vertices from
  // first_vertex on, centre vertices (apart, so that the top plane stays last)
  // from first_centre on, triangles from first_triangle on, their corners
  // counted from first_vertex or, with kCentreFlag, from first_centre. Of the
  // edge vertices, the bottom plane's x/y edges come first (bottom_count of
  // them), the top plane's x/y edges last (from top_begin on, also counted from
  // first_vertex).
  ScanArrays& arrays;
  const std::size_t first_vertex, first_centre, first_triangle;
  std::size_t end_vertex = 0, end_centre = 0, end_triangle = 0;
  std::size_t bottom_count = 0, top_begin = 0;
  std::size_t cells_visited = 0;

  void run(std::size_t k0, std::size_t k1) {
    compute_trims(k0);
    create_xy_vertices(k0);
    bottom_count = arrays.positions.size() - first_vertex;
    for (std::size_t k = k0; k < k1; ++k) {
      compute_trims(k + 1);
      create_z_vertices(k);
      top_begin = arrays.positions.size() - first_vertex;
      create_xy_vertices(k + 1);
      march_layer(k);
    }
    end_vertex = arrays.positions.size(), end_centre = arrays.centre_positions.size();
    end_triangle = arrays.triangles.size();
  }

 private:
  bool inside(std::size_t i) const { return thr_.inside(g_.data[i]); }
  const T* row(std::size_t j, std::size_t k) const { return g_.data.data() + g_.index(0, j, k); }
  std::vector<RowTrim>& trims(std::size_t k) { return arrays.trims[k & 1]; }

  void compute_trims(std::size_t k) {
    std::vector<RowTrim>& out = trims(k);
    const std::size_t nx = nx_;
    for (std::size_t j = 0; j < ny_; ++j) {
      const T* r = row(j, k);
      const std::size_t count = thr_.count_inside(r, nx);
      if (count == 0 || count == nx) {
        out[j] = {std::uint32_t(nx), 0};
        continue;
      }
      const bool first = thr_.inside(r[0]), last = thr_.inside(r[nx - 1]);
      std::size_t xl = 0, xr = nx - 1;
      while (thr_.inside(r[xl + 1]) == first) ++xl;
      while (thr_.inside(r[xr - 1]) == last) --xr;
      out[j] = {std::uint32_t(xl), std::uint32_t(xr)};
    }
  }

  // Samples [a, b] of two rows outside of which the two rows keep their sides
  // and agree; false if they agree everywhere.
  template <std::size_t N>
  bool active_range(const T* const (&rows)[N], const RowTrim* const (&trim)[N], std::size_t& a,
                    std::size_t& b) const {
    std::size_t lo = nx_, hi = 0;
    for (std::size_t r = 0; r < N; ++r) lo = std::min<std::size_t>(lo, trim[r]->xl), hi = std::max<std::size_t>(hi, trim[r]->xr);
    auto differ_at = [&](std::size_t x) {
      const bool s = thr_.inside(rows[0][x]);
      for (std::size_t r = 1; r < N; ++r)
        if (thr_.inside(rows[r][x]) != s) return true;
      return false;
    };
    if (lo > hi) {  // every row on one side
      if (!differ_at(0)) return false;
      a = 0, b = nx_ - 1;
      return true;
    }
    a = differ_at(lo) ? 0 : lo;
    b = differ_at(hi) ? nx_ - 1 : hi;
    return true;
  }

  void create_xy_vertices(std::size_t k) {
    std::uint32_t* xid = xid_[k & 1];
    std::uint32_t* yid = yid_[k & 1];
    const std::vector<RowTrim>& t = trims(k);
    for (std::size_t j = 0; j < ny_; ++j) {
      if (t[j].uniform()) continue;
      const T* r = row(j, k);
      for (std::size_t i = t[j].xl; i < t[j].xr; ++i)
        if (thr_.inside(r[i]) != thr_.inside(r[i + 1])) xid[j * nx_ + i] = add_vertex(i, j, k, 0);
    }
    for (std::size_t j = 0; j + 1 < ny_; ++j) {
      const T* const rows[2] = {row(j, k), row(j + 1, k)};
      const RowTrim* const rt[2] = {&t[j], &t[j + 1]};
      std::size_t a, b;
      if (!active_range(rows, rt, a, b)) continue;
      for (std::size_t i = a; i <= b; ++i)
        if (thr_.inside(rows[0][i]) != thr_.inside(rows[1][i])) yid[j * nx_ + i] = add_vertex(i, j, k, 1);
    }
  }

  void create_z_vertices(std::size_t k) {
    const std::vector<RowTrim>& t0 = trims(k);
    const std::vector<RowTrim>& t1 = trims(k + 1);
    for (std::size_t j = 0; j < ny_; ++j) {
      const T* const rows[2] = {row(j, k), row(j, k + 1)};
      const RowTrim* const rt[2] = {&t0[j], &t1[j]};
      std::size_t a, b;
      if (!active_range(rows, rt, a, b)) continue;
      for (std::size_t i = a; i <= b; ++i)
        if (thr_.inside(rows[0][i]) != thr_.inside(rows[1][i])) zid_[j * nx_ + i] = add_vertex(i, j, k, 2);
    }
  }

  std::uint32_t add_vertex(std::size_t i, std::size_t j, std::size_t k, int axis) {
    const std::size_t id = arrays.positions.size() - first_vertex;
    if (id >= std::size_t(kCentreFlag)) throw Error("isosurface: more than 2^32 - 1 vertices");
    placer_.place(i, j, k, axis, arrays.positions, arrays.normals);
    return std::uint32_t(id);
  }

  void march_layer(std::size_t k) {
    const std::vector<RowTrim>& t0 = trims(k);
    const std::vector<RowTrim>& t1 = trims(k + 1);
    const std::uint32_t* id_arrays[5] = {xid_[k & 1], xid_[(k + 1) & 1], yid_[k & 1], yid_[(k + 1) & 1], zid_};
    for (std::size_t j = 0; j + 1 < ny_; ++j) {
      // Corner bit c = x + 2y + 4z: rows (y, z) = (0,0), (1,0), (0,1), (1,1).
      const T* const rows[4] = {row(j, k), row(j + 1, k), row(j, k + 1), row(j + 1, k + 1)};
      const RowTrim* const rt[4] = {&t0[j], &t0[j + 1], &t1[j], &t1[j + 1]};
      std::size_t a, b;
      if (!active_range(rows, rt, a, b)) continue;
      cells_visited += b - a;
      auto column = [&](std::size_t x) {
        return unsigned(thr_.inside(rows[0][x])) | unsigned(thr_.inside(rows[1][x])) << 2 |
               unsigned(thr_.inside(rows[2][x])) << 4 | unsigned(thr_.inside(rows[3][x])) << 6;
      };
      unsigned left = column(a);
      for (std::size_t i = a; i < b; ++i) {
        const unsigned right = column(i + 1);
        const unsigned c = left | right << 1;
        left = right;
        if (c == 0 || c == 255) continue;
        std::uint8_t joined = 0;
        if (const std::uint8_t amb = table_.ambiguous[c]) {
          joined = detail::decide_faces(amb, iso_, [&](int corner) {
            return rows[corner >> 1][i + (corner & 1)];
          });
        }
        const std::size_t entry = std::size_t(c) * 64 + joined;
        const std::ptrdiff_t base = std::ptrdiff_t(j * nx_ + i);
        std::uint32_t ids[12 + kMaxCentres];
        for (unsigned crossed = detail::kCrossedEdges[c]; crossed != 0; crossed &= crossed - 1) {
          const int e = std::countr_zero(crossed);
          ids[e] = id_arrays[kEdgeArray[e]][base + edge_delta_[e]];
        }
        for (std::size_t n = 0; n < kMaxCentres && table_.centres[entry * kMaxCentres + n] != 0; ++n) {
          ids[12 + n] = kCentreFlag | std::uint32_t(arrays.centre_positions.size() - first_centre);
          Vec3f position, normal;
          detail::centre_vertex(table_.centres[entry * kMaxCentres + n], ids, arrays.positions.data() + first_vertex,
                                placer_.normals() ? arrays.normals.data() + first_vertex : nullptr, position, normal);
          arrays.centre_positions.push_back(position);
          if (placer_.normals()) arrays.centre_normals.push_back(normal);
        }
        const std::uint8_t* e = table_.edges + table_.offsets[entry];
        const std::uint8_t* end = table_.edges + table_.offsets[entry + 1];
        for (; e != end; e += 3)
          arrays.triangles.push_back(flip_ ? TriMesh::Triangle{ids[e[0]], ids[e[2]], ids[e[1]]}
                                           : TriMesh::Triangle{ids[e[0]], ids[e[1]], ids[e[2]]});
      }
    }
  }

  Grid3View<T> g_;
  double iso_;
  detail::Threshold<T> thr_;
  detail::VertexPlacer<T> placer_;
  bool flip_;
  detail::CaseTableView table_;
  std::size_t nx_, ny_;
  std::ptrdiff_t edge_delta_[12];
  std::uint32_t *xid_[2], *yid_[2], *zid_;  // in arrays.ids
};

// 0, ..., n-1 in bit-reversed order (0, 4, 2, 6, 1, 5, 3, 7 for 8). tbb gives
// a thread half of a range first and splits it in halves again: taken in this
// order, every such part spans the whole height of the volume, so that the
// slabs of a surface that fills only some layers are shared out, not left to one.
std::vector<std::size_t> bit_reversed_order(std::size_t n) {
  const int bits = std::bit_width(n - 1);
  std::vector<std::size_t> order;
  order.reserve(n);
  for (std::size_t i = 0; i < std::size_t(1) << bits; ++i) {
    std::size_t r = 0;
    for (int b = 0; b < bits; ++b) r |= (i >> b & 1) << (bits - 1 - b);
    if (r < n) order.push_back(r);
  }
  return order;
}

}  // namespace

template <typename T>
TriMesh isosurface(const Grid3View<T>& volume, double iso, const IsoOptions& options, std::size_t* cells_visited) {
  if (cells_visited) *cells_visited = 0;
  const detail::Threshold<T> check_iso(iso);  // throws for a non-finite iso-value
  detail::check_positions(volume, options.positions);
  TriMesh mesh;
  const std::size_t nz = volume.dims[2];
  if (volume.dims[0] < 2 || volume.dims[1] < 2 || nz < 2) {
    detail::check_samples(volume);
    Progress(options.progress, "isosurface", 1).finish();
    return mesh;
  }
  const bool flip = detail::mirrored(volume, options.positions);
  const std::size_t layers = nz - 1;
  // Several slabs per thread for balance, but not so thin that the plane
  // each slab recomputes at its bottom costs much. With a progress callback,
  // at least 32 slabs, run a thread's worth at a time between the reports.
  const std::size_t threads = std::size_t(num_threads());
  std::size_t slabs = threads == 1 ? 1 : std::min(layers, 4 * threads);
  if (options.progress) slabs = std::max(slabs, std::min<std::size_t>(layers, 32));
  const std::size_t batch = options.progress ? threads : slabs;
  Progress progress(options.progress, "isosurface", double(slabs));
  ScanArraysPool pool;
  std::vector<std::unique_ptr<SlabScan<T>>> scans(slabs);
  const std::vector<std::size_t> order = bit_reversed_order(slabs);
  for (std::size_t first = 0; first < slabs; first += batch) {
    const std::size_t last = std::min(slabs, first + batch);
    parallel_for_each_index(first, last, [&](std::size_t i) {
      const std::size_t s = order[i];
      ScanArrays* arrays = pool.take();
      scans[s] = std::make_unique<SlabScan<T>>(volume, iso, options, flip, *arrays);
      scans[s]->run(layers * s / slabs, layers * (s + 1) / slabs);
      pool.give_back(arrays);
    }, 1);
    progress.update(double(last));
  }

  // Slab s's top plane is slab s+1's bottom plane, made in the same order:
  // keep the latter, so that the result equals one slab over everything.
  // Edge vertices of all slabs first, then the centre vertices of all slabs.
  // A single slab is copied out as well: the mesh's arrays are plain std::vectors.
  std::vector<std::size_t> base(slabs + 1, 0), centre_base(slabs + 1, 0);
  for (std::size_t s = 0; s < slabs; ++s) {
    const SlabScan<T>& scan = *scans[s];
    const bool last = s + 1 == slabs;
    const std::size_t count = scan.end_vertex - scan.first_vertex;
    if (!last && count - scan.top_begin != scans[s + 1]->bottom_count)
      throw Error("isosurface: internal error: slab planes disagree");
    base[s + 1] = base[s] + (last ? count : scan.top_begin);
  }
  centre_base[0] = base[slabs];
  for (std::size_t s = 0; s < slabs; ++s)
    centre_base[s + 1] = centre_base[s] + (scans[s]->end_centre - scans[s]->first_centre);
  const std::size_t vertices = centre_base[slabs];
  if (vertices >= std::size_t(UINT32_MAX)) throw Error("isosurface: more than 2^32 - 1 vertices");
  if (cells_visited)
    for (const auto& scan : scans) *cells_visited += scan->cells_visited;
  std::vector<std::size_t> tri_base(slabs + 1, 0);
  for (std::size_t s = 0; s < slabs; ++s)
    tri_base[s + 1] = tri_base[s] + (scans[s]->end_triangle - scans[s]->first_triangle);
  // Mapped by all threads at once (the fresh pages of a first call cost microseconds each),
  // then sized: resize() writes the triangles on this thread.
  geods::detail::reserve_prefaulted_in_parallel(mesh.vertices, vertices);
  if (options.normals) geods::detail::reserve_prefaulted_in_parallel(mesh.normals, vertices);
  geods::detail::reserve_prefaulted_in_parallel(mesh.triangles, tri_base[slabs]);
  mesh.vertices.resize(vertices);
  if (options.normals) mesh.normals.resize(vertices);
  mesh.triangles.resize(tri_base[slabs]);
  parallel_for_each_index(0, slabs, [&](std::size_t s) {
    const SlabScan<T>& scan = *scans[s];
    const ScanArrays& from = scan.arrays;
    const std::size_t keep = base[s + 1] - base[s], centres_kept = centre_base[s + 1] - centre_base[s];
    std::copy_n(from.positions.data() + scan.first_vertex, keep, mesh.vertices.data() + base[s]);
    std::copy_n(from.centre_positions.data() + scan.first_centre, centres_kept, mesh.vertices.data() + centre_base[s]);
    if (options.normals) {
      std::copy_n(from.normals.data() + scan.first_vertex, keep, mesh.normals.data() + base[s]);
      std::copy_n(from.centre_normals.data() + scan.first_centre, centres_kept, mesh.normals.data() + centre_base[s]);
    }
    const std::uint32_t own = std::uint32_t(base[s]);
    const std::uint32_t centres = std::uint32_t(centre_base[s]);
    const std::uint32_t next = std::uint32_t(base[s + 1]);
    const std::uint32_t top = std::uint32_t(scan.top_begin);
    const bool last = s + 1 == slabs;
    TriMesh::Triangle* out = mesh.triangles.data() + tri_base[s];
    for (std::size_t n = scan.first_triangle; n < scan.end_triangle; ++n) {
      const TriMesh::Triangle& t = from.triangles[n];
      TriMesh::Triangle r;
      for (int c = 0; c < 3; ++c) {
        if (t[c] & SlabScan<T>::kCentreFlag) r[c] = centres + (t[c] & ~SlabScan<T>::kCentreFlag);
        else r[c] = (last || t[c] < top) ? own + t[c] : next + (t[c] - top);
      }
      *out++ = r;
    }
  }, 1);
  progress.finish();
  return mesh;
}

template TriMesh isosurface(const Grid3View<std::uint8_t>&, double, const IsoOptions&, std::size_t*);
template TriMesh isosurface(const Grid3View<std::uint16_t>&, double, const IsoOptions&, std::size_t*);
template TriMesh isosurface(const Grid3View<std::int16_t>&, double, const IsoOptions&, std::size_t*);
template TriMesh isosurface(const Grid3View<float>&, double, const IsoOptions&, std::size_t*);
template TriMesh isosurface(const Grid3View<double>&, double, const IsoOptions&, std::size_t*);

}  // namespace geods::iso
