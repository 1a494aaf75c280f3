#pragma once
// Adaptively sampled distance fields (seed §6.1, Figure 60; Frisken et al.
// 2000): the signed distance of a triangle mesh stored in an octree whose
// leaves hold the exact distances at their 8 corners; inside a leaf the field
// is their trilinear interpolation.
//
// Build (top-down, level by level): a cell is split into 8 while the
// trilinear interpolation of its corner distances differs by more than the
// error E from the exact field (MeshDistance, the same sign method) at any of
// its test points: the points of an n x n x n lattice over the cell other than
// its 8 corners (n = AdfOptions::checks, odd; n = 3 gives the 19 points of
// Frisken et al.: the 12 edge midpoints, the 6 face centres and the centre).
// The lattice of a split cell holds its children's corners, so each exact
// distance is computed once. The cells of a level are evaluated in parallel
// and stored in level order, so the tree does not depend on the thread count.
//
// The bound holds at the test points. Between them it is not a proof: a
// kink of the field (the medial axis, a sharp edge) can fall between test
// points and its error is then only seen partly (at least half of it along a
// lattice line). measure_adf_error reports what the bound is worth at random
// points (docs/field.md gives measured values for n = 3 and 5).
//
// Finite by two options: max_depth (cells at that depth are leaves whatever
// their error; they are counted as `unresolved`), and band: with a finite
// band B the ADF is the field clamped to [-B, B]: the error bound applies to
// the clamped values, |clamp(interpolation) - clamp(exact)| <= E at the test
// points, and distance() returns clamped values. The corners store the exact
// distance clamped to [-2B, 2B] (so the clamp's kink at B needs no
// refinement); a cell whose centre is farther than B + its half diagonal
// from the surface is one leaf without test points. Refinement thus happens
// only within about B of the surface.
//
// Storage: every byte counted in AdfStats::bytes. The tree is one bit a
// cell in level order (set: inner), with a rank table (the inner cells
// before each 64-bit word): the children of inner cell i are the 8 cells from
// 1 + 8 rank(i), so no pointers and no leaf indices. The corner values are
// stored once per distinct octree vertex (shared by the up to 8 leaves that
// meet there). A vertex that is the low corner (x, y, z least) of a leaf --
// every leaf has one, and it is that of no other leaf -- is stored at the
// leaf's rank among the leaves (i - rank(i)): no key. The others (a vertex
// in the middle of a larger leaf's low face or edge, or on the cube's high
// faces) follow in the order of their key x + (N + 1) (y + (N + 1) z) on the
// lattice of the finest cells (N = 2^depth), Elias-Fano coded: the low
// floor(log2(lattice / keyed)) bits of each key bit-packed, the rest in
// unary, with the position of every 128th zero kept for select. A leaf finds its corner c from its position:
// the leaf holding the corner (from the deepest ancestor that holds both,
// down) has the corner as its low corner, or the corner is keyed.
// The values are b-bit steps of [-R, R] (R bounds |distance| over the root
// cube) with the fewest bits b <= 16 whose step is at most E / 32, else
// floats; the build's test uses E less one step, so the stored ADF stays
// within E at the test points. Key parts and values are bit-packed.
// Across a level change (a T-junction) each leaf interpolates its own corners
// (exact samples, shared where leaves meet at a vertex): a coarse leaf's face
// does not pass through a finer neighbour's corner in its middle, so the field
// can jump there, by at most the two leaves' errors (2E at test points).
//
// Queries: distance (the trilinear interpolation in the leaf holding the
// point), gradient (that of the interpolation: piecewise, not continuous
// across cells), closest point (p - d g / |g|: on the ADF's zero set to first
// order, at distance |d| from p). Outside the root cube the distance is the
// one at the nearest point c of the cube plus |p - c|.
#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/field/mesh_distance.hpp"

namespace geods::field {

struct AdfOptions {
  /// Largest difference allowed between the interpolation and the exact
  /// field at a cell's test points (world units, > 0).
  double error = 0;
  /// Deepest level (root 0), at most kAdfMaxDepth.
  int max_depth = 10;
  /// Half-width of the band (world units): the ADF is the distance clamped
  /// to [-band, band] (see above). Infinity: the whole field.
  double band = std::numeric_limits<double>::infinity();
  /// Test points per cell: the checks^3 lattice less the corners (odd, 3 to 9).
  int checks = 3;
  /// The root cube: the mesh's bounding cube grown by padding x its largest extent on each side.
  double padding = 0.1;
  SignMethod sign = SignMethod::winding;
};

inline constexpr int kAdfMaxDepth = 20;

struct AdfStats {
  std::size_t cells = 0;          // octree cells (inner and leaves)
  std::size_t leaves = 0;         // cells holding 8 corner distances
  std::size_t depth = 0;          // deepest leaf's level
  std::size_t unresolved = 0;     // leaves at max_depth whose test points exceed the error
  std::size_t exact_queries = 0;  // exact distances computed by the build
  std::size_t signs = 0;          // of them, signs computed (the others: a neighbour's, see adf.cpp)
  std::size_t corners = 0;        // distinct leaf corners (octree vertices), each stored once: leaves + keyed ones
  std::size_t value_bits = 0;     // bits a quantized corner value (at most 16), or 32 (floats)
  std::size_t key_bits = 0;       // low bits of key stored a keyed corner (the rest in unary: about 2 bits)
  double quantum = 0;             // the quantization step (0 for floats): a corner is within half of it
  std::size_t bytes = 0;          // every array the ADF holds: tree bits, ranks, keys (high and low parts, select samples), values
  std::size_t dense_bytes = 0;    // a float grid of the finest leaves' spacing over the root cube: 4 (2^depth + 1)^3
};

/// The ADF's interpolation at a point, with its gradient.
struct AdfSample {
  float distance = 0;
  Vec3f gradient = Vec3f::Zero();
};

class Adf {
 public:
  Adf() = default;

  /// Builds the ADF of the mesh behind `mesh`. Throws geods::Error for a
  /// non-positive or non-finite error, a bad max_depth, checks, padding or
  /// band, and (before allocating it) a tree larger than the machine's memory.
  static Adf build(const TriMesh& source, const MeshDistance& mesh, const AdfOptions& options);
  /// The same, building the MeshDistance first (geods::Error for an empty or invalid mesh).
  static Adf build(const TriMesh& mesh, const AdfOptions& options);

  /// Distance at p (finite, else geods::Error), clamped to the band: see the header's comment.
  float distance(const Vec3f& p) const { return sample(p).distance; }
  Vec3f gradient(const Vec3f& p) const { return sample(p).gradient; }
  AdfSample sample(const Vec3f& p) const;
  /// p - d g / |g| (p itself where the gradient vanishes).
  Vec3f closest_point(const Vec3f& p) const;

  /// The surface {distance = offset} (|offset| < band) by marching cubes on
  /// the ADF sampled at res samples along each side of the root cube (0:
  /// 2^min(depth, 8) + 1), oriented outward. geods::Error for a non-finite
  /// offset, one outside the band, res < 2 or a grid the memory cannot hold.
  TriMesh isosurface(double offset, std::size_t res = 0) const;

  /// Calls f(level, lo, size, corners) for each leaf in level order: its
  /// cube's low corner, side and 8 corner distances (order x + 2y + 4z).
  template <typename F>
  void for_each_leaf(F&& f) const;

  void save(const std::filesystem::path& path) const;
  static Adf load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);
  /// Throws geods::Error unless the tree bits and keys are consistent
  /// (keys sorted, every leaf's corners present), values are finite (within
  /// twice the band) and the cube is finite.
  void validate() const;

  AdfStats stats() const { return stats_; }
  const AdfOptions& options() const { return options_; }
  /// The root cube: low corner and side.
  const Vec3d& origin() const { return origin_; }
  double size() const { return size_; }
  /// Cells in level order; cell i is inner (its 8 children from first_child(i), order x + 2y + 4z) or a leaf.
  std::size_t num_cells() const { return cells_; }
  bool is_inner(std::size_t i) const { return (inner_[i >> 6] >> (i & 63)) & 1; }
  std::size_t first_child(std::size_t i) const {
    const std::uint64_t below = inner_[i >> 6] & ((std::uint64_t(1) << (i & 63)) - 1);
    return 1 + 8 * (std::size_t(rank_[i >> 6]) + std::size_t(std::popcount(below)));
  }
  /// The tree bits (bit i of word i / 64: cell i is inner).
  const FlatArray<std::uint64_t>& inner_bits() const { return inner_; }
  /// The distinct corners' values (decoded), and their number: first the
  /// leaves' low corners in leaf order, then the keyed corners in key order.
  std::size_t num_corners() const { return corners_; }
  float corner_value(std::size_t i) const {
    return values32_.empty() ? float(value_lo_ + quantum_ * double(unpack(values_.data(), i, value_bits_))) : values32_[i];
  }
  /// Element i of an array of `bits`-bit fields packed in 64-bit words (and one word of padding).
  static std::uint64_t unpack(const std::uint64_t* words, std::size_t i, int bits) {
    const std::size_t at = i * std::size_t(bits), w = at >> 6, o = at & 63;
    std::uint64_t v = words[w] >> o;
    if (o + std::size_t(bits) > 64) v |= words[w + 1] << (64 - o);
    return bits >= 64 ? v : v & ((std::uint64_t(1) << bits) - 1);
  }
  /// The 8 corner values (x + 2y + 4z) of the cell at integer position (x, y, z) of `level`.
  void cell_corners(int level, std::uint64_t x, std::uint64_t y, std::uint64_t z, float out[8]) const;
  /// The index (for corner_value) of the vertex at (x, y, z) on the finest
  /// lattice, or kNoIndex if it is no stored vertex.
  std::size_t corner_index(std::uint64_t x, std::uint64_t y, std::uint64_t z) const;

 private:
  // Takes the build's tree (per node: kLeaf | leaf, or the first child) and 8 values a leaf.
  void store(const std::vector<std::uint32_t>& nodes, const std::vector<float>& values, int value_bits, double quantum,
             double lo);
  // Lays out the distinct corners (sorted keys with their quantized values,
  // or float values when value_bits_ is 32) over the tree in inner_.
  void lay_out(const std::vector<std::uint64_t>& keys, const std::vector<std::uint64_t>& fields,
               const std::vector<float>& floats);
  // The corners (x + 2y + 4z) of a leaf at `level` and (x, y, z), whose ancestors are path[0..level].
  void leaf_corners(const std::size_t* path, int level, std::uint64_t x, std::uint64_t y, std::uint64_t z,
                    float out[8]) const;
  // The index of finest-lattice vertex (x, y, z) from `node` at `level`, a cell holding it.
  std::size_t corner_below(std::size_t node, int level, std::uint64_t x, std::uint64_t y, std::uint64_t z) const;
  // Cell i's rank among the leaves: i less the inner cells before it.
  std::size_t leaf_rank(std::size_t i) const {
    const std::uint64_t below = inner_[i >> 6] & ((std::uint64_t(1) << (i & 63)) - 1);
    return i - std::size_t(rank_[i >> 6]) - std::size_t(std::popcount(below));
  }
  void finish_stats();
  void make_ranks();
  void make_selects();
  std::uint64_t select0(std::uint64_t r) const;
  // The keyed corner of `key` (its index among the keyed corners), or kNoIndex.
  std::size_t find_corner(std::uint64_t key) const;
  // Checks the keyed corners' structure, calling f(i, key) for each in order.
  template <typename F>
  void for_each_keyed(std::size_t count, std::uint64_t last, F&& f) const;

  AdfOptions options_;
  Vec3d origin_ = Vec3d::Zero();
  double size_ = 1;
  std::size_t cells_ = 0, corners_ = 0, leaves_ = 0;
  int depth_ = 0;             // the finest leaves' level: keys are on the (2^depth + 1)^3 lattice
  int shift_ = 0;             // the low shift bits of a keyed corner's key are stored, the rest in high_
  int value_bits_ = 32;       // bits a packed value, or 32: floats
  double value_lo_ = 0, quantum_ = 0;
  FlatArray<std::uint64_t> inner_;
  FlatArray<std::uint32_t> rank_;      // inner cells before each word of inner_ (computed on load)
  std::uint64_t high_bits_ = 0;        // keyed + (last key >> shift) + 1
  FlatArray<std::uint64_t> high_;      // Elias-Fano high parts: keyed corner i sets bit (key >> shift) + i
  FlatArray<std::uint32_t> select_;    // the position of every 128th zero of high_ (computed on load)
  FlatArray<std::uint64_t> keys_;      // the low shift bits of each keyed corner's key, packed
  FlatArray<std::uint64_t> values_;    // quantized values (value_bits_ each; leaves' low corners, then keyed), packed, or empty
  FlatArray<float> values32_;          // float values when the quantum would be too coarse
  AdfStats stats_;
};

/// The ADF's error against the exact (clamped) field at `samples` random
/// points (seeded): half uniform in the root cube, half near the surface (a
/// uniform point of a random face moved by up to 8 x the finest leaf side).
struct AdfError {
  double max_error = 0;
  double mean_error = 0;
  std::size_t samples = 0;
};
AdfError measure_adf_error(const Adf& adf, const TriMesh& source, const MeshDistance& mesh, std::size_t samples,
                           std::uint64_t seed = 1);

template <typename F>
void Adf::for_each_leaf(F&& f) const {
  // Level order: walk the levels with the positions of the current one.
  struct Cell {
    std::size_t node;
    std::uint64_t x, y, z;
  };
  std::vector<Cell> level{{0, 0, 0, 0}}, next;
  double side = size_;
  float corners[8];
  for (int l = 0; !level.empty(); ++l, side /= 2) {
    next.clear();
    for (const Cell& c : level) {
      if (!is_inner(c.node)) {
        cell_corners(l, c.x, c.y, c.z, corners);
        f(l, Vec3d(origin_ + Vec3d(double(c.x), double(c.y), double(c.z)) * side), side, static_cast<const float*>(corners));
      } else {
        const std::size_t first = first_child(c.node);
        for (std::uint64_t o = 0; o < 8; ++o)
          next.push_back({first + o, 2 * c.x + (o & 1), 2 * c.y + ((o >> 1) & 1), 2 * c.z + ((o >> 2) & 1)});
      }
    }
    std::swap(level, next);
  }
}

}  // namespace geods::field
