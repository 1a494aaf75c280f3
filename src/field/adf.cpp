#include "geods/field/adf.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/grid3.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/iso/marching_cubes.hpp"

namespace geods::field {
namespace {

constexpr char kKind[] = "field.Adf";
// 2: shared quantized corners, one bit a cell (version 1: 32-bit nodes and 8 floats a leaf).
constexpr std::uint32_t kVersion = 2;
// The build's temporary node: the leaf bit, else the first child's index.
constexpr std::uint32_t kLeaf = 0x80000000u;

// The options, the root cube and the storage's layout, one archive record.
struct Params {
  double error, band, padding;
  std::int32_t max_depth, checks;
  std::uint32_t sign, reserved;
  double origin[3];
  double size;
  std::uint64_t cells, corners;
  std::int32_t depth, shift, value_bits, reserved2;
  double value_lo, quantum;
};

// n fields of `bits` bits packed in 64-bit words, with a word of padding (see Adf::unpack).
std::size_t packed_words(std::size_t n, int bits) { return (n * std::size_t(bits) + 63) / 64 + 1; }

std::vector<std::uint64_t> pack(const std::vector<std::uint64_t>& fields, int bits) {
  std::vector<std::uint64_t> words(packed_words(fields.size(), bits), 0);
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::size_t at = i * std::size_t(bits), w = at >> 6, o = at & 63;
    words[w] |= fields[i] << o;
    if (o + std::size_t(bits) > 64) words[w + 1] |= fields[i] >> (64 - o);
  }
  return words;
}

// The key of lattice point (x, y, z) on the (n + 1)^3 lattice.
std::uint64_t lattice_key(std::uint64_t x, std::uint64_t y, std::uint64_t z, std::uint64_t n) {
  return x + (n + 1) * (y + (n + 1) * z);
}

double physical_memory() { return double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE)); }

void check_options(const AdfOptions& o) {
  if (!std::isfinite(o.error) || !(o.error > 0)) throw Error(fmt::format("adf: the error must be finite and > 0, got {}", o.error));
  if (o.max_depth < 0 || o.max_depth > kAdfMaxDepth)
    throw Error(fmt::format("adf: max_depth must be in 0..{}, got {}", kAdfMaxDepth, o.max_depth));
  if (o.checks < 3 || o.checks > 9 || o.checks % 2 == 0)
    throw Error(fmt::format("adf: checks must be odd, 3 to 9, got {}", o.checks));
  if (!std::isfinite(o.padding) || !(o.padding >= 0) || o.padding > 100)
    throw Error(fmt::format("adf: padding must be in [0, 100], got {}", o.padding));
  if (std::isnan(o.band) || !(o.band > 0)) throw Error(fmt::format("adf: the band must be > 0, got {}", o.band));
  if (std::uint32_t(o.sign) > std::uint32_t(SignMethod::none)) throw Error("adf: unknown sign method");
}

float trilinear(const float* c, double x, double y, double z) {
  const double c00 = c[0] + (c[1] - c[0]) * x, c10 = c[2] + (c[3] - c[2]) * x;
  const double c01 = c[4] + (c[5] - c[4]) * x, c11 = c[6] + (c[7] - c[6]) * x;
  const double c0 = c00 + (c10 - c00) * y, c1 = c01 + (c11 - c01) * y;
  return float(c0 + (c1 - c0) * z);
}

// One cell of a level being built: its integer position at its level and its corner distances.
struct BuildCell {
  std::uint32_t x, y, z;
  float corners[8];
};

// What the evaluation of a cell decided.
struct CellResult {
  bool split = false;
  bool unresolved = false;
  std::uint32_t queries = 0;
  std::size_t signs = 0;
  float lattice[27];  // the distances at {0, 1/2, 1}^3 of the cell (x fastest): its children's corners
};

// A point whose exact (clamped) distance is known: a cell's corner or centre.
struct Known {
  Vec3d p;
  float d;
};

// The exact field as the ADF stores it: the distance clamped to the band.
// The closest point is searched unsigned, no farther than the distance a
// known point bounds (|d_k| + |p - p_k|); the sign is that of a known point k
// when the balls about p and k free of surface overlap along the segment
// between them (|d| + |d_k| > |p - p_k|: the segment meets no surface), and
// is only computed (winding number, or pseudonormal) near the surface.
class Exact {
 public:
  Exact(const MeshDistance& mesh, const AdfOptions& o, double size)
      : mesh_(mesh), sign_(o.sign), outer_(2 * o.band), slack_(1e-6 * size) {}

  // Distance at p clamped to twice the band, searching no farther than
  // `reach` beyond the band (default: to twice the band; a point farther
  // gets +-that limit, and `beyond` tells).
  float operator()(const Vec3d& p, std::span<const Known> known, std::size_t& windings, double reach = -1,
                   bool* beyond = nullptr) const {
    const bool banded = std::isfinite(outer_);
    const double limit = banded ? (reach < 0 ? outer_ : outer_ / 2 + reach) : std::numeric_limits<double>::infinity();
    double bound = limit;
    for (const Known& k : known)
      if (!banded || std::abs(k.d) < outer_) bound = std::min(bound, std::abs(double(k.d)) + (p - k.p).norm());
    const Vec3f pf = p.cast<float>();
    const bool bounded = bound < limit;
    MeshPointDistance r = mesh_.query(pf, SignMethod::none, float(bounded ? bound * (1 + 1e-5) + slack_ : limit));
    if (bounded && std::isinf(r.distance)) r = mesh_.query(pf, SignMethod::none, float(limit));
    const bool far = std::isinf(r.distance);
    if (beyond) *beyond = far;
    const double u = far ? limit : double(r.distance);  // a lower bound when far
    double sign = 1;
    if (sign_ != SignMethod::none) {
      bool found = false;
      for (const Known& k : known)
        if (k.d != 0 && u + std::abs(double(k.d)) > (p - k.p).norm() * (1 + 1e-5) + slack_) {
          sign = k.d < 0 ? -1 : 1;
          found = true;
          break;
        }
      if (!found) {
        ++windings;
        if (sign_ == SignMethod::pseudonormal && !far)
          sign = mesh_.inside_by_pseudonormal(pf, r) ? -1 : 1;
        else
          sign = mesh_.winding_number(pf) > 0.5 ? -1 : 1;
      }
    }
    const double d = sign * u;
    return float(banded ? std::clamp(d, -outer_, outer_) : d);
  }

 private:
  const MeshDistance& mesh_;
  SignMethod sign_;
  double outer_, slack_;
};

}  // namespace

Adf Adf::build(const TriMesh& mesh, const AdfOptions& options) {
  check_options(options);
  return build(mesh, MeshDistance::build(mesh), options);
}

Adf Adf::build(const TriMesh& source, const MeshDistance& mesh, const AdfOptions& options) {
  check_options(options);
  if (mesh.num_faces() == 0 || source.num_triangles() == 0) throw Error("adf: the mesh has no faces");
  const AABB3f box = source.bounds();
  if (box.empty() || !box.lo.allFinite() || !box.hi.allFinite()) throw Error("adf: the mesh's bounds are not finite");
  const double extent = box.extent().cast<double>().maxCoeff();
  if (!(extent > 0)) throw Error("adf: the mesh has no extent (all its vertices coincide)");

  Adf adf;
  adf.options_ = options;
  adf.size_ = extent * (1 + 2 * options.padding);
  adf.origin_ = (box.lo.cast<double>() + box.hi.cast<double>()) / 2 - Vec3d::Constant(adf.size_ / 2);
  if (!adf.origin_.allFinite() || !std::isfinite(adf.size_) ||
      !(adf.origin_ + Vec3d::Constant(adf.size_)).cast<float>().allFinite())
    throw Error("adf: the root cube reaches beyond float range");

  const Exact exact(mesh, options, adf.size_);
  const float band = std::isfinite(options.band) ? float(options.band) : std::numeric_limits<float>::infinity();
  auto clamp_band = [band](float v) { return std::clamp(v, -band, band); };
  const int n = options.checks, m = (n - 1) / 2;
  std::vector<std::uint32_t> nodes;
  std::vector<float> values;
  std::size_t queries = 0, unresolved = 0;

  std::vector<BuildCell> level(1), next;
  level[0] = {0, 0, 0, {}};
  std::size_t signs = 0;
  for (int c = 0; c < 8; ++c)
    level[0].corners[c] = exact(adf.origin_ + Vec3d(c & 1, (c >> 1) & 1, (c >> 2) & 1) * adf.size_, {}, signs);
  queries += 8;
  // The values' range: |d(p)| <= |d(c)| + |p - c| for the corner c nearest p.
  double range = 0;
  for (const float v : level[0].corners) range = std::max(range, double(std::abs(v)));
  range = (range + adf.size_ * std::sqrt(3.0) / 2) * (1 + 1e-6);
  if (std::isfinite(options.band)) range = std::min(range, 2 * options.band);
  // b-bit steps of [-range, range], the fewest bits (at most 16) whose step
  // is at most E / 32; the test then leaves a step of the error (half for
  // the rounding, half for the float differences of one vertex computed from
  // different cells). Floats when 16 bits are too coarse. (mesh_100k at
  // E = 0.01: E / 8 gives 13 bits, 54,349 leaves, 299 kB; E / 32 15 bits,
  // 47,916 leaves, 285 kB; with the whole E, 46,285 leaves.)
  int value_bits = 1;
  while (value_bits <= 16 && 2 * range / double((1 << value_bits) - 1) > options.error / 32) ++value_bits;
  const bool quantize = value_bits <= 16;
  const double quantum = quantize ? 2 * range / double((1 << value_bits) - 1) : 0;
  if (!quantize) value_bits = 32;
  const float error = float(options.error - quantum);
  std::vector<CellResult> results;
  const double memory = physical_memory();

  for (int depth = 0; !level.empty(); ++depth) {
    const double side = adf.size_ / double(std::uint64_t(1) << depth), h = side / (n - 1);
    const double half_diagonal = side * std::sqrt(3.0) / 2;
    results.assign(level.size(), CellResult{});
    parallel_for_each_index(
        0, level.size(),
        [&](std::size_t i) {
          const BuildCell& cell = level[i];
          CellResult& r = results[i];
          const Vec3d lo = adf.origin_ + Vec3d(cell.x, cell.y, cell.z) * side;
          std::array<Known, 9> known;
          for (int c = 0; c < 8; ++c) known[c] = {lo + Vec3d(c & 1, (c >> 1) & 1, (c >> 2) & 1) * side, cell.corners[c]};
          // A cell wholly beyond the band holds the constant +-band: a leaf.
          bool beyond = false;
          const Vec3d mid = lo + Vec3d::Constant(side / 2);
          const float centre = exact(mid, std::span(known.data(), 8), r.signs, half_diagonal, &beyond);
          known[8] = {mid, centre};
          ++r.queries;
          if (beyond) return;
          const bool deepest = depth == options.max_depth;
          auto error_at = [&](int a, int b, int c, float& value) {
            if ((a == 0 || a == n - 1) && (b == 0 || b == n - 1) && (c == 0 || c == n - 1)) {
              value = cell.corners[(a ? 1 : 0) + (b ? 2 : 0) + (c ? 4 : 0)];
              return 0.0f;
            }
            if (a == m && b == m && c == m) {
              value = centre;
            } else {
              value = exact(lo + Vec3d(a, b, c) * h, known, r.signs);
              ++r.queries;
            }
            const double t = 1.0 / (n - 1);
            return std::abs(clamp_band(value) - clamp_band(trilinear(cell.corners, a * t, b * t, c * t)));
          };
          // First the points that are the children's corners, then the rest of the lattice.
          const int coarse[3] = {0, m, n - 1};
          bool over = false;
          for (int c = 0; c < 3; ++c)
            for (int b = 0; b < 3; ++b)
              for (int a = 0; a < 3; ++a)
                over |= error_at(coarse[a], coarse[b], coarse[c], r.lattice[a + 3 * b + 9 * c]) > error;
          for (int c = 0; c < n && !over; ++c)
            for (int b = 0; b < n && !over; ++b)
              for (int a = 0; a < n && !over; ++a) {
                if (a % m == 0 && b % m == 0 && c % m == 0) continue;  // done above
                float value;
                over = error_at(a, b, c, value) > error;
              }
          r.split = over && !deepest;
          r.unresolved = over && deepest;
        },
        16);

    // Number the level's nodes in order; split cells' children make the next level.
    std::size_t splits = 0;
    for (const CellResult& r : results) splits += r.split;
    const std::size_t leaves = values.size() / 8 + (level.size() - splits);
    const std::size_t total_nodes = nodes.size() + level.size() + 8 * splits;
    if (total_nodes >= kLeaf || leaves >= kLeaf)
      throw Error(fmt::format("adf: more than 2^31 cells at depth {}: a larger error or a smaller max_depth", depth + 1));
    const double bytes = double(total_nodes) * 4 + double(leaves) * 32 + double(8 * splits) * (sizeof(BuildCell) + sizeof(CellResult));
    if (memory > 0 && bytes > memory)
      throw Error(fmt::format("adf: depth {} needs {:.1f} GB, more than this machine's {:.1f} GB: a larger error or a "
                              "smaller max_depth",
                              depth + 1, bytes / 1e9, memory / 1e9));
    next.clear();
    next.reserve(8 * splits);
    std::size_t first_child = nodes.size() + level.size();
    for (std::size_t i = 0; i < level.size(); ++i) {
      const CellResult& r = results[i];
      queries += r.queries;
      unresolved += r.unresolved;
      signs += r.signs;
      if (!r.split) {
        nodes.push_back(kLeaf | std::uint32_t(values.size() / 8));
        values.insert(values.end(), level[i].corners, level[i].corners + 8);
        continue;
      }
      nodes.push_back(std::uint32_t(first_child));
      first_child += 8;
      const BuildCell& cell = level[i];
      for (int o = 0; o < 8; ++o) {
        const int ox = o & 1, oy = (o >> 1) & 1, oz = (o >> 2) & 1;
        BuildCell child{2 * cell.x + ox, 2 * cell.y + oy, 2 * cell.z + oz, {}};
        for (int c = 0; c < 8; ++c)
          child.corners[c] = r.lattice[(ox + (c & 1)) + 3 * (oy + ((c >> 1) & 1)) + 9 * (oz + ((c >> 2) & 1))];
        next.push_back(child);
      }
    }
    std::swap(level, next);
  }
  adf.store(nodes, values, value_bits, quantum, -range);
  adf.stats_.exact_queries = queries;
  adf.stats_.unresolved = unresolved;
  adf.stats_.signs = signs;
  adf.finish_stats();
  return adf;
}

void Adf::store(const std::vector<std::uint32_t>& nodes, const std::vector<float>& values, int value_bits, double quantum,
                double lo) {
  cells_ = nodes.size();
  std::vector<std::uint64_t> inner((cells_ + 63) / 64, 0);
  for (std::size_t i = 0; i < cells_; ++i)
    if (!(nodes[i] & kLeaf)) inner[i >> 6] |= std::uint64_t(1) << (i & 63);
  // The leaves' positions, level by level.
  struct Leaf {
    int level;
    std::uint64_t x, y, z;
    std::uint32_t leaf;
  };
  struct Cell {
    std::uint32_t node;
    std::uint64_t x, y, z;
  };
  std::vector<Leaf> leaves;
  std::vector<Cell> level{{0, 0, 0, 0}}, next;
  depth_ = 0;
  for (int l = 0; !level.empty(); ++l) {
    next.clear();
    for (const Cell& c : level) {
      const std::uint32_t v = nodes[c.node];
      if (v & kLeaf) {
        leaves.push_back({l, c.x, c.y, c.z, v & ~kLeaf});
        depth_ = std::max(depth_, l);
      } else {
        for (std::uint32_t o = 0; o < 8; ++o)
          next.push_back({v + o, 2 * c.x + (o & 1), 2 * c.y + ((o >> 1) & 1), 2 * c.z + ((o >> 2) & 1)});
      }
    }
    std::swap(level, next);
  }
  // Every leaf corner's key with its value; one value a key (a vertex computed
  // from different cells may differ in the last float bit: the smallest wins).
  const std::uint64_t n = std::uint64_t(1) << depth_;
  std::vector<std::pair<std::uint64_t, float>> corners;
  corners.reserve(8 * leaves.size());
  for (const Leaf& f : leaves) {
    const int s = depth_ - f.level;
    for (int c = 0; c < 8; ++c)
      corners.emplace_back(lattice_key((f.x + (c & 1)) << s, (f.y + ((c >> 1) & 1)) << s, (f.z + ((c >> 2) & 1)) << s, n),
                           values[std::size_t(f.leaf) * 8 + c]);
  }
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
                corners.end());
  corners_ = corners.size();
  if (corners_ >= kNoIndex) throw Error("adf: more than 2^32 distinct corners: a larger error or a smaller max_depth");
  // Buckets of about 32 keys (32 bits of offset for 32 corners: the fewest
  // bits a corner, offsets and key parts together, are at about 22).
  const std::uint64_t last = lattice_key(n, n, n, n);
  const std::uint64_t target = std::max<std::uint64_t>(1, corners_ / 32);
  shift_ = 0;
  while ((last >> shift_) + 1 > target) ++shift_;
  const std::uint64_t mask = shift_ >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << shift_) - 1;
  std::vector<std::uint32_t> buckets(std::size_t(last >> shift_) + 2, 0);
  std::vector<std::uint64_t> fields(corners_);
  for (std::size_t i = 0; i < corners_; ++i) {
    ++buckets[std::size_t(corners[i].first >> shift_) + 1];
    fields[i] = corners[i].first & mask;
  }
  for (std::size_t b = 1; b < buckets.size(); ++b) buckets[b] += buckets[b - 1];
  keys_ = FlatArray<std::uint64_t>(pack(fields, shift_));
  value_bits_ = value_bits;
  quantum_ = quantum;
  value_lo_ = quantum > 0 ? lo : 0;
  if (quantum > 0) {
    const long long top = (1LL << value_bits) - 1;
    for (std::size_t i = 0; i < corners_; ++i)
      fields[i] = std::uint64_t(std::clamp(std::llround((double(corners[i].second) - lo) / quantum), 0LL, top));
    values_ = FlatArray<std::uint64_t>(pack(fields, value_bits));
    values32_ = {};
  } else {
    std::vector<float> v(corners_);
    for (std::size_t i = 0; i < corners_; ++i) v[i] = corners[i].second;
    values32_ = FlatArray<float>(std::move(v));
    values_ = {};
  }
  inner_ = FlatArray<std::uint64_t>(std::move(inner));
  buckets_ = FlatArray<std::uint32_t>(std::move(buckets));
  make_ranks();
}

void Adf::make_ranks() {
  std::vector<std::uint32_t> rank(inner_.size());
  std::uint32_t count = 0;
  for (std::size_t w = 0; w < inner_.size(); ++w) {
    rank[w] = count;
    count += std::uint32_t(std::popcount(inner_[w]));
  }
  rank_ = FlatArray<std::uint32_t>(std::move(rank));
}

std::size_t Adf::find_corner(std::uint64_t key) const {
  const std::uint64_t b = key >> shift_;
  if (b + 1 >= buckets_.size()) return kNoIndex;
  const std::uint64_t low = shift_ >= 64 ? key : key & ((std::uint64_t(1) << shift_) - 1);
  std::size_t lo = buckets_[b], hi = buckets_[b + 1];
  const std::uint64_t* k = keys_.data();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (unpack(k, mid, shift_) < low) lo = mid + 1;
    else hi = mid;
  }
  return lo < std::size_t(buckets_[b + 1]) && unpack(k, lo, shift_) == low ? lo : kNoIndex;
}

void Adf::cell_corners(int level, std::uint64_t x, std::uint64_t y, std::uint64_t z, float out[8]) const {
  if (level < 0 || level > depth_) throw Error(fmt::format("adf: no cell at level {} (depth {})", level, depth_));
  const int s = depth_ - level;
  const std::uint64_t n = std::uint64_t(1) << depth_;
  for (int c = 0; c < 8; ++c) {
    const std::uint64_t cx = (x + (c & 1)) << s, cy = (y + ((c >> 1) & 1)) << s, cz = (z + ((c >> 2) & 1)) << s;
    const std::size_t i = cx <= n && cy <= n && cz <= n ? find_corner(lattice_key(cx, cy, cz, n)) : kNoIndex;
    if (i == kNoIndex) throw Error(fmt::format("adf: the corner ({}, {}, {}) of a level-{} cell is not stored", cx, cy, cz, level));
    out[c] = corner_value(i);
  }
}

void Adf::finish_stats() {
  std::size_t inner = 0;
  for (const std::uint64_t w : inner_) inner += std::size_t(std::popcount(w));
  stats_.cells = cells_;
  stats_.leaves = cells_ - inner;
  stats_.depth = std::size_t(depth_);
  stats_.corners = corners_;
  stats_.value_bits = std::size_t(value_bits_);
  stats_.key_bits = std::size_t(shift_);
  stats_.quantum = quantum_;
  stats_.bytes = 8 * inner_.size() + 4 * rank_.size() + 4 * buckets_.size() + 8 * keys_.size() + 8 * values_.size() +
                 4 * values32_.size();
  const double side = double(std::uint64_t(1) << depth_) + 1;
  stats_.dense_bytes = std::size_t(4 * side * side * side);
}

void Adf::validate() const {
  check_options(options_);
  if (!origin_.allFinite() || !std::isfinite(size_) || !(size_ > 0)) throw Error("adf: the root cube is not finite");
  if (cells_ == 0 || cells_ >= kLeaf) throw Error("adf: no cells, or more than 2^31");
  if (inner_.size() != (cells_ + 63) / 64 || rank_.size() != inner_.size())
    throw Error(fmt::format("adf: {} tree words for {} cells", inner_.size(), cells_));
  if (cells_ % 64 && inner_.back() >> (cells_ % 64)) throw Error("adf: tree bits beyond the last cell");
  std::size_t inner = 0;
  for (const std::uint64_t w : inner_) inner += std::size_t(std::popcount(w));
  if (cells_ != 1 + 8 * inner) throw Error(fmt::format("adf: {} cells with {} inner ones is not an octree", cells_, inner));
  // The levels are consecutive cell ranges: the deepest one is the depth.
  std::size_t begin = 0, end = 1;
  int levels = 0;
  while (begin < end) {
    std::size_t level_inner = 0;
    for (std::size_t i = begin; i < end; ++i) level_inner += is_inner(i);
    begin = end;
    end += 8 * level_inner;
    ++levels;
  }
  if (levels - 1 != depth_ || depth_ > options_.max_depth)
    throw Error(fmt::format("adf: the tree has depth {}, recorded {} (max_depth {})", levels - 1, depth_, options_.max_depth));
  // Buckets and keys.
  const std::uint64_t n = std::uint64_t(1) << depth_, last = lattice_key(n, n, n, n);
  if (shift_ < 0 || shift_ > 64) throw Error(fmt::format("adf: bad key layout (shift {})", shift_));
  if (buckets_.size() != std::size_t(shift_ >= 64 ? 0 : last >> shift_) + 2 || buckets_[0] != 0 || buckets_.back() != corners_ ||
      keys_.size() != packed_words(corners_, shift_))
    throw Error(fmt::format("adf: {} buckets and {} key words for {} corners do not match", buckets_.size(), keys_.size(), corners_));
  for (std::size_t b = 0; b + 1 < buckets_.size(); ++b) {
    if (buckets_[b] > buckets_[b + 1]) throw Error(fmt::format("adf: bucket {} starts after the next one", b));
    for (std::size_t i = buckets_[b]; i < buckets_[b + 1]; ++i) {
      const std::uint64_t low = unpack(keys_.data(), i, shift_);
      const std::uint64_t key = shift_ >= 64 ? low : (std::uint64_t(b) << shift_) | low;
      if (key > last || (i > buckets_[b] && unpack(keys_.data(), i - 1, shift_) >= low))
        throw Error(fmt::format("adf: corner key {} is out of order or out of range", i));
    }
  }
  // Values.
  const float outer = std::isfinite(options_.band) ? float(2 * options_.band) : std::numeric_limits<float>::max();
  if (value_bits_ <= 16) {
    const double top = value_lo_ + double((1 << value_bits_) - 1) * quantum_;
    if (value_bits_ < 1 || values_.size() != packed_words(corners_, value_bits_) || !values32_.empty() ||
        !std::isfinite(value_lo_) || !std::isfinite(quantum_) || !(quantum_ > 0) ||
        !(std::abs(value_lo_) <= 1.01 * double(outer)) || !(std::abs(top) <= 1.01 * double(outer)))
      throw Error(fmt::format("adf: bad {}-bit values ({} words for {} corners, from {} by {})", value_bits_, values_.size(),
                              corners_, value_lo_, quantum_));
  } else {
    if (value_bits_ != 32 || !values_.empty()) throw Error(fmt::format("adf: {}-bit values are not 1 to 16 or 32", value_bits_));
    if (values32_.size() != corners_) throw Error(fmt::format("adf: {} values for {} corners", values32_.size(), corners_));
    for (std::size_t i = 0; i < corners_; ++i)
      if (!(std::abs(values32_[i]) <= outer))
        throw Error(fmt::format("adf: value {} is {} (not finite or beyond the band)", i, values32_[i]));
  }
  // Every leaf finds its 8 corners (cell_corners throws otherwise).
  for_each_leaf([](int, const Vec3d&, double, const float*) {});
}

AdfSample Adf::sample(const Vec3f& p) const {
  if (!p.allFinite()) throw Error("adf: a query point is not finite");
  Vec3d u = (p.cast<double>() - origin_) / size_;
  const Vec3d inside = u.cwiseMax(0.0).cwiseMin(1.0);
  const Vec3d outside = (u - inside) * size_;  // p - (nearest point of the cube)
  u = inside;
  std::size_t node = 0;
  std::uint64_t cx = 0, cy = 0, cz = 0;
  int level = 0;
  double side = size_;
  while (is_inner(node)) {
    std::size_t child = 0;
    for (int a = 0; a < 3; ++a)
      if (u[a] >= 0.5) child |= std::size_t(1) << a, u[a] = 2 * u[a] - 1;
      else u[a] = 2 * u[a];
    node = first_child(node) + child;
    cx = 2 * cx + (child & 1), cy = 2 * cy + ((child >> 1) & 1), cz = 2 * cz + ((child >> 2) & 1);
    side /= 2;
    ++level;
  }
  float c[8];
  cell_corners(level, cx, cy, cz, c);
  AdfSample s;
  s.distance = trilinear(c, u.x(), u.y(), u.z());
  // The derivatives of the trilinear interpolation along x, y, z.
  const double x = u.x(), y = u.y(), z = u.z();
  const double dx = ((c[1] - c[0]) * (1 - y) + (c[3] - c[2]) * y) * (1 - z) + ((c[5] - c[4]) * (1 - y) + (c[7] - c[6]) * y) * z;
  const double dy = ((c[2] - c[0]) * (1 - x) + (c[3] - c[1]) * x) * (1 - z) + ((c[6] - c[4]) * (1 - x) + (c[7] - c[5]) * x) * z;
  const double dz = ((c[4] - c[0]) * (1 - x) + (c[5] - c[1]) * x) * (1 - y) + ((c[6] - c[2]) * (1 - x) + (c[7] - c[3]) * x) * y;
  Vec3d g = Vec3d(dx, dy, dz) / side;
  const double away = outside.norm();
  if (away > 0) {
    s.distance = float(double(s.distance) + away);
    for (int a = 0; a < 3; ++a)
      if (outside[a] != 0) g[a] = outside[a] / away;
  }
  s.gradient = g.cast<float>();
  if (std::isfinite(options_.band))
    s.distance = std::clamp(s.distance, -float(options_.band), float(options_.band));
  return s;
}

Vec3f Adf::closest_point(const Vec3f& p) const {
  const AdfSample s = sample(p);
  const float norm = s.gradient.norm();
  if (!(norm > 0)) return p;
  return p - s.distance * s.gradient / norm;
}

TriMesh Adf::isosurface(double offset, std::size_t res) const {
  if (!std::isfinite(offset)) throw Error("adf isosurface: the offset is not finite");
  if (std::isfinite(options_.band) && !(std::abs(offset) < options_.band))
    throw Error(fmt::format("adf isosurface: offset {} is outside the band {}", offset, options_.band));
  if (res == 0) res = (std::size_t(1) << std::min<std::size_t>(stats_.depth, 8)) + 1;
  if (res < 2) throw Error("adf isosurface: res must be >= 2");
  const double bytes = double(res) * double(res) * double(res) * 4;
  const double memory = physical_memory();
  if (res > (std::size_t(1) << 21) || (memory > 0 && bytes > memory / 2))
    throw Error(fmt::format("adf isosurface: {}^3 samples need {:.1f} GB, more than half this machine's {:.1f} GB", res,
                            bytes / 1e9, memory / 1e9));
  Grid3<float> grid(res, res, res);
  grid.origin = origin_.cast<float>();
  grid.spacing = Vec3f::Constant(float(size_ / double(res - 1)));
  // Marching cubes puts inside at samples >= iso: the negated distance, inside the offset surface.
  parallel_for_each_index(
      0, res * res,
      [&](std::size_t kj) {
        const std::size_t k = kj / res, j = kj % res;
        for (std::size_t i = 0; i < res; ++i) {
          const Vec3d p = origin_ + Vec3d(double(i), double(j), double(k)) * (size_ / double(res - 1));
          grid(i, j, k) = -distance(p.cast<float>());
        }
      },
      4);
  return iso::isosurface(grid, -offset);
}

void Adf::save(const std::filesystem::path& path) const {
  Params p{options_.error,
           options_.band,
           options_.padding,
           options_.max_depth,
           options_.checks,
           std::uint32_t(options_.sign),
           0,
           {origin_.x(), origin_.y(), origin_.z()},
           size_,
           cells_,
           corners_,
           depth_,
           shift_,
           value_bits_,
           0,
           value_lo_,
           quantum_};
  ArchiveWriter w(kKind, kVersion);
  w.add_value("params", p);
  w.add_value("stats", stats_);
  w.add("inner", inner_);
  w.add("buckets", buckets_);
  w.add("keys", keys_);
  if (values_.empty()) w.add("values", values32_);
  else w.add("values", values_);
  w.write(path);
}

Adf Adf::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kKind, kVersion, verify);
  const Params p = a.value<Params>("params");
  Adf adf;
  adf.options_.error = p.error;
  adf.options_.band = p.band;
  adf.options_.padding = p.padding;
  adf.options_.max_depth = p.max_depth;
  adf.options_.checks = p.checks;
  if (p.sign > std::uint32_t(SignMethod::none)) throw a.error("unknown sign method");
  adf.options_.sign = SignMethod(p.sign);
  adf.origin_ = Vec3d(p.origin[0], p.origin[1], p.origin[2]);
  adf.size_ = p.size;
  if (p.depth < 0 || p.depth > kAdfMaxDepth) throw a.error(fmt::format("depth {} is out of range", p.depth));
  adf.cells_ = std::size_t(p.cells);
  adf.corners_ = std::size_t(p.corners);
  adf.depth_ = p.depth;
  adf.shift_ = p.shift;
  adf.value_bits_ = p.value_bits;
  adf.value_lo_ = p.value_lo;
  adf.quantum_ = p.quantum;
  adf.inner_ = a.array<std::uint64_t>("inner");
  adf.buckets_ = a.array<std::uint32_t>("buckets");
  adf.keys_ = a.array<std::uint64_t>("keys");
  if (p.value_bits >= 1 && p.value_bits <= 16) adf.values_ = a.array<std::uint64_t>("values");
  else if (p.value_bits == 32) adf.values32_ = a.array<float>("values");
  else throw a.error(fmt::format("{}-bit values are not 1 to 16 or 32", p.value_bits));
  const AdfStats stored = a.value<AdfStats>("stats");
  a.check([&] {
    if (adf.inner_.size() != (adf.cells_ + 63) / 64) throw Error("adf: the tree bits do not match the cells");
    adf.make_ranks();
    adf.validate();
  });
  adf.stats_.exact_queries = stored.exact_queries;
  adf.stats_.unresolved = stored.unresolved;
  adf.stats_.signs = stored.signs;
  adf.finish_stats();
  return adf;
}

AdfError measure_adf_error(const Adf& adf, const TriMesh& source, const MeshDistance& mesh, std::size_t samples,
                           std::uint64_t seed) {
  if (source.num_triangles() == 0) throw Error("adf error: the mesh has no faces");
  Rng rng(seed);
  const double finest = adf.size() / double(std::uint64_t(1) << adf.stats().depth);
  const Vec3d lo = adf.origin(), hi = lo + Vec3d::Constant(adf.size());
  std::vector<Vec3f> points(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    Vec3d p;
    if (i % 2 == 0) {
      p = Vec3d(rng.uniform(), rng.uniform(), rng.uniform());
      p = lo + p * adf.size();
    } else {
      const auto& t = source.triangles[rng.below(source.num_triangles())];
      double a = rng.uniform(), b = rng.uniform();
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Vec3d v0 = source.vertices[t[0]].cast<double>(), v1 = source.vertices[t[1]].cast<double>(),
                  v2 = source.vertices[t[2]].cast<double>();
      Vec3d dir(rng.normal(), rng.normal(), rng.normal());
      if (dir.norm() > 0) dir.normalize();
      p = v0 + a * (v1 - v0) + b * (v2 - v0) + dir * rng.uniform(0, 8 * finest);
    }
    points[i] = p.cwiseMax(lo).cwiseMin(hi).cast<float>();
  }
  std::vector<double> errors(samples);
  const double band = adf.options().band;
  parallel_for_each_index(
      0, samples,
      [&](std::size_t i) {
        double d = mesh.query(points[i], adf.options().sign).distance;
        if (std::isfinite(band)) d = std::clamp(d, -band, band);
        errors[i] = std::abs(double(adf.distance(points[i])) - d);
      },
      64);
  AdfError e;
  e.samples = samples;
  for (const double x : errors) e.max_error = std::max(e.max_error, x), e.mean_error += x;
  if (samples) e.mean_error /= double(samples);
  return e;
}

}  // namespace geods::field
