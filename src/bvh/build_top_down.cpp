// Top-down builders (§4.1.3): binned SAH, object median, PCA plane and
// Zachmann's restricted boxtree criterion. Each recursion step splits a range
// of the primitive array in place; large ranges recurse in parallel. Each
// side of a parallel split numbers its nodes in its own range of ids (a
// subtree of k primitives has at most 2 k - 1 nodes), so no counter is shared
// between threads (one atomic per node made them fight over its cache line);
// the ids leave gaps, finalize() renumbers depth first, and every split
// decision depends only on the range's contents, so the tree is deterministic.
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "binary_tree.hpp"
#include "geods/core/huge_page_array.hpp"
#include "geods/core/parallel.hpp"

namespace geods::bvh::detail {
namespace {

constexpr std::size_t kParallelThreshold = 4096;  // ranges below this recurse sequentially
constexpr std::size_t kParallelScan = 65536;      // ranges above this are scanned in parallel
constexpr int kMaxBins = 64;

struct RangeBounds {
  AABB3f box;       // of the primitive boxes
  AABB3f centroid;  // of their centers
  void join(const RangeBounds& o) {
    box.extend(o.box);
    centroid.extend(o.centroid);
  }
};

typedef float Float4 __attribute__((vector_size(16)));
typedef std::int32_t Int4 __attribute__((vector_size(16)));

inline Float4 load4(const float* p) {
  Float4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Float4 min4(Float4 a, Float4 b) { return a < b ? a : b; }
inline Float4 max4(Float4 a, Float4 b) { return a > b ? a : b; }
// Whether any lane of a comparison result is true.
inline bool any4(Int4 m) {
#if defined(__SSE2__)
  return _mm_movemask_ps(_mm_castsi128_ps(__m128i(m))) != 0;
#else
  return (m[0] | m[1] | m[2] | m[3]) != 0;
#endif
}

// A bin of the SAH builder, 4-wide (the fourth lane is ignored): resetting
// only the bins in use is cheap, and one bin update is two SIMD operations.
struct Bin {
  Float4 lo, hi;
  std::uint32_t n;
  void reset() {
    const float inf = std::numeric_limits<float>::infinity();
    lo = Float4{inf, inf, inf, inf};
    hi = -lo;
    n = 0;
  }
  void extend(const Bin& o) {
    lo = min4(lo, o.lo);
    hi = max4(hi, o.hi);
    n += o.n;
  }
  float area() const {
    if (n == 0) return 0;
    const Float4 e = hi - lo;
    return 2 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
  }
};

struct Bins {
  int count = 0;
  Bin bin[3][kMaxBins];
  explicit Bins(int c) : count(c) {
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < count; ++i) bin[a][i].reset();
  }
  void join(const Bins& o) {
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < count; ++i) bin[a][i].extend(o.bin[a][i]);
  }
};

// lo, hi and center are contiguous floats: 4-wide loads from box.lo and
// box.hi read one float beyond (box.hi[0], center[0]), in the ignored lane.
struct PrimRef {
  AABB3f box;
  Vec3f center;
  std::uint32_t id;
};
static_assert(sizeof(AABB3f) == 24 && offsetof(PrimRef, center) == 24, "PrimRef layout");

// An array of n elements in memory advised to use huge pages, not yet touched:
// the builder constructs each element itself, in parallel (a std::vector
// would first initialize them all on one thread), and of the 2 n binary nodes
// only the pages of those made are ever faulted in.
template <typename T>
class UntouchedArray {
 public:
  explicit UntouchedArray(std::size_t n)
      : data_(make_huge_page_array<T>(n, /*touched=*/false)), size_(n) {
    static_assert(std::is_trivially_destructible_v<T>);  // freeing the memory ends them
  }
  std::size_t size() const { return size_; }
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }

 private:
  HugePageArray<T> data_;
  std::size_t size_;
};

class TopDown {
 public:
  TopDown(std::span<const AABB3f> boxes, const BuildOptions& options)
      : options_(options), refs_(boxes.size()), nodes_(2 * boxes.size()) {
    parallel_for_each_index(0, boxes.size(), [&](std::size_t i) {
      std::construct_at(&refs_[i], PrimRef{boxes[i], boxes[i].center(), std::uint32_t(i)});
    });
  }

  Topology run() {
    const auto n = std::uint32_t(refs_.size());
    std::uint32_t next = 0;  // one past the largest node id used
    const std::uint32_t root = build(0, n, bounds(0, n), 0, next);
    UntouchedArray<std::uint32_t> prims(n);
    parallel_for_each_index(0, n, [&](std::size_t i) { prims[i] = refs_[i].id; });
    return finalize({{nodes_.data(), next}, root, {prims.data(), n}, false}, options_.leaf_size,
                    options_.arity);
  }

 private:
  RangeBounds bounds(std::uint32_t begin, std::uint32_t end) const {
    auto scan = [&](std::uint32_t b, std::uint32_t e, RangeBounds r) {
      for (std::uint32_t i = b; i < e; ++i) {
        r.box.extend(refs_[i].box);
        r.centroid.extend(refs_[i].center);
      }
      return r;
    };
    if (end - begin < kParallelScan) return scan(begin, end, {});
    // min/max are exact, so the chunking does not change the result.
    return tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(begin, end, 16384), RangeBounds{},
        [&](const tbb::blocked_range<std::uint32_t>& r, RangeBounds acc) { return scan(r.begin(), r.end(), acc); },
        [](RangeBounds a, const RangeBounds& b) {
          a.join(b);
          return a;
        });
  }

  std::uint32_t make_leaf(std::uint32_t id, std::uint32_t begin, std::uint32_t end) {
    nodes_[id].prim_first = begin;
    nodes_[id].prim_count = end - begin;
    return id;
  }

  // The subtree of [begin, end), its nodes numbered from `next` on (advanced past them).
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, const RangeBounds& rb, int depth, std::uint32_t& next) {
    const std::uint32_t id = next++;
    BinaryNode& node = *std::construct_at(&nodes_[id]);
    node.box = rb.box;
    node.prim_count = end - begin;
    const std::uint32_t count = end - begin;
    if (count == 1) return make_leaf(id, begin, end);
    std::uint32_t mid = begin;
    bool leaf = options_.builder != Builder::sah && count <= std::uint32_t(options_.leaf_size);
    if (leaf) return make_leaf(id, begin, end);
    // The SAH split computes the bounds of both sides while it partitions.
    RangeBounds side[2];
    bool have_sides = false;
    switch (options_.builder) {
      case Builder::sah: mid = split_sah(begin, end, rb, leaf, side, have_sides); break;
      case Builder::pca: mid = split_pca(begin, end); break;
      case Builder::boxtree: mid = depth < 48 ? split_boxtree(begin, end, rb.box) : begin; break;
      default: break;
    }
    if (leaf) return make_leaf(id, begin, end);
    if (mid <= begin || mid >= end) {
      mid = split_median(begin, end, rb.centroid);
      have_sides = false;
    }
    std::uint32_t left = 0, right = 0;
    if (count >= kParallelThreshold && num_threads() > 1) {
      if (!have_sides)
        tbb::parallel_invoke([&] { side[0] = bounds(begin, mid); }, [&] { side[1] = bounds(mid, end); });
      std::uint32_t next_left = next, next_right = next + 2 * (mid - begin) - 1;
      tbb::parallel_invoke([&] { left = build(begin, mid, side[0], depth + 1, next_left); },
                           [&] { right = build(mid, end, side[1], depth + 1, next_right); });
      next = next_right;
    } else {
      if (!have_sides) side[0] = bounds(begin, mid), side[1] = bounds(mid, end);
      left = build(begin, mid, side[0], depth + 1, next);
      right = build(mid, end, side[1], depth + 1, next);
    }
    nodes_[id].left = left;
    nodes_[id].right = right;
    return id;
  }

  // Object median along the longest axis of the centroids, ties by id.
  std::uint32_t split_median(std::uint32_t begin, std::uint32_t end, const AABB3f& centroid) {
    const int axis = centroid.longest_axis();
    const std::uint32_t mid = begin + (end - begin) / 2;
    auto* p = refs_.data();
    std::nth_element(p + begin, p + mid, p + end, [&](const PrimRef& a, const PrimRef& b) {
      const float ca = a.center[axis], cb = b.center[axis];
      return ca < cb || (ca == cb && a.id < b.id);
    });
    return mid;
  }

  // Binned SAH: bins on all three axes, the sweep of §4.1.4 over bin
  // boundaries, cost (7) with unit traversal and intersection costs.
  std::uint32_t split_sah(std::uint32_t begin, std::uint32_t end, const RangeBounds& rb, bool& leaf,
                          RangeBounds side[2], bool& have_sides) {
    const std::uint32_t count = end - begin;
    // The wide AABB layout tests leaf triangles in groups of 4
    // (ray_triangle4.hpp): a leaf costs one test per started group.
    const bool grouped = options_.bv == BoundingVolume::aabb && options_.arity >= 4;
    auto leaf_tests = [&](std::uint32_t n) { return float(grouped ? (n + 3) / 4 : n); };
    // Then a leaf of up to 4 costs 1, and any split at least 1 (plus areas
    // times tests, never negative): the leaf, without binning.
    if (grouped && count <= std::min<std::uint32_t>(4, std::uint32_t(options_.leaf_size))) {
      leaf = true;
      return begin;
    }
    // Fewer bins than primitives would leave most of them empty.
    const int nbins = std::clamp<int>(int(count), 2, std::min<int>(options_.sah_bins, kMaxBins));
    // Bins of the doubled centers lo + hi (exactly twice the centers).
    const Vec3f extent = rb.centroid.extent();
    Float4 scale = {0, 0, 0, 0}, origin = {0, 0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      scale[a] = extent[a] > 0 ? float(nbins) * (1.0f - 1e-6f) / (2 * extent[a]) : 0.0f;
      origin[a] = 2 * rb.centroid.lo[a];
    }
    const Int4 last = {nbins - 1, nbins - 1, nbins - 1, nbins - 1}, zero = {0, 0, 0, 0};
    auto bins_of = [&](const PrimRef& r) {
      const Float4 lo = load4(r.box.lo.data()), hi = load4(r.box.hi.data());
      Int4 k = __builtin_convertvector((lo + hi - origin) * scale, Int4);
      k = k < zero ? zero : k;
      return k > last ? last : k;
    };
    auto fill = [&](std::uint32_t b, std::uint32_t e, Bins& bins) {
      for (std::uint32_t i = b; i < e; ++i) {
        const PrimRef& r = refs_[i];
        const Float4 lo = load4(r.box.lo.data()), hi = load4(r.box.hi.data());
        const Int4 k = bins_of(r);
        for (int a = 0; a < 3; ++a) {
          Bin& bin = bins.bin[a][k[a]];
          bin.lo = min4(bin.lo, lo);
          bin.hi = max4(bin.hi, hi);
          ++bin.n;
        }
      }
    };
    Bins bins(nbins);
    if (count < kParallelScan) {
      fill(begin, end, bins);
    } else {
      bins = tbb::parallel_reduce(
          tbb::blocked_range<std::uint32_t>(begin, end, 16384), bins,
          [&](const tbb::blocked_range<std::uint32_t>& r, Bins acc) {
            fill(r.begin(), r.end(), acc);
            return acc;
          },
          [](Bins a, const Bins& b) {
            a.join(b);
            return a;
          });
    }
    const float parent_area = rb.box.surface_area();
    float best_cost = std::numeric_limits<float>::infinity();
    int best_axis = -1, best_bin = -1;
    // The costs of all axes first, the three side by side (independent
    // dependency chains), then the least in axis-major order (the first least
    // wins, as when each axis was swept and compared in turn).
    const float inf = std::numeric_limits<float>::infinity();
    float right_cost[3][kMaxBins], cost[3][kMaxBins];
    Bin acc[3];
    for (Bin& b : acc) b.reset();
    for (int k = nbins - 1; k > 0; --k)
      for (int a = 0; a < 3; ++a) {
        acc[a].extend(bins.bin[a][k]);
        right_cost[a][k] = acc[a].area() * leaf_tests(acc[a].n);
      }
    for (Bin& b : acc) b.reset();
    for (int k = 0; k < nbins - 1; ++k)
      for (int a = 0; a < 3; ++a) {
        acc[a].extend(bins.bin[a][k]);
        const bool split = acc[a].n != 0 && acc[a].n != count;
        cost[a][k] = split ? acc[a].area() * leaf_tests(acc[a].n) + right_cost[a][k + 1] : inf;
      }
    for (int a = 0; a < 3; ++a) {
      if (scale[a] == 0) continue;
      for (int k = 0; k < nbins - 1; ++k)
        if (cost[a][k] < best_cost) best_cost = cost[a][k], best_axis = a, best_bin = k;
    }
    const float leaf_cost = leaf_tests(count);
    const float split_cost =
        best_axis < 0 ? std::numeric_limits<float>::infinity() : 1.0f + best_cost / std::max(parent_area, 1e-30f);
    if (count <= std::uint32_t(options_.leaf_size) && leaf_cost <= split_cost) {
      leaf = true;
      return begin;
    }
    if (best_axis < 0) return begin;  // all centroids equal: median split by id
    // The boxes of both sides are the unions of their bins.
    Bin box[2];
    box[0].reset(), box[1].reset();
    for (int k = 0; k < nbins; ++k) box[k <= best_bin ? 0 : 1].extend(bins.bin[best_axis][k]);
    for (int s = 0; s < 2; ++s)
      for (int a = 0; a < 3; ++a) side[s].box.lo[a] = box[s].lo[a], side[s].box.hi[a] = box[s].hi[a];
    have_sides = true;
    // bins_of(r)[best_axis] <= best_bin, without the clamps (they never move a
    // bin across best_bin) and without picking a lane: the others' limits are
    // never exceeded.
    Int4 limit = {INT32_MAX, INT32_MAX, INT32_MAX, INT32_MAX};
    limit[best_axis] = best_bin;
    return partition(begin, end, [&](const PrimRef& r) {
      const Float4 lo = load4(r.box.lo.data()), hi = load4(r.box.hi.data());
      return !any4(__builtin_convertvector((lo + hi - origin) * scale, Int4) > limit);
    }, side);
  }

  // std::partition's result (libstdc++'s bidirectional algorithm: the same
  // order, so the same tree as before) and the centroid boxes of both sides,
  // without data-dependent branches. That algorithm swaps the j-th
  // right-going primitive of [begin, mid), counted from the left, with the
  // j-th left-going one of [mid, end), counted from the right, and moves
  // nothing else. So: the sides as bits, 64 to a word, then the pairs.
  template <typename IsLeft>
  std::uint32_t partition(std::uint32_t begin, std::uint32_t end, const IsLeft& is_left, RangeBounds side[2]) {
    const std::uint32_t count = end - begin, words = (count + 63) / 64;
    thread_local std::vector<std::uint64_t> left_bits;
    if (left_bits.size() < words) left_bits.resize(words);
    std::uint64_t* bits = left_bits.data();
    const float inf = std::numeric_limits<float>::infinity();
    const Float4 pos = {inf, inf, inf, inf}, neg = -pos;
    // Two sets of accumulators, for even and odd primitives: their min/max chains overlap.
    Float4 lo0 = pos, hi0 = neg, lo1 = pos, hi1 = neg, lo2 = pos, hi2 = neg, lo3 = pos, hi3 = neg;
    auto add = [&](const PrimRef& r, bool l, Float4& llo, Float4& lhi, Float4& rlo, Float4& rhi) {
      const Int4 m = -Int4{l, l, l, l};
      const Float4 c = load4(r.center.data());
      llo = min4(llo, m ? c : pos), lhi = max4(lhi, m ? c : neg);
      rlo = min4(rlo, m ? pos : c), rhi = max4(rhi, m ? neg : c);
    };
    std::uint32_t left_count = 0;
    const PrimRef* p = refs_.data() + begin;
    for (std::uint32_t w = 0; w < words; ++w) {
      const std::uint32_t n = std::min<std::uint32_t>(64, count - 64 * w);
      const PrimRef* r = p + 64 * w;
      std::uint64_t word = 0;
      std::uint32_t j = 0;
      for (; j + 1 < n; j += 2) {
        const bool l0 = is_left(r[j]), l1 = is_left(r[j + 1]);
        word |= (std::uint64_t(l0) | std::uint64_t(l1) << 1) << j;
        add(r[j], l0, lo0, hi0, lo1, hi1);
        add(r[j + 1], l1, lo2, hi2, lo3, hi3);
      }
      if (j < n) {
        const bool l0 = is_left(r[j]);
        word |= std::uint64_t(l0) << j;
        add(r[j], l0, lo0, hi0, lo1, hi1);
      }
      bits[w] = word;
      left_count += std::uint32_t(__builtin_popcountll(word));
    }
    const Float4 lo[2] = {min4(lo0, lo2), min4(lo1, lo3)}, hi[2] = {max4(hi0, hi2), max4(hi1, hi3)};
    for (int s = 0; s < 2; ++s)
      for (int a = 0; a < 3; ++a) side[s].centroid.lo[a] = lo[s][a], side[s].centroid.hi[a] = hi[s][a];
    // Right-going ones below mid (front, upwards) and left-going ones from mid on (back, downwards).
    const std::uint32_t mid = left_count;
    std::uint32_t swaps = 0;
    for (std::uint32_t w = 0; 64 * w < mid; ++w) {
      const std::uint32_t n = std::min<std::uint32_t>(64, mid - 64 * w);
      const std::uint64_t valid = n == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1;
      swaps += std::uint32_t(__builtin_popcountll(~bits[w] & valid));
    }
    auto front_bits = [&](std::uint32_t w) {
      const std::uint32_t n = std::min<std::uint32_t>(64, mid - 64 * w);
      return ~bits[w] & (n == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1);
    };
    auto back_bits = [&](std::uint32_t w) {
      return 64 * w >= mid ? bits[w] : bits[w] & ~((std::uint64_t(1) << (mid - 64 * w)) - 1);
    };
    PrimRef* q = refs_.data() + begin;
    std::uint32_t fw = 0, bw = words - 1;
    std::uint64_t front = swaps ? front_bits(0) : 0, back = swaps ? back_bits(bw) : 0;
    for (std::uint32_t k = 0; k < swaps; ++k) {
      while (front == 0) front = front_bits(++fw);
      while (back == 0) back = back_bits(--bw);
      const std::uint32_t i = 64 * fw + std::uint32_t(__builtin_ctzll(front));
      const int top = 63 - __builtin_clzll(back);
      const std::uint32_t j = 64 * bw + std::uint32_t(top);
      front &= front - 1;
      back &= ~(std::uint64_t(1) << top);
      std::swap(q[i], q[j]);
    }
    return begin + mid;
  }

  // Plane through the barycenter of the centroids, orthogonal to their
  // principal axis (§4.1.4, after Gottschalk et al.).
  std::uint32_t split_pca(std::uint32_t begin, std::uint32_t end) {
    Vec3d mean = Vec3d::Zero();
    for (std::uint32_t i = begin; i < end; ++i) mean += refs_[i].center.cast<double>();
    mean /= double(end - begin);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::uint32_t i = begin; i < end; ++i) {
      const Vec3d d = refs_[i].center.cast<double>() - mean;
      cov += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
    if (solver.info() != Eigen::Success) return begin;
    const Vec3d axis = solver.eigenvectors().col(2);
    auto* p = refs_.data();
    return std::uint32_t(std::partition(p + begin, p + end, [&](const PrimRef& r) {
                           return (r.center.cast<double>() - mean).dot(axis) < 0;
                         }) - p);
  }

  // Area of the box's section orthogonal to `axis`; flat sides count as a
  // tiny fraction of the largest extent so that flat boxes still compare.
  static double cross_section(const AABB3f& box, int axis) {
    const Vec3d e = box.extent().cast<double>();
    const double floor = 1e-6 * std::max(e.maxCoeff(), 1e-30);
    return std::max(e[(axis + 1) % 3], floor) * std::max(e[(axis + 2) % 3], floor);
  }

  // Restricted boxtree (§4.1.5): each child is the parent box cut by one
  // plane, a "lower" box [lo, m] or an "upper" box [m, hi] along the axis, so
  // a child's volume is proportional to its length along the axis. For each
  // axis and each pairing (lower+upper, lower+lower, upper+upper) two seeds
  // nearest the outer borders start the subsets; every other primitive joins
  // the subset whose volume grows least, visiting the array alternately from
  // the front and the back. The split with the least total volume wins.
  std::uint32_t split_boxtree(std::uint32_t begin, std::uint32_t end, const AABB3f& parent) {
    const std::uint32_t count = end - begin;
    std::vector<std::uint8_t> side(count), best_side;
    double best_total = std::numeric_limits<double>::infinity();
    const PrimRef* p = refs_.data() + begin;
    for (int a = 0; a < 3; ++a) {
      const double plo = parent.lo[a], phi = parent.hi[a];
      if (!(phi > plo)) continue;
      for (int pairing = 0; pairing < 3; ++pairing) {
        // upper[s]: subset s forms an upper box.
        const bool upper[2] = {pairing == 2, pairing >= 1};
        // Seeds: a lower box is seeded by the primitive reaching least far up,
        // an upper box by the one reaching least far down.
        std::uint32_t seed[2] = {count, count};
        for (int s = 0; s < 2; ++s) {
          double best = std::numeric_limits<double>::infinity();
          for (std::uint32_t i = 0; i < count; ++i) {
            if (s == 1 && i == seed[0]) continue;
            const double key = upper[s] ? -double(p[i].box.lo[a]) : double(p[i].box.hi[a]);
            if (key < best) best = key, seed[s] = i;
          }
        }
        double reach[2];  // lower box: its top; upper box: its bottom
        for (int s = 0; s < 2; ++s) {
          const AABB3f& b = p[seed[s]].box;
          reach[s] = upper[s] ? b.lo[a] : b.hi[a];
          side[seed[s]] = std::uint8_t(s);
        }
        std::uint32_t size[2] = {1, 1};
        auto length = [&](int s, double r) { return upper[s] ? phi - r : r - plo; };
        for (std::uint32_t k = 0; k < count; ++k) {
          const std::uint32_t i = (k % 2 == 0) ? k / 2 : count - 1 - k / 2;
          if (i == seed[0] || i == seed[1]) continue;
          const AABB3f& b = p[i].box;
          double grown[2], increase[2];
          for (int s = 0; s < 2; ++s) {
            grown[s] = upper[s] ? std::min(reach[s], double(b.lo[a])) : std::max(reach[s], double(b.hi[a]));
            increase[s] = length(s, grown[s]) - length(s, reach[s]);
          }
          const int s = increase[0] < increase[1] ? 0 : increase[1] < increase[0] ? 1 : (size[0] <= size[1] ? 0 : 1);
          reach[s] = grown[s];
          side[i] = std::uint8_t(s);
          ++size[s];
        }
        const double total = (length(0, reach[0]) + length(1, reach[1])) * cross_section(parent, a);
        if (total < best_total) best_total = total, best_side = side;
      }
    }
    if (best_side.empty()) return begin;
    // Stable partition of the ids by the chosen sides.
    const std::vector<PrimRef> ids(p, p + count);
    PrimRef* out = refs_.data() + begin;
    std::uint32_t n0 = 0;
    for (std::uint32_t i = 0; i < count; ++i)
      if (best_side[i] == 0) out[n0++] = ids[i];
    std::uint32_t n1 = n0;
    for (std::uint32_t i = 0; i < count; ++i)
      if (best_side[i] == 1) out[n1++] = ids[i];
    return begin + n0;
  }

  const BuildOptions& options_;
  // The primitives move with the partitions, so every scan reads them in order.
  UntouchedArray<PrimRef> refs_;
  UntouchedArray<BinaryNode> nodes_;
};

}  // namespace

Topology build_top_down(std::span<const AABB3f> boxes, const BuildOptions& options) {
  return TopDown(boxes, options).run();
}

}  // namespace geods::bvh::detail
