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
// 3: a leaf's low corner stored at the leaf's rank, only the other corners
// keyed (2: every corner keyed, read and converted; 1: 32-bit nodes and 8
// floats a leaf, refused).
constexpr std::uint32_t kVersion = 3;
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

// Bits of the Elias-Fano high part of m keys up to `last` whose low `shift` bits are stored apart.
std::uint64_t high_length(std::uint64_t m, std::uint64_t last, int shift) { return m + (last >> shift) + 1; }

// Every this many zeros of the high part, the position of one is sampled for select0.
constexpr std::uint64_t kSelectStep = 128;

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
          sign = mesh_.inside_by_winding(pf) ? -1 : 1;
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
  inner_ = FlatArray<std::uint64_t>(std::move(inner));
  make_ranks();
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
  if (corners.size() >= kNoIndex) throw Error("adf: more than 2^32 distinct corners: a larger error or a smaller max_depth");
  std::vector<std::uint64_t> keys(corners.size()), fields;
  std::vector<float> floats;
  for (std::size_t i = 0; i < corners.size(); ++i) keys[i] = corners[i].first;
  value_bits_ = value_bits;
  quantum_ = quantum;
  value_lo_ = quantum > 0 ? lo : 0;
  if (quantum > 0) {
    const long long top = (1LL << value_bits) - 1;
    fields.resize(corners.size());
    for (std::size_t i = 0; i < corners.size(); ++i)
      fields[i] = std::uint64_t(std::clamp(std::llround((double(corners[i].second) - lo) / quantum), 0LL, top));
  } else {
    floats.resize(corners.size());
    for (std::size_t i = 0; i < corners.size(); ++i) floats[i] = corners[i].second;
  }
  lay_out(keys, fields, floats);
}

void Adf::lay_out(const std::vector<std::uint64_t>& keys, const std::vector<std::uint64_t>& fields,
                  const std::vector<float>& floats) {
  // Each leaf's low corner: its value goes to the leaf's rank, unkeyed.
  const std::uint64_t n = std::uint64_t(1) << depth_;
  std::size_t inner = 0;
  for (const std::uint64_t w : inner_) inner += std::size_t(std::popcount(w));
  leaves_ = cells_ - inner;
  std::vector<std::size_t> of_leaf(leaves_, kNoIndex);
  std::vector<char> regular(keys.size(), 0);
  struct Cell {
    std::size_t node;
    std::uint64_t x, y, z;
  };
  std::vector<Cell> level{{0, 0, 0, 0}}, next;
  for (int l = 0; !level.empty() && l <= depth_; ++l) {
    next.clear();
    for (const Cell& c : level) {
      if (is_inner(c.node)) {
        const std::size_t first = first_child(c.node);
        for (std::uint64_t o = 0; o < 8; ++o)
          next.push_back({first + o, 2 * c.x + (o & 1), 2 * c.y + ((o >> 1) & 1), 2 * c.z + ((o >> 2) & 1)});
        continue;
      }
      const int s = depth_ - l;
      const std::uint64_t key = lattice_key(c.x << s, c.y << s, c.z << s, n);
      const auto it = std::lower_bound(keys.begin(), keys.end(), key);
      if (it == keys.end() || *it != key)
        throw Error(fmt::format("adf: the low corner of the level-{} leaf at ({}, {}, {}) is not stored", l, c.x, c.y, c.z));
      const std::size_t i = std::size_t(it - keys.begin());
      regular[i] = 1;
      of_leaf[leaf_rank(c.node)] = i;
    }
    std::swap(level, next);
  }
  if (!level.empty()) throw Error(fmt::format("adf: the tree is deeper than its recorded depth {}", depth_));
  std::vector<std::size_t> order(of_leaf);
  std::vector<std::uint64_t> keyed;
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (!regular[i]) order.push_back(i), keyed.push_back(keys[i]);
  corners_ = order.size();
  // The keyed corners, Elias-Fano coded: key = (high << shift) | low with
  // shift = floor(log2(lattice / keyed)); the lows bit-packed, the highs in
  // unary (keyed i sets bit high_i + i of `high`), found by select0.
  const std::uint64_t last = lattice_key(n, n, n, n);
  shift_ = 0;
  while (shift_ < 62 && (last >> (shift_ + 1)) >= std::max<std::uint64_t>(1, keyed.size())) ++shift_;
  const std::uint64_t mask = (std::uint64_t(1) << shift_) - 1;
  std::vector<std::uint64_t> low(keyed.size());
  high_bits_ = high_length(keyed.size(), last, shift_);
  if (high_bits_ >= (std::uint64_t(1) << 32)) throw Error("adf: more than 2^32 bits of keys: a larger error or a smaller max_depth");
  std::vector<std::uint64_t> high((high_bits_ + 63) / 64, 0);
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    low[i] = keyed[i] & mask;
    const std::uint64_t at = (keyed[i] >> shift_) + i;
    high[at >> 6] |= std::uint64_t(1) << (at & 63);
  }
  keys_ = FlatArray<std::uint64_t>(pack(low, shift_));
  high_ = FlatArray<std::uint64_t>(std::move(high));
  make_selects();
  if (value_bits_ <= 16) {
    std::vector<std::uint64_t> v(corners_);
    for (std::size_t i = 0; i < corners_; ++i) v[i] = fields[order[i]];
    values_ = FlatArray<std::uint64_t>(pack(v, value_bits_));
    values32_ = {};
  } else {
    std::vector<float> v(corners_);
    for (std::size_t i = 0; i < corners_; ++i) v[i] = floats[order[i]];
    values32_ = FlatArray<float>(std::move(v));
    values_ = {};
  }
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

void Adf::make_selects() {
  // The position of every kSelectStep-th zero of `high`.
  std::vector<std::uint32_t> select;
  std::uint64_t zeros = 0;
  for (std::size_t w = 0; w < high_.size(); ++w) {
    std::uint64_t z = ~high_[w];
    if (w + 1 == high_.size() && high_bits_ % 64) z &= (std::uint64_t(1) << (high_bits_ % 64)) - 1;
    for (; z; z &= z - 1, ++zeros)
      if (zeros % kSelectStep == 0) select.push_back(std::uint32_t(64 * w + std::size_t(std::countr_zero(z))));
  }
  select_ = FlatArray<std::uint32_t>(std::move(select));
}

// The position in `high` of zero number r (from 0; r below the zeros' count).
std::uint64_t Adf::select0(std::uint64_t r) const {
  const std::uint64_t pos = select_[r / kSelectStep];
  std::uint64_t left = r % kSelectStep;
  if (!left) return pos;
  std::size_t w = pos >> 6;
  std::uint64_t z = ~high_[w] & (~std::uint64_t(0) << (pos & 63));
  z &= z - 1;  // past zero number r - left
  for (;;) {
    const auto c = std::uint64_t(std::popcount(z));
    if (left <= c) {
      for (; left > 1; --left) z &= z - 1;
      return 64 * w + std::uint64_t(std::countr_zero(z));
    }
    left -= c;
    z = ~high_[++w];
  }
}

// The index (into the keyed corners) of `key`, or kNoIndex.
std::size_t Adf::find_corner(std::uint64_t key) const {
  const std::uint64_t h = key >> shift_, low = key & ((std::uint64_t(1) << shift_) - 1);
  if (h >= high_bits_ - (corners_ - leaves_)) return kNoIndex;  // beyond the zeros: no such high part
  // The keyed corners of high part h: the ones between zero h - 1 and zero h.
  std::uint64_t at = h == 0 ? 0 : select0(h - 1) + 1;
  for (std::size_t i = std::size_t(at - h); (high_[at >> 6] >> (at & 63)) & 1; ++at, ++i) {
    const std::uint64_t l = unpack(keys_.data(), i, shift_);
    if (l >= low) return l == low ? i : kNoIndex;
  }
  return kNoIndex;
}

std::size_t Adf::corner_below(std::size_t node, int level, std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
  // Down to the leaf holding (x, y, z) (half-open cells): the vertex is its low corner, or keyed.
  while (is_inner(node)) {
    const int s = depth_ - level - 1;
    node = first_child(node) + ((x >> s) & 1) + 2 * ((y >> s) & 1) + 4 * ((z >> s) & 1);
    ++level;
  }
  const std::uint64_t below = (std::uint64_t(1) << (depth_ - level)) - 1;
  if (((x | y | z) & below) == 0) return leaf_rank(node);
  const std::size_t i = find_corner(lattice_key(x, y, z, std::uint64_t(1) << depth_));
  return i == kNoIndex ? kNoIndex : leaves_ + i;
}

std::size_t Adf::corner_index(std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
  const std::uint64_t n = std::uint64_t(1) << depth_;
  if (x > n || y > n || z > n) return kNoIndex;
  if (x < n && y < n && z < n) return corner_below(0, 0, x, y, z);
  const std::size_t i = find_corner(lattice_key(x, y, z, n));  // on the cube's high faces: keyed
  return i == kNoIndex ? kNoIndex : leaves_ + i;
}

void Adf::leaf_corners(const std::size_t* path, int level, std::uint64_t x, std::uint64_t y, std::uint64_t z,
                       float out[8]) const {
  const int s = depth_ - level;
  const std::uint64_t n = std::uint64_t(1) << depth_;
  out[0] = corner_value(leaf_rank(path[level]));
  for (int c = 1; c < 8; ++c) {
    const std::uint64_t ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
    const std::uint64_t vx = (x + ox) << s, vy = (y + oy) << s, vz = (z + oz) << s;
    std::size_t i;
    if (vx < n && vy < n && vz < n) {
      // The deepest ancestor holding the corner too: above the highest bit where x and x + 1 differ.
      const int up = int(std::max({std::bit_width((x + ox) ^ x), std::bit_width((y + oy) ^ y), std::bit_width((z + oz) ^ z)}));
      i = corner_below(path[level - up], level - up, vx, vy, vz);
    } else {
      i = find_corner(lattice_key(vx, vy, vz, n));
      if (i != kNoIndex) i += leaves_;
    }
    if (i == kNoIndex) throw Error(fmt::format("adf: the corner ({}, {}, {}) of a level-{} cell is not stored", vx, vy, vz, level));
    out[c] = corner_value(i);
  }
}

void Adf::cell_corners(int level, std::uint64_t x, std::uint64_t y, std::uint64_t z, float out[8]) const {
  if (level < 0 || level > depth_) throw Error(fmt::format("adf: no cell at level {} (depth {})", level, depth_));
  const int s = depth_ - level;
  for (int c = 0; c < 8; ++c) {
    const std::uint64_t cx = (x + (c & 1)) << s, cy = (y + ((c >> 1) & 1)) << s, cz = (z + ((c >> 2) & 1)) << s;
    const std::size_t i = corner_index(cx, cy, cz);
    if (i == kNoIndex) throw Error(fmt::format("adf: the corner ({}, {}, {}) of a level-{} cell is not stored", cx, cy, cz, level));
    out[c] = corner_value(i);
  }
}

void Adf::finish_stats() {
  stats_.cells = cells_;
  stats_.leaves = leaves_;
  stats_.depth = std::size_t(depth_);
  stats_.corners = corners_;
  stats_.value_bits = std::size_t(value_bits_);
  stats_.key_bits = std::size_t(shift_);
  stats_.quantum = quantum_;
  stats_.bytes = 8 * inner_.size() + 4 * rank_.size() + 8 * high_.size() + 4 * select_.size() + 8 * keys_.size() + 8 * values_.size() +
                 4 * values32_.size();
  const double side = double(std::uint64_t(1) << depth_) + 1;
  stats_.dense_bytes = std::size_t(4 * side * side * side);
}

// The tree's checks: word count, bits beyond the last cell, an octree, level count = depth.
static void check_tree(std::size_t cells, const FlatArray<std::uint64_t>& inner_bits, int depth, int max_depth) {
  if (cells == 0 || cells >= kLeaf) throw Error("adf: no cells, or more than 2^31");
  if (inner_bits.size() != (cells + 63) / 64) throw Error(fmt::format("adf: {} tree words for {} cells", inner_bits.size(), cells));
  if (cells % 64 && inner_bits.back() >> (cells % 64)) throw Error("adf: tree bits beyond the last cell");
  std::size_t inner = 0;
  for (const std::uint64_t w : inner_bits) inner += std::size_t(std::popcount(w));
  if (cells != 1 + 8 * inner) throw Error(fmt::format("adf: {} cells with {} inner ones is not an octree", cells, inner));
  // The levels are consecutive cell ranges: the deepest one is the depth.
  std::size_t begin = 0, end = 1;
  int levels = 0;
  while (begin < end) {
    std::size_t level_inner = 0;
    for (std::size_t i = begin; i < end; ++i) level_inner += (inner_bits[i >> 6] >> (i & 63)) & 1;
    begin = end;
    end += 8 * level_inner;
    ++levels;
  }
  if (levels - 1 != depth || depth > max_depth)
    throw Error(fmt::format("adf: the tree has depth {}, recorded {} (max_depth {})", levels - 1, depth, max_depth));
}

// The bucketed keys' checks (buckets, word count, keys sorted within the lattice); calls f(i, key) for each.
template <typename F>
static void check_keys(const FlatArray<std::uint32_t>& buckets, const FlatArray<std::uint64_t>& keys, std::size_t count,
                       int shift, std::uint64_t last, F&& f) {
  if (shift < 0 || shift > 64) throw Error(fmt::format("adf: bad key layout (shift {})", shift));
  if (buckets.size() != std::size_t(shift >= 64 ? 0 : last >> shift) + 2 || buckets[0] != 0 || buckets.back() != count ||
      keys.size() != packed_words(count, shift))
    throw Error(fmt::format("adf: {} buckets and {} key words for {} keyed corners do not match", buckets.size(), keys.size(), count));
  for (std::size_t b = 0; b + 1 < buckets.size(); ++b)
    if (buckets[b] > buckets[b + 1]) throw Error(fmt::format("adf: bucket {} starts after the next one", b));
  for (std::size_t b = 0; b + 1 < buckets.size(); ++b) {
    for (std::size_t i = buckets[b]; i < buckets[b + 1]; ++i) {
      const std::uint64_t low = Adf::unpack(keys.data(), i, shift);
      const std::uint64_t key = shift >= 64 ? low : (std::uint64_t(b) << shift) | low;
      if (key > last || (i > buckets[b] && Adf::unpack(keys.data(), i - 1, shift) >= low))
        throw Error(fmt::format("adf: corner key {} is out of order or out of range", i));
      f(i, key);
    }
  }
}

template <typename F>
void Adf::for_each_keyed(std::size_t count, std::uint64_t last, F&& f) const {
  // The Elias-Fano structure's checks: its size, `count` ones, the zeros of
  // every high part, keys increasing within the lattice; f(i, key) for each.
  if (shift_ < 0 || shift_ > 62) throw Error(fmt::format("adf: bad key layout (shift {})", shift_));
  if (high_bits_ != high_length(count, last, shift_) || high_.size() != (high_bits_ + 63) / 64 ||
      keys_.size() != packed_words(count, shift_))
    throw Error(fmt::format("adf: {} bits of high parts and {} key words for {} keyed corners do not match", high_bits_,
                            keys_.size(), count));
  if (high_bits_ % 64 && high_.back() >> (high_bits_ % 64)) throw Error("adf: key bits beyond the last");
  std::size_t ones = 0;
  for (const std::uint64_t w : high_) ones += std::size_t(std::popcount(w));
  if (ones != count || select_.size() != (high_bits_ - count + kSelectStep - 1) / kSelectStep)
    throw Error(fmt::format("adf: {} keyed corners in the high parts, {} recorded", ones, count));
  std::uint64_t zeros = 0, previous = 0;
  std::size_t i = 0;
  for (std::uint64_t at = 0; at < high_bits_; ++at) {
    if (!((high_[at >> 6] >> (at & 63)) & 1)) {
      ++zeros;
      continue;
    }
    const std::uint64_t key = (zeros << shift_) | unpack(keys_.data(), i, shift_);
    if (key > last || (i > 0 && key <= previous)) throw Error(fmt::format("adf: corner key {} is out of order or out of range", i));
    previous = key;
    f(i++, key);
  }
}

void Adf::validate() const {
  check_options(options_);
  if (!origin_.allFinite() || !std::isfinite(size_) || !(size_ > 0)) throw Error("adf: the root cube is not finite");
  check_tree(cells_, inner_, depth_, options_.max_depth);
  if (rank_.size() != inner_.size()) throw Error("adf: the rank table does not match the tree");
  std::size_t inner = 0;
  for (const std::uint64_t w : inner_) inner += std::size_t(std::popcount(w));
  if (leaves_ != cells_ - inner || corners_ < leaves_)
    throw Error(fmt::format("adf: {} corners for {} leaves", corners_, cells_ - inner));
  // The keyed corners: sorted, on the lattice, none a leaf's low corner (stored unkeyed).
  const std::uint64_t n = std::uint64_t(1) << depth_, last = lattice_key(n, n, n, n);
  for_each_keyed(corners_ - leaves_, last, [&](std::size_t i, std::uint64_t key) {
    const std::uint64_t x = key % (n + 1), y = key / (n + 1) % (n + 1), z = key / (n + 1) / (n + 1);
    if (x < n && y < n && z < n && corner_below(0, 0, x, y, z) != leaves_ + i)
      throw Error(fmt::format("adf: keyed corner {} at ({}, {}, {}) is a leaf's low corner", i, x, y, z));
    if (find_corner(key) != i) throw Error(fmt::format("adf: keyed corner {} is not found", i));
  });
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
  std::size_t node = 0, path[kAdfMaxDepth + 1];
  path[0] = 0;
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
    path[++level] = node;
  }
  float c[8];
  leaf_corners(path, level, cx, cy, cz, c);
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
  w.add("high", high_);
  w.add("keys", keys_);
  if (values_.empty()) w.add("values", values32_);
  else w.add("values", values_);
  w.write(path);
}

Adf Adf::load(const std::filesystem::path& path, Archive::Verify verify) {
  // Version 2 (every corner keyed) is read and laid out anew; any other but 3 is refused by open.
  const bool v2 = Archive::peek(path).version == 2;
  const Archive a = Archive::open(path, kKind, v2 ? 2 : kVersion, verify);
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
  FlatArray<std::uint32_t> buckets;  // version 2
  if (v2) buckets = a.array<std::uint32_t>("buckets");
  else adf.high_ = a.array<std::uint64_t>("high");
  adf.keys_ = a.array<std::uint64_t>("keys");
  if (p.value_bits >= 1 && p.value_bits <= 16) adf.values_ = a.array<std::uint64_t>("values");
  else if (p.value_bits == 32) adf.values32_ = a.array<float>("values");
  else throw a.error(fmt::format("{}-bit values are not 1 to 16 or 32", p.value_bits));
  const AdfStats stored = a.value<AdfStats>("stats");
  a.check([&] {
    check_tree(adf.cells_, adf.inner_, adf.depth_, adf.options_.max_depth);
    adf.make_ranks();
    std::size_t inner = 0;
    for (const std::uint64_t w : adf.inner_) inner += std::size_t(std::popcount(w));
    adf.leaves_ = adf.cells_ - inner;
    if (v2) {
      // Every corner keyed, in key order: decode and lay out.
      const std::uint64_t n = std::uint64_t(1) << adf.depth_;
      std::vector<std::uint64_t> keys(adf.corners_), fields;
      std::vector<float> floats;
      check_keys(buckets, adf.keys_, adf.corners_, adf.shift_, lattice_key(n, n, n, n),
                 [&](std::size_t i, std::uint64_t key) { keys[i] = key; });
      if (adf.value_bits_ <= 16) {
        if (adf.values_.size() != packed_words(adf.corners_, adf.value_bits_))
          throw Error(fmt::format("adf: {} value words for {} corners", adf.values_.size(), adf.corners_));
        fields.resize(adf.corners_);
        for (std::size_t i = 0; i < adf.corners_; ++i) fields[i] = unpack(adf.values_.data(), i, adf.value_bits_);
      } else {
        if (adf.values32_.size() != adf.corners_) throw Error(fmt::format("adf: {} values for {} corners", adf.values32_.size(), adf.corners_));
        floats.assign(adf.values32_.begin(), adf.values32_.end());
      }
      adf.lay_out(keys, fields, floats);
    } else {
      if (adf.corners_ < adf.leaves_ || adf.shift_ < 0 || adf.shift_ > 62)
        throw Error(fmt::format("adf: {} corners for {} leaves, key shift {}", adf.corners_, adf.leaves_, adf.shift_));
      const std::uint64_t n = std::uint64_t(1) << adf.depth_;
      adf.high_bits_ = high_length(adf.corners_ - adf.leaves_, lattice_key(n, n, n, n), adf.shift_);
      if (adf.high_.size() != (adf.high_bits_ + 63) / 64) throw Error("adf: the keys' high parts do not match the corners");
      adf.make_selects();
    }
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
