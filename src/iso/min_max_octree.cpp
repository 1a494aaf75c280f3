// Min/max octree: build, validation, and extraction by recursive descent with
// the edge-vertex hash table of seed §2.4.
#include "geods/iso/min_max_octree.hpp"

#include <algorithm>
#include <bit>
#include <memory>
#include <string>

#include "../core/prefault.hpp"
#include "cell.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/progress.hpp"

namespace geods::iso {

VertexSharing parse_vertex_sharing(std::string_view name) {
  if (name == "block_masks" || name == "blocks") return VertexSharing::block_masks;
  if (name == "hash_table" || name == "hash") return VertexSharing::hash_table;
  throw Error("iso: sharing must be 'block_masks' or 'hash_table', not '" + std::string(name) + "'");
}

std::string_view to_string(VertexSharing sharing) {
  return sharing == VertexSharing::hash_table ? "hash_table" : "block_masks";
}
namespace {

// Open addressing with linear probing and backward-shift deletion, keyed by
// grid edge (3 * sample index + axis).
class EdgeTable {
 public:
  struct Slot {
    std::uint64_t key;
    std::uint32_t vertex;
    std::uint8_t visits, needed;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);

  EdgeTable() { rehash(1024); }

  std::size_t size() const { return size_; }

  // The slot of key, or nullptr.
  Slot* find(std::uint64_t key) {
    for (std::size_t i = home(key);; i = (i + 1) & mask_) {
      if (slots_[i].key == key) return &slots_[i];
      if (slots_[i].key == kEmpty) return nullptr;
    }
  }

  void insert(const Slot& slot) {
    if (2 * (size_ + 1) > slots_.size()) rehash(2 * slots_.size());
    std::size_t i = home(slot.key);
    while (slots_[i].key != kEmpty) i = (i + 1) & mask_;
    slots_[i] = slot;
    ++size_;
  }

  void erase(Slot* slot) {
    std::size_t i = std::size_t(slot - slots_.data());
    for (std::size_t j = (i + 1) & mask_; slots_[j].key != kEmpty; j = (j + 1) & mask_) {
      const std::size_t h = home(slots_[j].key);
      // Move slot j back into the hole at i unless its home lies in (i, j].
      const bool stays = i <= j ? (h > i && h <= j) : (h > i || h <= j);
      if (!stays) slots_[i] = slots_[j], i = j;
    }
    slots_[i].key = kEmpty;
    --size_;
  }

 private:
  std::size_t home(std::uint64_t key) const { return std::size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }

  void rehash(std::size_t capacity) {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(capacity, Slot{kEmpty, 0, 0, 0});
    mask_ = capacity - 1;
    shift_ = 64 - std::countr_zero(capacity);
    size_ = 0;
    for (const Slot& s : old)
      if (s.key != kEmpty) insert(s);
  }

  std::vector<Slot> slots_;
  std::size_t mask_ = 0, size_ = 0;
  int shift_ = 0;
};


// Calls fn(i) for every i in [0, n) in parallel. With a progress callback
// (`batched`) the range runs in about 32 batches, and after each the calling
// thread reports done_before + (indices done) steps.
template <typename Fn>
void for_each_in_batches(std::size_t n, bool batched, Progress& progress, double done_before, std::size_t grain,
                         const Fn& fn) {
  const std::size_t batch = batched ? std::max<std::size_t>(1, (n + 31) / 32) : std::max<std::size_t>(n, 1);
  for (std::size_t first = 0; first < n; first += batch) {
    const std::size_t last = std::min(n, first + batch);
    parallel_for_each_index(first, last, fn, grain);
    progress.update(done_before + double(last));
  }
}

// What both extractions (hash-table and block-mask vertex sharing) start from:
// the tree and its volume, the iso-value and how a cell is cut at it.
template <typename Tree, typename T>
struct Extraction {
  const Tree& tree;
  Grid3View<T> volume;
  double iso;
  detail::Threshold<T> thr;
  detail::VertexPlacer<T> placer;
  bool flip;
  detail::CaseTableView table = detail::case_table_view();

  Extraction(const Tree& t, double iso_value, const IsoOptions& options, bool flip_triangles)
      : tree(t), volume(t.volume()), iso(iso_value), thr(iso_value),
        placer(volume, iso_value, options.positions, options.normals), flip(flip_triangles) {}
};

}  // namespace

// One extraction over one subtree (or the whole tree): its own hash table and output.
template <typename T>
struct MinMaxOctree<T>::Query : Extraction<MinMaxOctree<T>, T> {
  using Base = Extraction<MinMaxOctree<T>, T>;
  using Base::tree, Base::volume, Base::iso, Base::thr, Base::placer, Base::flip, Base::table;
  EdgeTable edges;
  std::vector<Vec3f> positions, normals;
  static constexpr std::uint64_t kNoEdge = EdgeTable::kEmpty;  // key of a cell-centre vertex
  std::vector<std::uint64_t> keys;  // the grid edge of each vertex
  std::vector<TriMesh::Triangle> triangles;
  std::size_t cells_visited = 0, nodes_visited = 0;

  Query(const MinMaxOctree& t, double iso_value, const IsoOptions& options, bool flip_triangles)
      : Base(t, iso_value, options, flip_triangles) {}

  bool active(std::size_t node) const { return thr.inside(tree.max_[node]) && !thr.inside(tree.min_[node]); }

  // Tests the existing children of node (level, x, y, z) and descends into the crossed ones.
  void descend(std::size_t level, std::size_t x, std::size_t y, std::size_t z) {
    if (level == 0) {
      march_leaf(x, y, z);
      return;
    }
    const auto& dims = tree.levels_[level - 1].dims;
    for (std::size_t dz = 0; dz < 2; ++dz)
      for (std::size_t dy = 0; dy < 2; ++dy)
        for (std::size_t dx = 0; dx < 2; ++dx) {
          const std::size_t cx = 2 * x + dx, cy = 2 * y + dy, cz = 2 * z + dz;
          if (cx >= dims[0] || cy >= dims[1] || cz >= dims[2]) continue;
          ++nodes_visited;
          if (active(tree.node_index(level - 1, cx, cy, cz))) descend(level - 1, cx, cy, cz);
        }
  }

  void march_leaf(std::size_t bx, std::size_t by, std::size_t bz) {
    const Grid3View<T>& g = volume;
    const std::size_t L = tree.leaf_cells_;
    const std::size_t x0 = bx * L, y0 = by * L, z0 = bz * L;
    const std::size_t x1 = std::min(x0 + L, tree.cells_[0]), y1 = std::min(y0 + L, tree.cells_[1]),
                      z1 = std::min(z0 + L, tree.cells_[2]);
    const std::size_t sy = g.dims[0], sz = g.dims[0] * g.dims[1];
    const std::size_t corner_offset[8] = {0, 1, sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1};
    cells_visited += (x1 - x0) * (y1 - y0) * (z1 - z0);
    for (std::size_t k = z0; k < z1; ++k)
      for (std::size_t j = y0; j < y1; ++j)
        for (std::size_t i = x0; i < x1; ++i) {
          const T* s = g.data.data() + g.index(i, j, k);
          unsigned c = 0;
          for (int q = 0; q < 8; ++q) c |= unsigned(thr.inside(s[corner_offset[q]])) << q;
          if (c == 0 || c == 255) continue;
          march_cell(i, j, k, c, s, corner_offset);
        }
  }

  void march_cell(std::size_t i, std::size_t j, std::size_t k, unsigned c, const T* s,
                  const std::size_t (&corner_offset)[8]) {
    std::uint8_t joined = 0;
    if (const std::uint8_t amb = table.ambiguous[c])
      joined = detail::decide_faces(amb, iso, [&](int q) { return s[corner_offset[q]]; });
    std::uint32_t ids[12 + kMaxCentres];
    for (unsigned crossed = detail::kCrossedEdges[c]; crossed != 0; crossed &= crossed - 1) {
      const int e = std::countr_zero(crossed);
      ids[e] = edge_vertex(i, j, k, e);
    }
    const std::size_t entry = std::size_t(c) * 64 + joined;
    for (std::size_t n = 0; n < kMaxCentres && table.centres[entry * kMaxCentres + n] != 0; ++n) {
      ids[12 + n] = std::uint32_t(positions.size());
      detail::place_centre(table.centres[entry * kMaxCentres + n], ids, positions, normals, positions, normals);
      keys.push_back(kNoEdge);
    }
    const std::uint8_t* e = table.edges + table.offsets[entry];
    const std::uint8_t* end = table.edges + table.offsets[entry + 1];
    for (; e != end; e += 3)
      triangles.push_back(flip ? TriMesh::Triangle{ids[e[0]], ids[e[2]], ids[e[1]]}
                               : TriMesh::Triangle{ids[e[0]], ids[e[1]], ids[e[2]]});
  }

  // The vertex on cube edge e of cell (i, j, k): from the table if an earlier
  // cell made it (removed at its last visit), else new.
  std::uint32_t edge_vertex(std::size_t i, std::size_t j, std::size_t k, int e) {
    const Grid3View<T>& g = volume;
    const int lo = detail::kEdgeCorners[e][0], axis = e / 4;
    const std::size_t p[3] = {i + (lo & 1), j + ((lo >> 1) & 1), k + ((lo >> 2) & 1)};
    const std::uint64_t key = 3 * std::uint64_t(g.index(p[0], p[1], p[2])) + std::uint64_t(axis);
    if (EdgeTable::Slot* slot = edges.find(key)) {
      const std::uint32_t v = slot->vertex;
      if (++slot->visits == slot->needed) edges.erase(slot);
      return v;
    }
    // Cells around the edge: along each other axis, the cells before and after it that exist.
    std::uint8_t needed = 1;
    for (int d = 0; d < 3; ++d)
      if (d != axis) needed = std::uint8_t(needed * ((p[d] > 0) + (p[d] + 1 < g.dims[d])));
    const std::size_t id = positions.size();
    if (id >= std::size_t(UINT32_MAX)) throw Error("isosurface: more than 2^32 - 1 vertices");
    placer.place(p[0], p[1], p[2], axis, positions, normals);
    keys.push_back(key);
    if (needed > 1) edges.insert({key, std::uint32_t(id), 1, needed});
    return std::uint32_t(id);
  }
};

template <typename T>
std::size_t MinMaxOctree<T>::make_levels() {
  levels_.clear();
  cells_ = {0, 0, 0};
  for (int d = 0; d < 3; ++d)
    if (grid_.dims[d] < 2) return 0;  // no cells
  for (int d = 0; d < 3; ++d) cells_[d] = grid_.dims[d] - 1;
  std::array<std::size_t, 3> dims;
  for (int d = 0; d < 3; ++d) dims[d] = (cells_[d] + leaf_cells_ - 1) / leaf_cells_;
  std::size_t total = 0;
  for (;;) {
    levels_.push_back({dims, total});
    total += dims[0] * dims[1] * dims[2];
    if (dims[0] == 1 && dims[1] == 1 && dims[2] == 1) break;
    for (int d = 0; d < 3; ++d) dims[d] = (dims[d] + 1) / 2;
  }
  return total;
}

template <typename T>
MinMaxOctree<T>::MinMaxOctree(Grid3<T> volume, std::size_t leaf_cells)
    : grid_(volume), samples_(std::move(volume.data)), leaf_cells_(leaf_cells) {
  if (leaf_cells_ == 0 || leaf_cells_ > kMaxLeafCells)
    throw Error("MinMaxOctree: leaf_cells must be in [1, " + std::to_string(kMaxLeafCells) + "], not " +
                std::to_string(leaf_cells_));
  const std::size_t total = make_levels();
  if (total == 0) {
    detail::check_samples(this->volume());
    return;
  }
  std::vector<T> min(total), max(total);
  const auto& leaves = levels_[0].dims;
  // The leaves cover every sample, so their pass also checks that all are finite (one pass over
  // the volume instead of two; check_samples then names the first bad sample).
  std::vector<char> non_finite(leaves[2], 0);
  parallel_for_each_index(0, leaves[2], [&](std::size_t z) {
    bool bad = false;
    for (std::size_t y = 0; y < leaves[1]; ++y)
      for (std::size_t x = 0; x < leaves[0]; ++x) {
        const std::array<T, 2> r = leaf_range(x, y, z, &bad);
        min[node_index(0, x, y, z)] = r[0];
        max[node_index(0, x, y, z)] = r[1];
      }
    non_finite[z] = bad;
  }, 1);
  if (std::find(non_finite.begin(), non_finite.end(), 1) != non_finite.end()) detail::check_samples(this->volume());
  for (std::size_t level = 1; level < levels_.size(); ++level) {
    const auto& d = levels_[level].dims;
    const auto& cd = levels_[level - 1].dims;
    parallel_for_each_index(0, d[2], [&](std::size_t z) {
      for (std::size_t y = 0; y < d[1]; ++y)
        for (std::size_t x = 0; x < d[0]; ++x) {
          const std::size_t first = node_index(level - 1, 2 * x, 2 * y, 2 * z);
          T lo = min[first], hi = max[first];
          for (std::size_t cz = 2 * z; cz < std::min(2 * z + 2, cd[2]); ++cz)
            for (std::size_t cy = 2 * y; cy < std::min(2 * y + 2, cd[1]); ++cy)
              for (std::size_t cx = 2 * x; cx < std::min(2 * x + 2, cd[0]); ++cx) {
                const std::size_t c = node_index(level - 1, cx, cy, cz);
                lo = std::min(lo, min[c]);
                hi = std::max(hi, max[c]);
              }
          min[node_index(level, x, y, z)] = lo;
          max[node_index(level, x, y, z)] = hi;
        }
    }, 1);
  }
  min_ = std::move(min);
  max_ = std::move(max);
}

template <typename T>
std::array<T, 2> MinMaxOctree<T>::leaf_range(std::size_t x, std::size_t y, std::size_t z, bool* non_finite) const {
  const std::size_t L = leaf_cells_;
  const std::size_t x0 = x * L, y0 = y * L, z0 = z * L;
  const std::size_t x1 = std::min(x0 + L, cells_[0]), y1 = std::min(y0 + L, cells_[1]),
                    z1 = std::min(z0 + L, cells_[2]);
  T lo = samples_[grid_.index(x0, y0, z0)], hi = lo;
  bool bad = false;
  for (std::size_t k = z0; k <= z1; ++k)
    for (std::size_t j = y0; j <= y1; ++j) {
      const T* row = samples_.data() + grid_.index(0, j, k);
      for (std::size_t i = x0; i <= x1; ++i) lo = std::min(lo, row[i]), hi = std::max(hi, row[i]);
      if constexpr (std::is_floating_point_v<T>)
        if (non_finite)
          for (std::size_t i = x0; i <= x1; ++i) bad |= (row[i] - row[i] != 0);  // NaN or infinite
    }
  if (non_finite) *non_finite |= bad;
  return {lo, hi};
}

template <typename T>
template <typename Threshold>
std::vector<typename MinMaxOctree<T>::SubtreeRoot> MinMaxOctree<T>::subtree_roots(const Threshold& thr,
                                                                                   std::size_t wanted,
                                                                                   std::size_t& nodes_visited) const {
  const std::size_t root = levels_.back().offset;
  ++nodes_visited;
  if (!(thr.inside(max_[root]) && !thr.inside(min_[root]))) return {};
  std::vector<SubtreeRoot> roots = {{levels_.size() - 1, 0, 0, 0}};
  // A crossed node always has a crossed child, so `roots` never runs empty.
  while (roots.size() < wanted && roots.front().level > 0) {
    std::vector<SubtreeRoot> next;
    for (const SubtreeRoot& n : roots) {
      const auto& dims = levels_[n.level - 1].dims;
      for (std::size_t dz = 0; dz < 2; ++dz)
        for (std::size_t dy = 0; dy < 2; ++dy)
          for (std::size_t dx = 0; dx < 2; ++dx) {
            const SubtreeRoot c{n.level - 1, 2 * n.x + dx, 2 * n.y + dy, 2 * n.z + dz};
            if (c.x >= dims[0] || c.y >= dims[1] || c.z >= dims[2]) continue;
            ++nodes_visited;
            const std::size_t i = node_index(c.level, c.x, c.y, c.z);
            if (thr.inside(max_[i]) && !thr.inside(min_[i])) next.push_back(c);
          }
    }
    roots = std::move(next);
  }
  return roots;
}

template <typename T>
OctreeIsoResult MinMaxOctree<T>::isosurface(double iso, const IsoOptions& options, VertexSharing sharing) const {
  const detail::Threshold<T> thr(iso);  // throws for a non-finite iso-value
  detail::check_positions(volume(), options.positions);
  if (levels_.empty()) {
    Progress(options.progress, "isosurface", 1).finish();
    return {};
  }
  const bool flip = detail::mirrored(volume(), options.positions);
  return sharing == VertexSharing::hash_table ? hash_table_isosurface(iso, options, flip)
                                              : block_isosurface(iso, options, flip);
}

template <typename T>
OctreeIsoResult MinMaxOctree<T>::hash_table_isosurface(double iso, const IsoOptions& options, bool flip) const {
  OctreeIsoResult result;
  // Subtree roots: enough for the threads, and with a progress callback enough
  // for about 32 batches between the reports.
  std::size_t wanted = num_threads() == 1 ? 1 : 8 * std::size_t(num_threads());
  if (options.progress) wanted = std::max<std::size_t>(wanted, 64);
  const std::vector<SubtreeRoot> roots = subtree_roots(detail::Threshold<T>(iso), wanted, result.nodes_visited);
  Progress progress(options.progress, "isosurface", double(roots.size()));

  std::vector<std::unique_ptr<Query>> queries(roots.size());
  for_each_in_batches(roots.size(), bool(options.progress), progress, 0, 1, [&](std::size_t r) {
    queries[r] = std::make_unique<Query>(*this, iso, options, flip);
    queries[r]->descend(roots[r].level, roots[r].x, roots[r].y, roots[r].z);
  });

  // Merge in traversal order: a vertex already made by an earlier subtree
  // (on a shared border) keeps its first id, as in the sequential descent.
  TriMesh& mesh = result.mesh;
  EdgeTable first_id;
  std::vector<std::uint32_t> remap;
  for (auto& q : queries) {
    result.cells_visited += q->cells_visited;
    result.nodes_visited += q->nodes_visited;
    remap.resize(q->positions.size());
    for (std::size_t v = 0; v < q->positions.size(); ++v) {
      if (queries.size() > 1 && q->keys[v] != Query::kNoEdge) {
        if (const EdgeTable::Slot* s = first_id.find(q->keys[v])) {
          remap[v] = s->vertex;
          continue;
        }
        first_id.insert({q->keys[v], std::uint32_t(mesh.vertices.size()), 0, 0});
      }
      remap[v] = std::uint32_t(mesh.vertices.size());
      mesh.vertices.push_back(q->positions[v]);
      if (options.normals) mesh.normals.push_back(q->normals[v]);
    }
    for (const TriMesh::Triangle& t : q->triangles) mesh.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
    q.reset();
  }
  progress.finish();
  return result;
}

// The block extraction (VertexSharing::block_masks) over the crossed leaves.
//
// Leaf b covers the cells [b * L, b * L + cells) along each axis and owns the
// samples [b * L, b * L + L), the last leaf also the last sample plane, and
// with them the grid edges that start at these samples. The owner of a crossed
// edge contains a cell around it, which is crossed, so the owner is a crossed
// leaf too. Bit ((axis * S + z) * S + y) * S + x (S = L + 1, local sample
// coordinates) of a leaf's masks is set for each crossed edge it owns; its
// vertices are numbered in bit order after those of the earlier leaves.
template <typename T>
struct MinMaxOctree<T>::BlockQuery : Extraction<MinMaxOctree<T>, T> {
  // One crossed leaf: its first cell and sample, cells and owned samples per axis.
  struct Box {
    std::size_t leaf_xyz[3];
    std::size_t origin[3];
    std::size_t cells[3], owned[3];
  };
  static constexpr std::uint32_t kUnknown = ~std::uint32_t(0);
  using Base = Extraction<MinMaxOctree<T>, T>;
  using Base::tree, Base::volume, Base::iso, Base::thr, Base::placer, Base::flip, Base::table;

  std::size_t L, S, words;
  std::array<std::size_t, 3> leaf_dims;
  std::size_t corner_offset[8];

  std::vector<std::uint32_t> leaves;        // crossed leaves (leaf-grid index), in descent order
  std::unique_ptr<std::uint32_t[]> slot;    // leaf-grid index -> place in `leaves`, set for crossed leaves only
  std::vector<std::uint64_t> masks;         // `words` per crossed leaf
  std::vector<std::uint32_t> ranks;         // per word: bits set in the leaf's earlier words
  std::vector<const std::uint32_t*> crossed_cells;  // per crossed leaf: its crossed cells (kept by pass 1)
  std::vector<std::uint32_t> crossed_count, centre_count;  // per crossed leaf
  std::vector<std::size_t> vertex_first;    // per crossed leaf: its edge vertices, then its centre vertices
  std::vector<std::size_t> triangle_first;

  BlockQuery(const MinMaxOctree& t, double iso_value, const IsoOptions& options, bool flip_triangles)
      : Base(t, iso_value, options, flip_triangles), L(t.leaf_cells_), S(t.leaf_cells_ + 1),
        words((3 * S * S * S + 63) / 64), leaf_dims(t.levels_[0].dims) {
    const std::size_t sy = volume.dims[0], sz = volume.dims[0] * volume.dims[1];
    const std::size_t offsets[8] = {0, 1, sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1};
    std::copy(offsets, offsets + 8, corner_offset);
  }

  void collect(std::size_t level, std::size_t x, std::size_t y, std::size_t z, std::vector<std::uint32_t>& out,
               std::size_t& nodes_visited) const {
    if (level == 0) {
      out.push_back(std::uint32_t(x + leaf_dims[0] * (y + leaf_dims[1] * z)));
      return;
    }
    const auto& dims = tree.levels_[level - 1].dims;
    for (std::size_t cz = 2 * z; cz < std::min(2 * z + 2, dims[2]); ++cz)
      for (std::size_t cy = 2 * y; cy < std::min(2 * y + 2, dims[1]); ++cy)
        for (std::size_t cx = 2 * x; cx < std::min(2 * x + 2, dims[0]); ++cx) {
          ++nodes_visited;
          const std::size_t n = tree.node_index(level - 1, cx, cy, cz);
          if (thr.inside(tree.max_[n]) && !thr.inside(tree.min_[n])) collect(level - 1, cx, cy, cz, out, nodes_visited);
        }
  }

  Box box(std::uint32_t leaf) const {
    Box b;
    b.leaf_xyz[0] = leaf % leaf_dims[0];
    b.leaf_xyz[1] = (leaf / leaf_dims[0]) % leaf_dims[1];
    b.leaf_xyz[2] = leaf / (leaf_dims[0] * leaf_dims[1]);
    for (int d = 0; d < 3; ++d) {
      b.origin[d] = b.leaf_xyz[d] * L;
      b.cells[d] = std::min(L, tree.cells_[d] - b.origin[d]);
      b.owned[d] = b.leaf_xyz[d] + 1 < leaf_dims[d] ? L : b.cells[d] + 1;
    }
    return b;
  }

  static std::uint64_t low_bits(std::size_t n) { return n >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1; }

  // rows[z * S + y], bit x: sample (x, y, z) of the box is inside.
  void inside_rows(const Box& b, std::uint64_t* rows) const {
    const Grid3View<T>& g = volume;
    for (std::size_t z = 0; z <= b.cells[2]; ++z)
      for (std::size_t y = 0; y <= b.cells[1]; ++y) {
        const T* r = g.data.data() + g.index(b.origin[0], b.origin[1] + y, b.origin[2] + z);
        std::uint64_t bits = 0;
        for (std::size_t x = 0; x <= b.cells[0]; ++x) bits |= std::uint64_t(thr.inside(r[x])) << x;
        rows[z * S + y] = bits;
      }
  }

  // fn(x, y, z, case) for every crossed cell of the box, in z, y, x order.
  template <typename Fn>
  void for_each_crossed_cell(const Box& b, const std::uint64_t* rows, const Fn& fn) const {
    const std::uint64_t cells_x = low_bits(b.cells[0]);
    for (std::size_t z = 0; z < b.cells[2]; ++z)
      for (std::size_t y = 0; y < b.cells[1]; ++y) {
        const std::uint64_t r00 = rows[z * S + y], r10 = rows[z * S + y + 1], r01 = rows[(z + 1) * S + y],
                            r11 = rows[(z + 1) * S + y + 1];
        const std::uint64_t any = r00 | r10 | r01 | r11, all = r00 & r10 & r01 & r11;
        for (std::uint64_t crossed = (any | any >> 1) & ~(all & all >> 1) & cells_x; crossed != 0;
             crossed &= crossed - 1) {
          const int x = std::countr_zero(crossed);
          const unsigned c = unsigned((r00 >> x) & 3) | unsigned((r10 >> x) & 3) << 2 | unsigned((r01 >> x) & 3) << 4 |
                             unsigned((r11 >> x) & 3) << 6;
          fn(std::size_t(x), y, z, c);
        }
      }
  }

  // The table entry of crossed cell (x, y, z) of the box with case c.
  std::size_t entry(const Box& b, std::size_t x, std::size_t y, std::size_t z, unsigned c) const {
    std::uint8_t joined = 0;
    if (const std::uint8_t amb = table.ambiguous[c]) {
      const T* s = volume.data.data() + volume.index(b.origin[0] + x, b.origin[1] + y, b.origin[2] + z);
      joined = detail::decide_faces(amb, iso, [&](int q) { return s[corner_offset[q]]; });
    }
    return std::size_t(c) * 64 + joined;
  }

  // Bits set in w, without the libgcc call std::popcount becomes when the
  // target has no popcnt instruction.
  static std::uint32_t bit_count(std::uint64_t w) {
    w = w - ((w >> 1) & 0x5555555555555555ull);
    w = (w & 0x3333333333333333ull) + ((w >> 2) & 0x3333333333333333ull);
    w = (w + (w >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return std::uint32_t((w * 0x0101010101010101ull) >> 56);
  }

  // The S bits of row (axis, y, z) of a leaf's masks.
  std::uint64_t row_bits(const std::uint64_t* w, std::size_t axis, std::size_t y, std::size_t z) const {
    const std::size_t bit = ((axis * S + z) * S + y) * S, word = bit >> 6, shift = bit & 63;
    std::uint64_t bits = w[word] >> shift;
    if (shift + S > 64) bits |= w[word + 1] << (64 - shift);
    return bits & low_bits(S);
  }

  // A crossed cell as stored by pass 1: table entry << 15 | z << 10 | y << 5 | x.
  static constexpr int kEntryShift = 15;

  // Pass 1 for crossed leaf s: its edge masks, its crossed cells and counts; returns its cells.
  std::size_t count(std::size_t s, std::size_t& triangles, std::vector<std::uint32_t>& cells) {
    const Box b = box(leaves[s]);
    std::uint64_t rows[(kMaxLeafCells + 1) * (kMaxLeafCells + 1)];
    inside_rows(b, rows);
    std::uint64_t* w = masks.data() + s * words;
    std::fill(w, w + words, std::uint64_t(0));
    auto put = [&](std::size_t axis, std::size_t y, std::size_t z, std::uint64_t bits) {
      if (bits == 0) return;
      const std::size_t bit = ((axis * S + z) * S + y) * S, word = bit >> 6, shift = bit & 63;
      w[word] |= bits << shift;
      if (shift + S > 64) w[word + 1] |= bits >> (64 - shift);
    };
    const std::uint64_t owned_x = low_bits(b.owned[0]), cells_x = low_bits(b.cells[0]);
    for (std::size_t z = 0; z <= b.cells[2] && z < b.owned[2]; ++z)
      for (std::size_t y = 0; y <= b.cells[1] && y < b.owned[1]; ++y) {
        const std::uint64_t r = rows[z * S + y];
        put(0, y, z, (r ^ (r >> 1)) & cells_x);
        if (y < b.cells[1]) put(1, y, z, (r ^ rows[z * S + y + 1]) & owned_x);
        if (z < b.cells[2]) put(2, y, z, (r ^ rows[(z + 1) * S + y]) & owned_x);
      }
    std::uint32_t running = 0;
    for (std::size_t i = 0; i < words; ++i) {
      ranks[s * words + i] = running;
      running += bit_count(w[i]);
    }
    std::size_t centres = 0;
    triangles = 0;
    const std::size_t before = cells.size();
    for_each_crossed_cell(b, rows, [&](std::size_t x, std::size_t y, std::size_t z, unsigned c) {
      const std::size_t e = entry(b, x, y, z, c);
      triangles += (table.offsets[e + 1] - table.offsets[e]) / 3;
      for (std::size_t n = 0; n < kMaxCentres && table.centres[e * kMaxCentres + n] != 0; ++n) ++centres;
      cells.push_back(std::uint32_t(e << kEntryShift | z << 10 | y << 5 | x));
    });
    crossed_count[s] = std::uint32_t(cells.size() - before);
    centre_count[s] = std::uint32_t(centres);
    return b.cells[0] * b.cells[1] * b.cells[2];
  }

  // Appends the edge vertices owned by crossed leaf s, in bit order, then
  // room for its centre vertices.
  void place_edge_vertices(std::size_t s, std::vector<Vec3f>& positions, std::vector<Vec3f>& normals) const {
    const Box b = box(leaves[s]);
    const std::uint64_t* w = masks.data() + s * words;
    for (std::size_t axis = 0; axis < 3; ++axis)
      for (std::size_t z = 0; z < S; ++z)
        for (std::size_t y = 0; y < S; ++y)
          for (std::uint64_t bits = row_bits(w, axis, y, z); bits != 0; bits &= bits - 1)
            placer.place(b.origin[0] + std::size_t(std::countr_zero(bits)), b.origin[1] + y, b.origin[2] + z,
                         int(axis), positions, normals);
    positions.resize(positions.size() + centre_count[s]);
    if (placer.normals()) normals.resize(positions.size());
  }

  // Pass 2: the centre vertices and triangles of the crossed cells of leaf s.
  void march(std::size_t s, TriMesh& mesh) const {
    const Box b = box(leaves[s]);
    // The owner of an edge: this leaf or its neighbour +x, +y, +z (bits 0-2), looked up once.
    std::uint32_t owner[8];
    std::fill(owner, owner + 8, kUnknown);
    const std::size_t leaf = leaves[s];
    std::size_t centre = vertex_first[s + 1] - centre_count[s];
    TriMesh::Triangle* out = mesh.triangles.data() + triangle_first[s];
    const Vec3f* normals = placer.normals() ? mesh.normals.data() : nullptr;
    // The ids of the edges this leaf owns, by bit (only those bits are read).
    thread_local std::vector<std::uint32_t> own_ids;
    own_ids.resize(words * 64);
    std::uint32_t next_id = std::uint32_t(vertex_first[s]);
    for (std::size_t i = 0; i < words; ++i)
      for (std::uint64_t bits = masks[s * words + i]; bits != 0; bits &= bits - 1)
        own_ids[i * 64 + std::size_t(std::countr_zero(bits))] = next_id++;
    // Edge e of cell (x, y, z) has bit (z * S + y) * S + x + edge_bit[e] when this leaf owns it.
    std::size_t edge_bit[12];
    for (int edge = 0; edge < 12; ++edge) {
      const int lo = detail::kEdgeCorners[edge][0];
      edge_bit[edge] = ((std::size_t(edge >> 2) * S + std::size_t((lo >> 2) & 1)) * S + std::size_t((lo >> 1) & 1)) * S +
                       std::size_t(lo & 1);
    }
    // Cells at these coordinates (L - 1, or none in the last leaf) have edges owned by the next leaf.
    std::size_t last_cell[3];
    for (int d = 0; d < 3; ++d) last_cell[d] = b.leaf_xyz[d] + 1 < leaf_dims[d] ? L - 1 : L;
    const std::uint32_t* cells = crossed_cells[s];
    for (std::uint32_t i = 0; i < crossed_count[s]; ++i) {
      const std::size_t e = cells[i] >> kEntryShift, c = e >> 6;
      const std::size_t x = cells[i] & 31, y = (cells[i] >> 5) & 31, z = (cells[i] >> 10) & 31;
      const std::size_t cell_bit = (z * S + y) * S + x;
      const bool inner = x != last_cell[0] && y != last_cell[1] && z != last_cell[2];
      std::uint32_t ids[12 + kMaxCentres];
      for (unsigned crossed = detail::kCrossedEdges[c]; crossed != 0; crossed &= crossed - 1) {
        const int edge = std::countr_zero(crossed);
        const int lo = detail::kEdgeCorners[edge][0];
        std::size_t p[3] = {x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1)};
        unsigned neighbour = 0;
        if (!inner)
          for (int d = 0; d < 3; ++d)
            if (p[d] == L && b.leaf_xyz[d] + 1 < leaf_dims[d]) p[d] = 0, neighbour |= 1u << d;
        if (neighbour == 0) {
          ids[edge] = own_ids[cell_bit + edge_bit[edge]];
          continue;
        }
        if (owner[neighbour] == kUnknown)
          owner[neighbour] = slot[leaf + (neighbour & 1) + leaf_dims[0] * (((neighbour >> 1) & 1) +
                                                                           leaf_dims[1] * ((neighbour >> 2) & 1))];
        const std::size_t o = owner[neighbour];
        const std::size_t bit = ((std::size_t(edge >> 2) * S + p[2]) * S + p[1]) * S + p[0];
        const std::size_t word = o * words + (bit >> 6);
        ids[edge] = std::uint32_t(vertex_first[o] + ranks[word] +
                                  bit_count(masks[word] & ((std::uint64_t(1) << (bit & 63)) - 1)));
      }
      for (std::size_t n = 0; n < kMaxCentres && table.centres[e * kMaxCentres + n] != 0; ++n, ++centre) {
        ids[12 + n] = std::uint32_t(centre);
        Vec3f unused_normal;
        detail::centre_vertex(table.centres[e * kMaxCentres + n], ids, mesh.vertices.data(), normals,
                              mesh.vertices[centre], normals ? mesh.normals[centre] : unused_normal);
      }
      const std::uint8_t* t = table.edges + table.offsets[e];
      const std::uint8_t* end = table.edges + table.offsets[e + 1];
      for (; t != end; t += 3)
        *out++ = flip ? TriMesh::Triangle{ids[t[0]], ids[t[2]], ids[t[1]]}
                      : TriMesh::Triangle{ids[t[0]], ids[t[1]], ids[t[2]]};
    }
  }
};

template <typename T>
OctreeIsoResult MinMaxOctree<T>::block_isosurface(double iso, const IsoOptions& options, bool flip) const {
  const auto& dims = levels_[0].dims;
  if (dims[0] * dims[1] * dims[2] > std::size_t(UINT32_MAX))
    throw Error("isosurface: more than 2^32 - 1 octree leaves; use larger leaves or VertexSharing::hash_table");
  OctreeIsoResult result;
  BlockQuery q(*this, iso, options, flip);
  // The crossed leaves, subtree by subtree in parallel, in the order of the sequential descent.
  const std::size_t wanted = num_threads() == 1 ? 1 : 8 * std::size_t(num_threads());
  const std::vector<SubtreeRoot> roots = subtree_roots(q.thr, wanted, result.nodes_visited);
  std::vector<std::vector<std::uint32_t>> found(roots.size());
  std::vector<std::size_t> nodes(roots.size(), 0);
  parallel_for_each_index(0, roots.size(), [&](std::size_t r) {
    q.collect(roots[r].level, roots[r].x, roots[r].y, roots[r].z, found[r], nodes[r]);
  }, 1);
  for (std::size_t r = 0; r < roots.size(); ++r) {
    result.nodes_visited += nodes[r];
    q.leaves.insert(q.leaves.end(), found[r].begin(), found[r].end());
  }
  found.clear();
  const std::size_t n = q.leaves.size();
  if (n == 0) {
    Progress(options.progress, "isosurface", 1).finish();
    return result;
  }
  q.slot = std::make_unique_for_overwrite<std::uint32_t[]>(dims[0] * dims[1] * dims[2]);
  for (std::size_t s = 0; s < n; ++s) q.slot[q.leaves[s]] = std::uint32_t(s);
  q.masks.resize(n * q.words);
  q.ranks.resize(n * q.words);

  // Pass 1, over chunks of consecutive leaves: a leaf's masks, crossed cells
  // and counts, then its edge vertices while its samples are in cache, into
  // the chunk's arrays (with room for its centre vertices).
  const std::size_t threads = std::size_t(num_threads());
  const std::size_t chunks = std::min(n, std::max<std::size_t>(threads == 1 ? 1 : 8 * threads, options.progress ? 32 : 1));
  // Progress steps: the chunks of pass 1, then the leaves of pass 2.
  Progress progress(options.progress, "isosurface", double(chunks + n));
  struct Chunk {
    std::vector<Vec3f> positions, normals;
    std::vector<std::uint32_t> cells;  // the crossed cells of its leaves
  };
  std::vector<Chunk> chunk(chunks);
  q.crossed_cells.resize(n);
  q.crossed_count.resize(n);
  q.centre_count.resize(n);
  q.vertex_first.resize(n + 1);
  q.triangle_first.resize(n + 1);
  std::vector<std::size_t> triangles(n), cells(n);
  for_each_in_batches(chunks, bool(options.progress), progress, 0, 1, [&](std::size_t c) {
    const std::size_t first = n * c / chunks, last = n * (c + 1) / chunks;
    // Room for about L^2 vertices and cells per leaf, what a smooth surface through it has.
    chunk[c].positions.reserve((last - first) * leaf_cells_ * leaf_cells_);
    if (options.normals) chunk[c].normals.reserve((last - first) * leaf_cells_ * leaf_cells_);
    chunk[c].cells.reserve((last - first) * leaf_cells_ * leaf_cells_);
    for (std::size_t s = first; s < last; ++s) {
      cells[s] = q.count(s, triangles[s], chunk[c].cells);
      q.vertex_first[s] = chunk[c].positions.size();  // within the chunk for now
      q.place_edge_vertices(s, chunk[c].positions, chunk[c].normals);
    }
    const std::uint32_t* next = chunk[c].cells.data();
    for (std::size_t s = first; s < last; ++s) q.crossed_cells[s] = next, next += q.crossed_count[s];
  });
  std::vector<std::size_t> chunk_first(chunks + 1, 0);
  for (std::size_t c = 0; c < chunks; ++c) {
    chunk_first[c + 1] = chunk_first[c] + chunk[c].positions.size();
    for (std::size_t s = n * c / chunks; s < n * (c + 1) / chunks; ++s) q.vertex_first[s] += chunk_first[c];
  }
  q.vertex_first[n] = chunk_first[chunks];
  q.triangle_first[0] = 0;
  for (std::size_t s = 0; s < n; ++s) {
    q.triangle_first[s + 1] = q.triangle_first[s] + triangles[s];
    result.cells_visited += cells[s];
  }
  if (q.vertex_first[n] >= std::size_t(UINT32_MAX)) throw Error("isosurface: more than 2^32 - 1 vertices");

  // The chunks' vertices in order, then pass 2 (which averages some of them
  // into centre vertices) writes the centres and triangles in place.
  TriMesh& mesh = result.mesh;
  if (chunks == 1) {
    mesh.vertices = std::move(chunk[0].positions);
    mesh.normals = std::move(chunk[0].normals);
  } else {
    // Mapped by all threads at once, as the scan's output (marching_cubes.cpp).
    geods::detail::reserve_prefaulted_in_parallel(mesh.vertices, q.vertex_first[n]);
    if (options.normals) geods::detail::reserve_prefaulted_in_parallel(mesh.normals, q.vertex_first[n]);
    mesh.vertices.resize(q.vertex_first[n]);
    if (options.normals) mesh.normals.resize(q.vertex_first[n]);
    parallel_for_each_index(0, chunks, [&](std::size_t c) {
      std::copy(chunk[c].positions.begin(), chunk[c].positions.end(), mesh.vertices.begin() + std::ptrdiff_t(chunk_first[c]));
      std::copy(chunk[c].normals.begin(), chunk[c].normals.end(), mesh.normals.begin() + std::ptrdiff_t(chunk_first[c]));
    }, 1);
  }
  geods::detail::reserve_prefaulted_in_parallel(mesh.triangles, q.triangle_first[n]);
  mesh.triangles.resize(q.triangle_first[n]);
  for_each_in_batches(n, bool(options.progress), progress, double(chunks), 16, [&](std::size_t s) { q.march(s, mesh); });
  progress.finish();
  return result;
}

template <typename T>
MinMaxOctreeStats MinMaxOctree<T>::stats() const {
  MinMaxOctreeStats s;
  s.nodes = min_.size();
  s.levels = levels_.size();
  s.leaf_cells = leaf_cells_;
  s.cells = cells_[0] * cells_[1] * cells_[2];
  s.bytes = 2 * min_.size() * sizeof(T) + levels_.size() * sizeof(Level);
  return s;
}

template <typename T>
void MinMaxOctree<T>::validate() const {
  check_nodes(true);
}

template <typename T>
void MinMaxOctree<T>::check_nodes(bool leaves_against_samples) const {
  auto fail = [](std::size_t level, std::size_t x, std::size_t y, std::size_t z) {
    throw Error("MinMaxOctree: node (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) +
                ") of level " + std::to_string(level) + " has a wrong min/max");
  };
  if (!leaves_against_samples && !levels_.empty()) {
    const std::size_t leaves = levels_.size() > 1 ? levels_[1].offset : min_.size();
    for (std::size_t n = 0; n < leaves; ++n)
      if (!(min_[n] <= max_[n])) throw Error("MinMaxOctree: leaf " + std::to_string(n) + " has min > max");
  }
  for (std::size_t level = leaves_against_samples ? 0 : 1; level < levels_.size(); ++level) {
    const auto& d = levels_[level].dims;
    for (std::size_t z = 0; z < d[2]; ++z)
      for (std::size_t y = 0; y < d[1]; ++y)
        for (std::size_t x = 0; x < d[0]; ++x) {
          std::array<T, 2> want;
          if (level == 0) {
            want = leaf_range(x, y, z);
          } else {
            const auto& cd = levels_[level - 1].dims;
            want = {min_[node_index(level - 1, 2 * x, 2 * y, 2 * z)], max_[node_index(level - 1, 2 * x, 2 * y, 2 * z)]};
            for (std::size_t cz = 2 * z; cz < std::min(2 * z + 2, cd[2]); ++cz)
              for (std::size_t cy = 2 * y; cy < std::min(2 * y + 2, cd[1]); ++cy)
                for (std::size_t cx = 2 * x; cx < std::min(2 * x + 2, cd[0]); ++cx) {
                  want[0] = std::min(want[0], min_[node_index(level - 1, cx, cy, cz)]);
                  want[1] = std::max(want[1], max_[node_index(level - 1, cx, cy, cz)]);
                }
          }
          const std::size_t n = node_index(level, x, y, z);
          if (min_[n] != want[0] || max_[n] != want[1]) fail(level, x, y, z);
        }
  }
  const auto& root = levels_.empty() ? std::array<std::size_t, 3>{1, 1, 1} : levels_.back().dims;
  if (root[0] != 1 || root[1] != 1 || root[2] != 1) throw Error("MinMaxOctree: the top level is not a single root");
}

template <typename T>
void MinMaxOctree<T>::save(const std::filesystem::path& path) const {
  ArchiveWriter w(std::string(kMinMaxOctreeArchiveKind), kMinMaxOctreeArchiveVersion);
  w.add_dtype("scalar", dtype_of<T>());
  w.add_value("leaf_cells", std::uint64_t(leaf_cells_));
  const std::array<std::uint64_t, 3> dims{grid_.dims[0], grid_.dims[1], grid_.dims[2]};
  w.add("dims", std::span<const std::uint64_t>(dims));
  w.add("origin", std::span<const float>(grid_.origin.data(), 3));
  w.add("spacing", std::span<const float>(grid_.spacing.data(), 3));
  w.add("samples", samples_);
  w.add("min", min_);
  w.add("max", max_);
  w.write(path);
}

template <typename T>
MinMaxOctree<T> MinMaxOctree<T>::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kMinMaxOctreeArchiveKind, kMinMaxOctreeArchiveVersion, verify);
  a.require_dtype<T>("scalar", "min/max octree");
  MinMaxOctree tree;
  const std::uint64_t leaf_cells = a.value<std::uint64_t>("leaf_cells");
  if (leaf_cells == 0 || leaf_cells > kMaxLeafCells) throw a.error("bad leaf_cells " + std::to_string(leaf_cells));
  tree.leaf_cells_ = std::size_t(leaf_cells);
  const FlatArray<std::uint64_t> dims = a.array<std::uint64_t>("dims", 3);
  const FlatArray<float> origin = a.array<float>("origin", 3), spacing = a.array<float>("spacing", 3);
  FlatArray<T> samples = a.array<T>("samples");
  bool sized = false;
  try {
    sized = Grid3<T>::checked_size(dims[0], dims[1], dims[2]) == samples.size();
  } catch (const Error&) {  // dimensions that overflow
  }
  if (!sized) {
    throw a.error(std::to_string(samples.size()) + " samples for a volume of " + std::to_string(dims[0]) + " x " +
                  std::to_string(dims[1]) + " x " + std::to_string(dims[2]));
  }
  Grid3Geometry& g = tree.grid_;
  g.dims = {dims[0], dims[1], dims[2]};
  g.origin = Vec3f(origin[0], origin[1], origin[2]);
  g.spacing = Vec3f(spacing[0], spacing[1], spacing[2]);
  tree.samples_ = std::move(samples);
  const std::size_t nodes = tree.make_levels();
  tree.min_ = a.array<T>("min", nodes);
  tree.max_ = a.array<T>("max", nodes);
  try {
    detail::check_samples(tree.volume());
    tree.check_nodes(Archive::checks_everything(verify));
  } catch (const Error& e) {
    throw a.error(std::string("corrupted min/max octree: ") + e.what());
  }
  return tree;
}

DType read_min_max_octree_scalar(const std::filesystem::path& path) {
  return Archive::open(path, kMinMaxOctreeArchiveKind, kMinMaxOctreeArchiveVersion, Archive::Verify::structure_only)
      .dtype("scalar");
}

template class MinMaxOctree<std::uint8_t>;
template class MinMaxOctree<std::uint16_t>;
template class MinMaxOctree<std::int16_t>;
template class MinMaxOctree<float>;
template class MinMaxOctree<double>;

}  // namespace geods::iso
