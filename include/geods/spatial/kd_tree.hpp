#pragma once
// Balanced k-d tree (seed §2.2, Theorem 4): built in O(n log n) by median splits,
// O(n) space, axis-parallel range queries in O(n^(1-1/d) + a); exact and (1+eps)
// approximate k-nearest neighbours, radius search, batch queries in parallel.
//
// Layout: a flat array of nodes in depth-first order (the left child of node i is
// i + 1, the right child is stored) with 32-bit indices, and a permutation of the
// point indices so that every node owns a contiguous range of it. The points stay
// in the caller's array (PointView) or in one the tree owns; by default
// (PointLayout::tree_order) the tree also keeps a copy of them in leaf order,
// which the queries read contiguously (PointLayout::zero_copy: no copy); with
// a dimension fixed at compile time (up to 4) that copy is the packed layout
// (see "packed tree order" below: inner nodes only, leaf points in SIMD
// groups). The node array and the permutation are FlatArrays: a tree loaded from a file (load())
// reads them, and its points, in place from the mapped file.
//
// Split rule: each node splits its points at the median (select_nth) along
// the axis of widest spread of those points. Median splits bound the depth by
// ceil(log2(n / leaf_size)) whatever the distribution; the widest-spread axis
// (rather than cycling axes) keeps cells from becoming slivers on clustered and
// degenerate sets (all points on a line or a plane). Each inner node stores the
// largest coordinate of its left points and the smallest of its right points on
// the split axis, so empty space between them is pruned too (as in nanoflann).
//
// Searches: k-NN and radius search are one depth-first descent (descend) with
// a small policy each (the bound that prunes, what happens to a leaf point);
// box queries have their own descent over the cells. Every query takes an
// optional filter of points to skip (point_filter.hpp; the dynamic k-d tree
// hides its deleted points this way). kd_tree_stepped_build.hpp builds the
// same tree in pauses.
#include <tbb/parallel_invoke.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/vec.hpp"
#include "geods/spatial/knn_result.hpp"
#include "geods/spatial/permutation.hpp"
#include "geods/spatial/point_filter.hpp"
#include "geods/spatial/point_view.hpp"

namespace geods::spatial {

/// The dimension template argument for a dimension known only at run time (as in Eigen).
inline constexpr int Dynamic = -1;

/// How a k-d tree reads its points in k-NN and radius queries.
enum class PointLayout : std::uint8_t {
  /// The default: the tree keeps a copy of the points in leaf order, so a
  /// leaf's points are read contiguously: for a dimension fixed at compile
  /// time up to 4, the packed layout (groups of 4 points axis by axis with
  /// their indices, and 16-byte inner nodes for float: about 1.2 * (dim + 1)
  /// values per point), else size() * dim() values. Queries are about 1.5-2x faster
  /// on large inputs.
  tree_order,
  /// No copy: the points are read in place, through the permutation, from the
  /// caller's array (or the tree's own, or a mapped file). Half the memory.
  zero_copy,
};
inline std::string_view to_string(PointLayout layout) {
  return layout == PointLayout::tree_order ? "tree_order" : "zero_copy";
}
/// "tree_order" or "zero_copy"; throws geods::Error for any other name.
inline PointLayout parse_point_layout(std::string_view name) {
  if (name == "tree_order") return PointLayout::tree_order;
  if (name == "zero_copy") return PointLayout::zero_copy;
  throw Error("unknown point layout '" + std::string(name) + "' (tree_order or zero_copy)");
}

/// The archive kind and layout version of a saved k-d tree (KdTree::save).
inline constexpr std::string_view kKdTreeArchiveKind = "spatial.KdTree";
inline constexpr std::uint32_t kKdTreeArchiveVersion = 1;

/// What a saved k-d tree holds, to pick the tree type before loading it.
struct KdTreeFileInfo {
  DType scalar;     // f32 or f64
  std::size_t dim;  // coordinates per point
};
/// Reads the scalar type and dimension of the k-d tree saved at `path` (reads
/// only the header and section table). Throws geods::Error naming the file.
inline KdTreeFileInfo read_kd_tree_info(const std::filesystem::path& path) {
  const Archive a = Archive::open(path, kKdTreeArchiveKind, kKdTreeArchiveVersion, Archive::Verify::structure_only);
  return {a.dtype("scalar"), std::size_t(a.value<std::uint64_t>("dim"))};
}

struct KdTreeStats {
  std::size_t points = 0;
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  std::size_t depth = 0;  // edges on the longest root-to-leaf path
  std::size_t bytes = 0;  // nodes, permutation and owned points
};

template <typename T, int Dim>
class KdTreeSteppedBuild;

template <typename T, int Dim = Dynamic>
class KdTree {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "KdTree<T>: T is float or double");
  static_assert(Dim == Dynamic || Dim >= 1, "KdTree<T, Dim>: Dim >= 1 or Dynamic");

 public:
  using Scalar = T;
  static constexpr int kDim = Dim;
  static constexpr std::size_t kDefaultLeafSize = 10;

  struct Node {
    std::uint32_t begin, end;  // the node's points are permutation()[begin, end)
    std::uint32_t right;       // inner node: index of the right child; 0 marks a leaf
    std::uint32_t axis;        // inner node: split axis
    T low, high;               // inner node: max on `axis` over the left points, min over the right ones
    bool leaf() const { return right == 0; }
  };

  /// An empty tree (queries return nothing).
  KdTree() = default;

  /// Builds over the caller's points, which must outlive the tree, unchanged
  /// (point(i) reads them; with PointLayout::zero_copy the queries do too; the
  /// default, tree_order, also keeps a copy in leaf order for the queries).
  /// Throws geods::Error for NaN/inf coordinates, a dimension other than Dim,
  /// leaf_size 0 or 2^32 - 1 points or more.
  explicit KdTree(PointView<T> points, std::size_t leaf_size = kDefaultLeafSize,
                  PointLayout layout = PointLayout::tree_order)
      : view_(points) {
    build(leaf_size, layout);
  }

  /// Builds over points the tree owns: `coordinates` holds n * dim values, row by row.
  KdTree(std::vector<T> coordinates, std::size_t dim, std::size_t leaf_size = kDefaultLeafSize,
         PointLayout layout = PointLayout::tree_order) {
    if (dim == 0 || coordinates.size() % dim != 0)
      throw Error("KdTree: " + std::to_string(coordinates.size()) + " coordinates are not rows of dimension " +
                  std::to_string(dim));
    adopt(std::move(coordinates), dim);
    build(leaf_size, layout);
  }

  // ---------------------------------------------------------------- accessors
  std::size_t size() const { return view_.count; }
  bool empty() const { return view_.count == 0; }
  std::size_t dim() const { return Dim == Dynamic ? view_.dim : std::size_t(Dim); }
  std::size_t leaf_size() const { return leaf_size_; }
  /// Coordinates of point i (its index in the input).
  const T* point(std::size_t i) const { return view_[i]; }
  PointView<T> points() const { return view_; }
  const FlatArray<Node>& nodes() const { return nodes_; }
  /// Point indices in tree order: node v owns permutation()[v.begin, v.end).
  const FlatArray<std::uint32_t>& permutation() const { return perm_; }

  /// Turns a zero-copy tree (PointLayout::zero_copy, a loaded one, a stepped
  /// build's) into a tree_order one: makes the copy of the points in leaf order
  /// (size() * dim() values, shared by copies of the tree) that k-NN and radius
  /// queries then read contiguously instead of through the permutation. Results
  /// are identical. Does nothing if the tree has the copy.
  void store_points_in_tree_order() {
    if (stores_points_in_tree_order() || empty()) return;
    if (packs()) {
      packed_ = make_packed([this](std::size_t i) { return point(perm_[i]); });
      return;
    }
    auto ordered = std::make_shared_for_overwrite<T[]>(perm_.size() * dim());
    T* out = ordered.get();
    parallel_for(0, perm_.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) std::copy_n(point(perm_[i]), dim(), out + i * dim());
    });
    ordered_ = std::move(ordered);
  }
  bool stores_points_in_tree_order() const { return ordered_ != nullptr || packed_ != nullptr; }
  /// tree_order when the tree keeps the copy of its points in leaf order, else zero_copy.
  PointLayout layout() const {
    return stores_points_in_tree_order() || empty() ? PointLayout::tree_order : PointLayout::zero_copy;
  }
  /// Bounding box of all points (empty vectors for an empty tree).
  const std::vector<T>& bounds_lo() const { return root_lo_; }
  const std::vector<T>& bounds_hi() const { return root_hi_; }

  // ---------------------------------------------------------------- k nearest neighbours
  /// The request.k nearest points to `query`, sorted by distance, ties by index;
  /// fewer if the tree holds fewer or request.max_distance excludes them. Points
  /// for which skip(index) is true are left out (see point_filter.hpp).
  /// Cost: O(log n) expected for uniform data and small k.
  template <typename Skip = KeepAll>
  std::vector<Neighbor<T>> query(std::span<const T> query, const KnnRequest& request, const Skip& skip = {}) const {
    std::vector<Neighbor<T>> out(check_request(request, "KdTree::query"));
    out.resize(query_into(query, request, out.data(), skip));
    return out;
  }
  std::vector<Neighbor<T>> query(std::span<const T> q, std::size_t k, double eps = 0) const {
    return query(q, KnnRequest{k, eps});
  }
  std::vector<Neighbor<T>> query(const Vec<T, Dim>& q, std::size_t k, double eps = 0) const
    requires(Dim != Dynamic)
  {
    return query(std::span<const T>(q.data(), Dim), KnnRequest{k, eps});
  }

  /// Allocation-free form: writes exactly request.k slots to `out` (unused ones
  /// are {kNoIndex, +inf}) and returns how many neighbours were found.
  template <typename Skip = KeepAll>
  std::size_t query_into(std::span<const T> query, const KnnRequest& request, Neighbor<T>* out,
                         const Skip& skip = {}) const {
    const std::size_t k = check_request(request, "KdTree::query");
    check_point(query, "query point");
    check_query_range<2>(query, "KdTree");
    KnnResultSet<T> result(out, k, squared_limit<T>(request.max_distance));
    search_nearest(query.data(), result, request.eps, skip);
    result.finish();
    return result.size();
  }

  /// Every point within Euclidean distance `radius` of `query` (inclusive) that
  /// skip does not hide, sorted by distance, ties by index.
  template <typename Skip = KeepAll>
  std::vector<Neighbor<T>> query_radius(std::span<const T> query, double radius, const Skip& skip = {}) const {
    check_point(query, "query point");
    check_query_range<2>(query, "KdTree");
    if (!(radius >= 0)) throw Error("KdTree::query_radius: radius must be >= 0, got " + format_number(radius));
    std::vector<Neighbor<T>> out;
    search_radius(query.data(), squared_limit<T>(radius), [&](std::uint32_t i, T d) { out.push_back({i, d}); }, skip);
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<Neighbor<T>> query_radius(const Vec<T, Dim>& q, double radius) const
    requires(Dim != Dynamic)
  {
    return query_radius(std::span<const T>(q.data(), Dim), radius);
  }

  // ---------------------------------------------------------------- the searches the queries are made of
  // For callers that merge the answers of several trees (DynamicKdTree shares
  // one k-best list across its blocks). `q` points to dim() finite values (not
  // checked here); points for which skip(index) is true are not visited.

  /// Feeds result.insert(index, squared distance) the points that may improve
  /// `result`: result.worst() is the squared distance a point must not exceed,
  /// result.full() says whether k points are found (until then eps does not
  /// shrink the search). KnnResultSet is such a result; query_into is this search.
  template <typename Result, typename Skip = KeepAll>
  void search_nearest(const T* q, Result& result, double eps = 0, const Skip& skip = {}) const {
    // A subtree is visited while its lower bound is <= worst * factor: the slack keeps
    // exact ties from being pruned by rounding in the incremental distance, and
    // 1/(1+eps)^2 turns the search approximate.
    struct Nearest {
      Result& result;
      T slack, approx;
      T limit() const { return result.worst(); }
      T bound() const { return result.worst() * (result.full() ? approx : slack); }
      void report(std::uint32_t index, T d) const { result.insert(index, d); }
    } search{result, slack(), slack() / T((1 + eps) * (1 + eps))};
    descend(q, search, skip);
  }

  /// Calls f(index, squared distance) for every point within squared distance r2 of q, in no particular order.
  template <typename F, typename Skip = KeepAll>
  void search_radius(const T* q, T r2, const F& f, const Skip& skip = {}) const {
    struct Within {
      const F& f;
      T r2, bound_;
      T limit() const { return r2; }
      T bound() const { return bound_; }
      void report(std::uint32_t index, T d) const { f(index, d); }
    } search{f, r2, r2 * slack()};
    descend(q, search, skip);
  }

  /// Calls f(index) for every point p with lo <= p <= hi on every axis, in tree order.
  template <typename F, typename Skip = KeepAll>
  void search_box(const T* lo, const T* hi, const F& f, const Skip& skip = {}) const {
    struct Each {
      const KdTree& tree;
      const F& f;
      void range(std::uint32_t begin, std::uint32_t end) const {
        for (std::uint32_t i = begin; i < end; ++i) f(tree.perm_[i]);
      }
      void point(std::uint32_t index) const { f(index); }
    } visit{*this, f};
    box(lo, hi, visit, skip);
  }

  // ---------------------------------------------------------------- box range
  /// Indices of the points p with lo <= p <= hi on every axis (closed box), in
  /// tree order, without those skip hides. Subtrees whose cell lies inside the
  /// box are reported without visiting their nodes: O(sqrt(n) + a) in 2D
  /// (Theorem 4). `visited`, if given, is increased by the number of nodes visited.
  template <typename Skip = KeepAll>
  std::vector<std::uint32_t> query_box(std::span<const T> lo, std::span<const T> hi, std::size_t* visited = nullptr,
                                       const Skip& skip = {}) const {
    check_box(lo, hi);
    struct Report {
      const KdTree& tree;
      std::vector<std::uint32_t> out;
      void range(std::uint32_t begin, std::uint32_t end) {
        out.insert(out.end(), tree.perm_.begin() + begin, tree.perm_.begin() + end);
      }
      void point(std::uint32_t index) { out.push_back(index); }
    } report{*this, {}};
    const std::size_t nodes = box(lo.data(), hi.data(), report, skip);
    if (visited) *visited += nodes;
    return std::move(report.out);
  }
  /// How many points lie in the closed box; whole subtrees inside the box count
  /// in O(1) each (without a filter), so this is O(sqrt(n)) in 2D whatever the answer.
  template <typename Skip = KeepAll>
  std::size_t count_box(std::span<const T> lo, std::span<const T> hi, std::size_t* visited = nullptr,
                        const Skip& skip = {}) const {
    check_box(lo, hi);
    struct Count {
      std::size_t count = 0;
      void range(std::uint32_t begin, std::uint32_t end) { count += end - begin; }
      void point(std::uint32_t) { ++count; }
    } counter;
    const std::size_t nodes = box(lo.data(), hi.data(), counter, skip);
    if (visited) *visited += nodes;
    return counter.count;
  }
  std::vector<std::uint32_t> query_box(const AABB<T, Dim>& box) const
    requires(Dim != Dynamic)
  {
    return query_box(std::span<const T>(box.lo.data(), Dim), std::span<const T>(box.hi.data(), Dim));
  }
  std::size_t count_box(const AABB<T, Dim>& box) const
    requires(Dim != Dynamic)
  {
    return count_box(std::span<const T>(box.lo.data(), Dim), std::span<const T>(box.hi.data(), Dim));
  }

  // ---------------------------------------------------------------- batches (parallel over queries)
  /// request.k slots per query, query i at [i * k, (i + 1) * k); missing ones are {kNoIndex, +inf}.
  std::vector<Neighbor<T>> query_batch(PointView<T> queries, const KnnRequest& request) const {
    const std::size_t k = check_request(request, "KdTree::query");
    check_batch(queries, dim(), "queries");
    std::vector<Neighbor<T>> out(queries.count * k);
    parallel_for(0, queries.count, 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) query_into(std::span<const T>(queries[i], dim()), request, out.data() + i * k);
    });
    return out;
  }
  std::vector<std::vector<Neighbor<T>>> query_radius_batch(PointView<T> queries, double radius) const {
    check_batch(queries, dim(), "queries");
    std::vector<std::vector<Neighbor<T>>> out(queries.count);
    parallel_for(0, queries.count, 16, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) out[i] = query_radius(std::span<const T>(queries[i], dim()), radius);
    });
    return out;
  }
  /// Each row of `boxes` holds 2 * dim values: the low corner, then the high corner.
  std::vector<std::size_t> count_box_batch(PointView<T> boxes) const {
    check_batch(boxes, 2 * dim(), "boxes");
    std::vector<std::size_t> out(boxes.count);
    parallel_for(0, boxes.count, 16, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) out[i] = count_box(std::span<const T>(boxes[i], dim()), std::span<const T>(boxes[i] + dim(), dim()));
    });
    return out;
  }

  // ---------------------------------------------------------------- inspection
  /// Bytes held: nodes, permutation, owned points and their copy in tree order; O(1).
  std::size_t bytes() const {
    return nodes_.size() * sizeof(Node) + perm_.size() * sizeof(std::uint32_t) +
           (owned_ ? owned_->size() * sizeof(T) : 0) + (ordered_ ? size() * dim() * sizeof(T) : 0) +
           (packed_ ? packed_->nodes.size() * sizeof(PackedNode) + packed_->groups.size() * sizeof(Group) : 0) +
           2 * root_lo_.size() * sizeof(T);
  }

  KdTreeStats stats() const {
    KdTreeStats s;
    s.points = size();
    s.nodes = nodes_.size();
    s.bytes = bytes();
    std::vector<std::pair<std::uint32_t, std::size_t>> stack;
    if (!nodes_.empty()) stack.push_back({0, 0});
    while (!stack.empty()) {
      const auto [v, depth] = stack.back();
      stack.pop_back();
      s.depth = std::max(s.depth, depth);
      if (nodes_[v].leaf()) {
        ++s.leaves;
      } else {
        stack.push_back({v + 1, depth + 1});
        stack.push_back({nodes_[v].right, depth + 1});
      }
    }
    return s;
  }

  /// Checks every invariant; throws geods::Error naming the first violation:
  /// the permutation is a permutation; nodes form a tree in depth-first order
  /// whose children split their parent's range at its middle (balance); leaves
  /// hold 1..leaf_size points; low <= high; every point lies in the cell of its
  /// leaf (the root box cut by the low/high values on the path), so no split
  /// lies, and is finite; the copy in tree order, if any, holds the points.
  void validate() const {
    const std::size_t n = size();
    auto fail = [](const std::string& what) { throw Error("KdTree::validate: " + what); };
    require_permutation(perm_, n, "KdTree::validate");
    if (n == 0) {
      if (!nodes_.empty()) fail("nodes without points");
      return;
    }
    if (nodes_.empty()) fail("points without nodes");
    if (root_lo_.size() != dim() || root_hi_.size() != dim()) fail("root box has the wrong dimension");
    struct Item {
      std::uint32_t node;
      std::vector<T> lo, hi;
    };
    std::vector<Item> stack{{0, root_lo_, root_hi_}};
    std::size_t visited = 0, covered = 0;
    while (!stack.empty()) {
      Item item = std::move(stack.back());
      stack.pop_back();
      if (++visited > nodes_.size()) fail("node graph is not a tree");
      const Node& node = nodes_[item.node];
      const std::string where = "node " + std::to_string(item.node) + ": ";
      if (node.begin >= node.end || node.end > n) fail(where + "bad point range");
      if (node.leaf()) {
        if (node.end - node.begin > leaf_size_) fail(where + "leaf holds more than leaf_size points");
        if (node.begin != covered) fail(where + "leaves do not cover the permutation in order");
        covered = node.end;
        for (std::uint32_t i = node.begin; i < node.end; ++i) {
          const T* p = point(perm_[i]);
          for (std::size_t a = 0; a < dim(); ++a)
            if (!(std::isfinite(p[a]) && p[a] >= item.lo[a] && p[a] <= item.hi[a]))
              fail(where + "point " + std::to_string(perm_[i]) + " is not finite or lies outside its leaf's cell");
        }
        continue;
      }
      if (node.end - node.begin <= leaf_size_) fail(where + "inner node small enough to be a leaf");
      if (node.axis >= dim()) fail(where + "bad split axis");
      if (std::size_t(item.node) + 1 >= nodes_.size() || node.right <= item.node + 1 || node.right >= nodes_.size())
        fail(where + "bad child index");
      const Node& left = nodes_[item.node + 1];
      const Node& right = nodes_[node.right];
      const std::uint32_t mid = node.begin + (node.end - node.begin) / 2;
      if (left.begin != node.begin || left.end != mid || right.begin != mid || right.end != node.end)
        fail(where + "children do not split the range at its middle");
      if (!(node.low <= node.high)) fail(where + "low > high");
      Item l{item.node + 1, item.lo, item.hi}, r{node.right, std::move(item.lo), std::move(item.hi)};
      l.hi[node.axis] = node.low;
      r.lo[node.axis] = node.high;
      stack.push_back(std::move(r));
      stack.push_back(std::move(l));  // left first: leaves come out in permutation order
    }
    if (visited != nodes_.size()) fail("unreachable nodes");
    if (covered != n) fail("leaves do not cover all points");
    if (ordered_) {
      for (std::size_t i = 0; i < n; ++i)
        if (!std::equal(point(perm_[i]), point(perm_[i]) + dim(), ordered_.get() + i * dim()))
          fail("points in tree order differ from the points");
    }
    if (packed_) {
      std::uint32_t next_node = 0, next_group = 0;
      if (!validate_packed(0, next_node, next_group) || next_node != packed_->nodes.size() ||
          next_group != packed_->groups.size())
        fail("points in tree order differ from the tree and its points");
    }
  }

  // ---------------------------------------------------------------- archive sections
  /// Adds the tree to an archive (core/archive.hpp) as sections whose names
  /// start with `prefix`, so that one archive can hold several trees (the
  /// blocks of a DynamicKdTree): leaf_size, bounds_lo, bounds_hi, nodes,
  /// permutation, points (n x dim, row-major, in input order). The arrays are
  /// not copied: the tree must live until w.write(). Its points must be packed
  /// (stride = dim, as in a tree that owns them; save() packs a strided view).
  void add_sections(ArchiveWriter& w, const std::string& prefix) const {
    if (view_.stride != view_.dim && size() > 1) throw Error("KdTree::add_sections: strided points");
    add_sections(w, prefix, std::span<const T>(view_.data, size() * dim()));
  }

  /// The tree add_sections wrote under `prefix`, of dimension `dim`. Its nodes,
  /// permutation and points are read in place from the mapped file (no parse,
  /// no copy), which stays mapped while the tree or a copy of it lives. Throws
  /// geods::Error naming the file for another dimension, missing or
  /// inconsistent sections or contents that fail validate().
  static KdTree from_sections(const Archive& a, const std::string& prefix, std::size_t dim) {
    if ((Dim != Dynamic && dim != std::size_t(Dim)) || dim > (1u << 16))
      throw a.error("a k-d tree of dimension " + std::to_string(dim) + ", expected " +
                    (Dim == Dynamic ? std::string("at most 65536") : std::to_string(Dim)));
    const std::uint64_t leaf_size = a.value<std::uint64_t>(prefix + "leaf_size");
    if (leaf_size == 0 || leaf_size > std::numeric_limits<std::uint32_t>::max())
      throw a.error("bad k-d tree leaf size " + std::to_string(leaf_size));
    auto points = std::make_shared<const FlatArray<T>>(a.array<T>(prefix + "points"));
    if (dim == 0 ? !points->empty() : points->size() % dim != 0)
      throw a.error(std::to_string(points->size()) + " coordinates are not rows of dimension " + std::to_string(dim));
    const std::size_t n = dim == 0 ? 0 : points->size() / dim;
    if (n >= std::numeric_limits<std::uint32_t>::max()) throw a.error("too many points for a k-d tree");
    KdTree tree;
    tree.leaf_size_ = std::size_t(leaf_size);
    tree.view_ = PointView<T>(points->data(), n, dim);
    tree.owned_ = std::move(points);
    tree.nodes_ = a.array<Node>(prefix + "nodes");
    tree.perm_ = a.array<std::uint32_t>(prefix + "permutation", n);
    tree.root_lo_ = a.array<T>(prefix + "bounds_lo", n > 0 ? dim : 0).to_vector();
    tree.root_hi_ = a.array<T>(prefix + "bounds_hi", n > 0 ? dim : 0).to_vector();
    try {
      tree.validate();
      // The range of build(), on the root box that validate() found to hold every point.
      std::vector<T> corners = tree.root_lo_;
      corners.insert(corners.end(), tree.root_hi_.begin(), tree.root_hi_.end());
      check_coordinate_range(corners.data(), n > 0 ? 2 : 0, dim, dim, 2, "KdTree");
    } catch (const Error& e) {
      throw a.error(std::string("corrupted k-d tree: ") + e.what());
    }
    return tree;
  }

  // ---------------------------------------------------------------- files
  /// Writes the tree and its points (in input order) as a "spatial.KdTree"
  /// archive (core/archive.hpp): value sections scalar and dim, then the
  /// tree's sections (add_sections) without a prefix.
  void save(const std::filesystem::path& path) const {
    ArchiveWriter w(std::string(kKdTreeArchiveKind), kKdTreeArchiveVersion);
    w.add_dtype("scalar", dtype_of<T>());
    w.add_value("dim", std::uint64_t(dim()));
    std::vector<T> packed;  // only for a strided view: packed points are written as they are
    if (view_.stride != view_.dim && size() > 0) {
      packed.reserve(size() * dim());
      for (std::size_t i = 0; i < size(); ++i) packed.insert(packed.end(), point(i), point(i) + dim());
    }
    add_sections(w, "", packed.empty() ? std::span<const T>(view_.data, size() * dim()) : std::span<const T>(packed));
    w.write(path);
  }

  /// Maps a tree written by save() (see from_sections). Throws geods::Error
  /// naming the file for another scalar type or dimension, a truncated or
  /// corrupt file (checksums, unless `verify` says structure_only) or contents
  /// that fail validate().
  /// A loaded tree is zero_copy by default: it reads its points in place from
  /// the mapped file; `layout` tree_order copies them in leaf order after loading.
  static KdTree load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums,
                     PointLayout layout = PointLayout::zero_copy) {
    const Archive a = Archive::open(path, kKdTreeArchiveKind, kKdTreeArchiveVersion, verify);
    a.require_dtype<T>("scalar", "k-d tree");
    KdTree tree = from_sections(a, "", std::size_t(a.value<std::uint64_t>("dim")));
    if (layout == PointLayout::tree_order) tree.store_points_in_tree_order();
    return tree;
  }

 private:
  friend class KdTreeSteppedBuild<T, Dim>;

  // add_sections with the points given packed (save() packs a strided view).
  void add_sections(ArchiveWriter& w, const std::string& prefix, std::span<const T> points) const {
    w.add_value(prefix + "leaf_size", std::uint64_t(leaf_size_));
    w.add(prefix + "bounds_lo", root_lo_);
    w.add(prefix + "bounds_hi", root_hi_);
    w.add(prefix + "nodes", nodes_);
    w.add(prefix + "permutation", perm_);
    w.add(prefix + "points", points);
  }
  static_assert(sizeof(Node) == 16 + 2 * sizeof(T), "Node is written to files as is");
  static_assert(std::is_trivially_copyable_v<Node>);

  // A small per-query array: on the stack for compile-time and small run-time dimensions.
  template <typename U>
  class Scratch {
   public:
    explicit Scratch(std::size_t n) {
      if (Dim == Dynamic && n > kStack) heap_.resize(n);
    }
    U* data() { return heap_.empty() ? stack_.data() : heap_.data(); }

   private:
    static constexpr std::size_t kStack = Dim == Dynamic ? 64 : std::size_t(Dim);
    std::array<U, kStack> stack_;
    std::vector<U> heap_;
  };

  void adopt(std::vector<T> coordinates, std::size_t dim) {
    owned_ = std::make_shared<const FlatArray<T>>(std::move(coordinates));
    view_ = PointView<T>(owned_->data(), owned_->size() / dim, dim);
  }

  // ---------------------------------------------------------------- build
  void build(std::size_t leaf_size, PointLayout layout) {
    if (leaf_size == 0 || leaf_size > std::numeric_limits<std::uint32_t>::max())
      throw Error("KdTree: leaf_size must be >= 1");
    if (view_.dim == 0 || (Dim != Dynamic && view_.dim != std::size_t(Dim)))
      throw Error("KdTree: points of dimension " + std::to_string(view_.dim) + ", expected " +
                  (Dim == Dynamic ? std::string(">= 1") : std::to_string(Dim)));
    if (view_.stride < view_.dim) throw Error("KdTree: stride smaller than the dimension");
    if (view_.count >= std::numeric_limits<std::uint32_t>::max())
      throw Error("KdTree: " + std::to_string(view_.count) + " points, at most 2^32 - 2 are supported");
    if (view_.count > 0 && view_.data == nullptr) throw Error("KdTree: null point array");
    leaf_size_ = leaf_size;
    const std::size_t n = view_.count;
    // One pass in parallel; the checks one by one only run to name a bad point.
    const CoordinateScan<T> scan = scan_coordinates(view_.data, n, dim(), view_.stride, coordinate_limit<T>(2));
    if (!scan.finite_within) {
      for (std::size_t i = 0; i < n; ++i) {
        const T* p = view_[i];
        for (std::size_t a = 0; a < dim(); ++a)
          if (!std::isfinite(p[a]))
            throw Error("KdTree: point " + std::to_string(i) + " has a non-finite coordinate (axis " +
                        std::to_string(a) + ")");
      }
      check_coordinate_range(view_.data, n, dim(), view_.stride, 2, "KdTree");
    }
    check_coordinate_extent(scan.extent, extent_floor<T>(2), "KdTree");
    std::vector<std::uint32_t> perm(n);
    if (n == 0) return;
    // The size of every subtree depends only on its point count, so each one
    // knows its place in the node array before its siblings are built: the
    // parallel build writes disjoint parts and its output is deterministic.
    std::map<std::size_t, std::uint32_t> subtree_nodes;
    std::vector<Node> nodes(count_nodes(n, subtree_nodes));
    root_lo_.assign(dim(), T(0));
    root_hi_.assign(dim(), T(0));
    const Builder builder{this, nodes.data(), subtree_nodes, num_threads() > 1};
    if constexpr (Dim != Dynamic) {
      // Partitioning copies of the points (with their index) streams through
      // memory instead of following the permutation into the caller's array:
      // about twice as fast at the top levels, for n * (Dim + 1) scalars of scratch.
      struct Record {
        std::array<T, Dim> p;
        std::uint32_t index;
      };
      // The records end in tree order: the copy of tree_order is read off them.
      const auto records = std::make_unique_for_overwrite<Record[]>(n);
      parallel_for(0, n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          std::copy(view_[i], view_[i] + Dim, records[i].p.begin());
          records[i].index = std::uint32_t(i);
        }
      });
      builder.node(records.get(), [](const Record& r) { return r.p.data(); }, 0, 0, std::uint32_t(n),
                   root_lo_.data(), root_hi_.data());
      nodes_ = std::move(nodes);
      std::shared_ptr<T[]> ordered;
      if (layout == PointLayout::tree_order && !packs()) ordered = std::make_shared_for_overwrite<T[]>(n * Dim);
      parallel_for(0, n, 4096, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          perm[i] = records[i].index;
          if (ordered) std::copy_n(records[i].p.data(), Dim, ordered.get() + i * Dim);
        }
      });
      ordered_ = std::move(ordered);
      perm_ = std::move(perm);
      if (layout == PointLayout::tree_order && packs())
        packed_ = make_packed([&](std::size_t i) { return records[i].p.data(); });
    } else {
      std::iota(perm.begin(), perm.end(), 0u);
      builder.node(perm.data(), [this](std::uint32_t i) { return point(i); }, 0, 0, std::uint32_t(n),
                   root_lo_.data(), root_hi_.data());
      nodes_ = std::move(nodes);
      perm_ = std::move(perm);
      if (layout == PointLayout::tree_order) store_points_in_tree_order();
    }
  }

  // The split axis of a node whose points span [lo, hi]: the first of widest spread.
  static std::uint32_t widest_axis(const T* lo, const T* hi, std::size_t dim) {
    std::uint32_t axis = 0;
    for (std::uint32_t a = 1; a < dim; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    return axis;
  }

  std::uint32_t count_nodes(std::size_t m, std::map<std::size_t, std::uint32_t>& memo) const {
    if (m <= leaf_size_) return 1;
    if (auto it = memo.find(m); it != memo.end()) return it->second;
    const std::uint32_t c = 1 + count_nodes(m / 2, memo) + count_nodes(m - m / 2, memo);
    memo.emplace(m, c);
    return c;
  }

  // Puts into a[k] the item a sorted (by key(item)) sequence a[0, n) would
  // have there, smaller-or-equal keys before it and larger-or-equal after
  // (as std::nth_element, about twice as fast on the build's random keys).
  // The pivot of a large range is selected, recursively, on a part of it
  // around k (Floyd and Rivest's SELECT), so one pass leaves about n^(2/3)
  // to look at; a small range takes the median of three. Partitions are
  // branchless (comparisons against a median are coin flips a branch
  // predictor loses) and put the keys below the pivot first; when k lies
  // past them and none were below (the pivot is the least key), a second
  // pass gathers the keys equal to it, so equal keys cost one pass more, not
  // a quadratic time. Ranges of at most 16 are insertion-sorted; a range
  // still larger after 64 passes goes to std::nth_element.
  template <typename Item, typename Key>
  static void select_nth(Item* a, std::ptrdiff_t k, std::ptrdiff_t n, const Key& key) {
    std::ptrdiff_t left = 0, right = n;  // k lies in [left, right)
    // Moves the items of [begin, end) for which below(key) holds to its front; returns their end.
    auto partition = [&](std::ptrdiff_t begin, std::ptrdiff_t end, const auto& below) {
      std::ptrdiff_t store = begin;
      for (std::ptrdiff_t i = begin; i < end; ++i) {
        const Item x = a[i];
        const bool take = below(key(x));
        a[i] = a[store];
        a[store] = x;
        store += take;
      }
      return store;
    };
    for (int pass = 0; right - left > 16; ++pass) {
      if (pass == 64) {  // pivots that keep missing (adversarial orders): O(n log n) at worst
        std::nth_element(a + left, a + k, a + right, [&](const Item& x, const Item& y) { return key(x) < key(y); });
        return;
      }
      const std::ptrdiff_t size = right - left;
      T t;
      if (size > 600) {
        const double z = std::log(double(size)), s = 0.5 * std::exp(2 * z / 3);
        const double i = double(k - left + 1);
        const double sd = 0.5 * std::sqrt(z * s * (double(size) - s) / double(size)) * (i < double(size) / 2 ? -1 : 1);
        const std::ptrdiff_t l = std::max(left, std::ptrdiff_t(double(k) - i * s / double(size) + sd));
        const std::ptrdiff_t r = std::min(right - 1, std::ptrdiff_t(double(k) + (double(size) - i) * s / double(size) + sd));
        select_nth(a + l, k - l, r - l + 1, key);
        t = key(a[k]);
      } else {
        const T x = key(a[left]), y = key(a[k]), z = key(a[right - 1]);
        t = std::max(std::min(x, y), std::min(std::max(x, y), z));
      }
      const std::ptrdiff_t less = partition(left, right, [t](T v) { return v < t; });
      if (k < less) {
        right = less;
        continue;
      }
      if (less > left) {  // else t is the range's least key: equal keys need a pass of their own
        left = less;
        continue;
      }
      const std::ptrdiff_t equal = partition(less, right, [t](T v) { return v == t; });
      if (k < equal) return;  // a[k] == t, smaller keys before, larger after
      left = equal;
    }
    for (std::ptrdiff_t i = left + 1; i < right; ++i) {
      const Item x = a[i];
      const T v = key(x);
      std::ptrdiff_t j = i;
      for (; j > left && v < key(a[j - 1]); --j) a[j] = a[j - 1];
      a[j] = x;
    }
  }

  // Median-split recursion over a sequence of items (point records or point
  // indices) whose coordinates coords(item) returns.
  struct Builder {
    const KdTree* tree;
    Node* nodes;  // the node array being built
    const std::map<std::size_t, std::uint32_t>& subtree_nodes;
    bool parallel;

    // Subtrees smaller than this are built on one thread (task overhead dominates below).
    static constexpr std::size_t kParallelBuild = 1 << 14;

    // Builds node v over items[begin, end) and writes the bounds of its points to lo/hi.
    template <typename Item, typename Coords>
    void node(Item* items, const Coords& coords, std::uint32_t v, std::uint32_t begin, std::uint32_t end, T* lo,
              T* hi) const {
      const std::size_t dim = tree->dim();
      bounds(items, coords, begin, end, lo, hi);
      Node& node = nodes[v];
      node = Node{begin, end, 0, 0, T(0), T(0)};
      const std::size_t m = end - begin;
      if (m <= tree->leaf_size_) return;
      const std::uint32_t axis = widest_axis(lo, hi, dim);
      const std::uint32_t mid = begin + std::uint32_t(m / 2);
      select_nth(items + begin, std::ptrdiff_t(mid - begin), std::ptrdiff_t(m),
                 [&](const Item& item) { return coords(item)[axis]; });
      const std::size_t left_count = m / 2;
      const std::uint32_t right = v + 1 + (left_count <= tree->leaf_size_ ? 1 : subtree_nodes.at(left_count));
      node.right = right;
      node.axis = axis;
      Scratch<T> left_lo(dim), left_hi(dim), right_lo(dim), right_hi(dim);
      auto build_left = [&] { this->node(items, coords, v + 1, begin, mid, left_lo.data(), left_hi.data()); };
      auto build_right = [&] { this->node(items, coords, right, mid, end, right_lo.data(), right_hi.data()); };
      if (parallel && m >= kParallelBuild) {
        tbb::parallel_invoke(build_left, build_right);
      } else {
        build_left();
        build_right();
      }
      node.low = left_hi.data()[axis];
      node.high = right_lo.data()[axis];
    }

    template <typename Item, typename Coords>
    void bounds(const Item* items, const Coords& coords, std::uint32_t begin, std::uint32_t end, T* lo, T* hi) const {
#if defined(__SSE__)
      if constexpr (std::is_same_v<T, float> && Dim == 3 && sizeof(Item) == 4 * sizeof(float) &&
                    !std::is_integral_v<Item>) {
        // A record {x, y, z, index} is one SSE register: min/max of four lanes, the fourth ignored.
        if (coords(items[begin]) == reinterpret_cast<const T*>(items + begin)) {
          const float* p = reinterpret_cast<const float*>(items + begin);
          __m128 l = _mm_loadu_ps(p), h = l;
          for (std::uint32_t i = begin + 1; i < end; ++i) {
            const __m128 v = _mm_loadu_ps(reinterpret_cast<const float*>(items + i));
            l = _mm_min_ps(l, v);
            h = _mm_max_ps(h, v);
          }
          alignas(16) float lv[4], hv[4];
          _mm_store_ps(lv, l);
          _mm_store_ps(hv, h);
          std::copy_n(lv, 3, lo);
          std::copy_n(hv, 3, hi);
          return;
        }
      }
#endif
      if constexpr (Dim != Dynamic) {
        // In registers: through lo/hi the compiler would store every step (they might alias the items).
        std::array<T, std::size_t(Dim)> l, h;
        const T* p = coords(items[begin]);
        for (int a = 0; a < Dim; ++a) l[a] = h[a] = p[a];
        for (std::uint32_t i = begin + 1; i < end; ++i) {
          p = coords(items[i]);
          for (int a = 0; a < Dim; ++a) {
            l[a] = std::min(l[a], p[a]);
            h[a] = std::max(h[a], p[a]);
          }
        }
        std::copy(l.begin(), l.end(), lo);
        std::copy(h.begin(), h.end(), hi);
        return;
      }
      const std::size_t dim = tree->dim();
      const T* p = coords(items[begin]);
      for (std::size_t a = 0; a < dim; ++a) lo[a] = hi[a] = p[a];
      for (std::uint32_t i = begin + 1; i < end; ++i) {
        p = coords(items[i]);
        for (std::size_t a = 0; a < dim; ++a) {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
      }
    }
  };

  // ---------------------------------------------------------------- search
  void check_point(std::span<const T> q, const char* what) const {
    if (q.size() != dim())
      throw Error(std::string("KdTree: ") + what + " of dimension " + std::to_string(q.size()) + ", the tree has " +
                  std::to_string(dim()));
    for (T x : q)
      if (!std::isfinite(x)) throw Error(std::string("KdTree: ") + what + " has a non-finite coordinate");
  }

  static void check_batch(const PointView<T>& rows, std::size_t width, const char* what) {
    if (rows.dim != width)
      throw Error(std::string("KdTree: ") + what + " rows hold " + std::to_string(rows.dim) + " values, expected " +
                  std::to_string(width));
    if (rows.count > 0 && (rows.data == nullptr || rows.stride < rows.dim))
      throw Error(std::string("KdTree: bad ") + what + " array");
  }

  T squared_distance(const T* q, const T* p) const { return spatial::squared_distance(q, p, dim()); }

  // Per-axis squared distances from q to the root box and their sum (Arya & Mount's incremental distance).
  T initial_distances(const T* q, T* dists) const {
    T sum = 0;
    for (std::size_t a = 0; a < dim(); ++a) {
      T t = 0;
      if (q[a] < root_lo_[a]) t = root_lo_[a] - q[a];
      if (q[a] > root_hi_[a]) t = q[a] - root_hi_[a];
      dists[a] = t * t;
      sum += dists[a];
    }
    return sum;
  }

  // Rounding slack of the pruning bound: keeps exact ties from being pruned by
  // rounding in the incremental distance.
  T slack() const { return T(1) + T(4 * (dim() + 2)) * std::numeric_limits<T>::epsilon(); }

  // The one descent of the distance searches (Arya & Mount's incremental
  // distance): nearer child first; a subtree is entered while the squared
  // distance from q to its cell is <= search.bound(); every leaf point that
  // skip keeps and whose squared distance is <= search.limit() goes to
  // search.report(index, d). bound() and limit() are read again after each
  // report, so a k-best list tightens the search as it fills.
  template <typename Search, typename Skip>
  void descend(const T* q, const Search& search, const Skip& skip) const {
    if (empty()) return;
    Scratch<T> dists(dim());
    const T mindist = initial_distances(q, dists.data());
    if (!(mindist <= search.bound())) return;  // the whole tree is too far (one of several, or beyond max_distance)
    if (packed_) {
      const PackedDescent<Search, Skip> descent{packed_->nodes.data(), packed_->groups.data(), q, dists.data(), search,
                                                skip, std::uint32_t(leaf_size_)};
      descent.enter({0, 0, std::uint32_t(size())}, mindist);
    } else if (ordered_)
      Descent<true, Search, Skip>{*this, q, dists.data(), search, skip}.visit(0, mindist);
    else
      Descent<false, Search, Skip>{*this, q, dists.data(), search, skip}.visit(0, mindist);
  }

  // The query state in one place, so the recursion passes only (node, mindist);
  // the policy is held by value (it refers to its result), one indirection less.
  // Ordered: read the leaf points from ordered_ (store_points_in_tree_order) instead of via perm_.
  template <bool Ordered, typename Search, typename Skip>
  struct Descent {
    const KdTree& tree;
    const T* q;
    T* dists;  // per-axis terms of mindist
    Search search;
    const Skip& skip;

    // mindist is a lower bound of the squared distance from q to the cell of node v.
    void visit(std::uint32_t v, T mindist) const {
      const Node& node = tree.nodes_[v];
      if (node.leaf()) {
        T limit = search.limit();  // cheap rejection first; a k-best list breaks exact ties by index
        const std::size_t dim = tree.dim();
        const T* next = Ordered ? tree.ordered_.get() + std::size_t(node.begin) * dim : nullptr;
        for (std::uint32_t i = node.begin; i < node.end; ++i) {
          const T* p;
          if constexpr (Ordered) {
            p = next;
            next += dim;
          } else {
            p = tree.point(tree.perm_[i]);
          }
          if constexpr (!kSkipsNothing<Skip>)
            if (skip(tree.perm_[i])) continue;
          const T d = tree.squared_distance(q, p);
          if (d <= limit) {
            search.report(tree.perm_[i], d);
            limit = search.limit();
          }
        }
        return;
      }
      const std::uint32_t axis = node.axis;
      const T x = q[axis];
      const T to_low = x - node.low, to_high = node.high - x;
      std::uint32_t near = v + 1, far = node.right;
      T cut = to_high * to_high;  // distance term of the far cell on this axis
      if (to_low > to_high) {
        std::swap(near, far);
        cut = to_low * to_low;
      }
      visit(near, mindist);
      const T old = dists[axis];
      mindist += cut - old;
      if (mindist <= search.bound()) {
        dists[axis] = cut;
        visit(far, mindist);
        dists[axis] = old;
      }
    }
  };

  // ---------------------------------------------------------------- packed tree order
  // The tree_order layout of trees whose dimension is fixed at compile time
  // (up to 4), which is what their k-NN and radius searches read instead of
  // nodes_ and perm_: the inner nodes only, in depth-first order, 16 bytes each
  // for float (low, high, the right child and the split axis in one word, the
  // first point group of the right child), and the points of every leaf in
  // groups of 4 laid out axis by axis (Dim x 4 coordinates, then the 4 point
  // indices: one 64-byte cache line for float 3D), the last group of a leaf
  // padded with NaN, which no distance test accepts. Leaves need no node: a
  // child is a leaf when its point count, which the descent carries (a node of
  // m points splits them m / 2 and m - m / 2), is at most leaf_size, and its
  // points are the groups from the one its parent names. One leaf point costs
  // a vector lane instead of a scalar distance and a load of perm_.
  static constexpr bool kPacked = Dim != Dynamic && Dim <= 4;
  static constexpr int kGroupDim = kPacked ? Dim : 1;
  static constexpr std::uint32_t kChildMask = (1u << 30) - 1;
  struct PackedNode {
    T low, high;                // as in Node
    std::uint32_t right;        // index of the right child if it is inner (else 0) | axis << 30
    std::uint32_t right_group;  // the first point group of the right child
  };
  struct alignas(sizeof(T) * 4 * kGroupDim + 16 == 64 ? 64 : 16) Group {
    T x[kGroupDim][4];        // x[axis][lane]
    std::uint32_t index[4];  // kNoIndex in padding lanes
  };
  // In huge pages (when large), as the BVH's nodes: a query's cache misses at random
  // in 16 MB of groups (1M float 3D points) then cost no TLB miss (page walk) on top.
  struct Packed {
    std::vector<PackedNode, HugePageAllocator<PackedNode>> nodes;
    std::vector<Group, HugePageAllocator<Group>> groups;
  };

  // Whether tree_order is the packed layout (else the plain copy ordered_).
  bool packs() const { return kPacked && nodes_.size() <= kChildMask; }

  // The packed layout; coords(i) are the coordinates of the point at permutation position i.
  template <typename Coords>
  std::shared_ptr<const Packed> make_packed(const Coords& coords) const {
    auto packed = std::make_shared<Packed>();
    std::size_t inner = 0, groups = 0;
    for (const Node& v : nodes_) v.leaf() ? groups += (v.end - v.begin + 3) / 4 : ++inner;
    packed->nodes.resize(inner);
    packed->groups.resize(groups);
    std::uint32_t next_node = 0, next_group = 0;
    pack_node(*packed, 0, next_node, next_group, coords);
    return packed;
  }

  template <typename Coords>
  void pack_node(Packed& packed, std::uint32_t v, std::uint32_t& next_node, std::uint32_t& next_group,
                 const Coords& coords) const {
    const Node& node = nodes_[v];
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; i += 4) {
        Group& g = packed.groups[next_group++];
        for (std::uint32_t l = 0; l < 4; ++l) {
          const bool real = i + l < node.end;
          g.index[l] = real ? perm_[i + l] : kNoIndex;
          for (int a = 0; a < kGroupDim; ++a) g.x[a][l] = real ? coords(i + l)[a] : std::numeric_limits<T>::quiet_NaN();
        }
      }
      return;
    }
    const std::uint32_t me = next_node++;
    pack_node(packed, v + 1, next_node, next_group, coords);
    packed.nodes[me] = PackedNode{node.low, node.high, (nodes_[node.right].leaf() ? 0 : next_node) | node.axis << 30,
                                  next_group};
    pack_node(packed, node.right, next_node, next_group, coords);
  }

  // validate(): the packed layout of the subtree of node v says what nodes_, perm_ and the points do.
  bool validate_packed(std::uint32_t v, std::uint32_t& next_node, std::uint32_t& next_group) const {
    const Node& node = nodes_[v];
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; i += 4) {
        if (next_group >= packed_->groups.size()) return false;
        const Group& g = packed_->groups[next_group++];
        for (std::uint32_t l = 0; l < 4; ++l) {
          const bool real = i + l < node.end;
          if (g.index[l] != (real ? perm_[i + l] : kNoIndex)) return false;
          for (int a = 0; a < kGroupDim; ++a)
            if (real ? !(g.x[a][l] == point(perm_[i + l])[a]) : !std::isnan(g.x[a][l])) return false;
        }
      }
      return true;
    }
    if (next_node >= packed_->nodes.size()) return false;
    const PackedNode pn = packed_->nodes[next_node++];
    if (!validate_packed(v + 1, next_node, next_group)) return false;
    if (pn.low != node.low || pn.high != node.high || pn.right >> 30 != node.axis || pn.right_group != next_group ||
        (pn.right & kChildMask) != (nodes_[node.right].leaf() ? 0 : next_node))
      return false;
    return validate_packed(node.right, next_node, next_group);
  }

  // Descent over the packed layout: the same visits, in the same order, as Descent.
  template <typename Search, typename Skip>
  struct PackedDescent {
    const PackedNode* nodes;
    const Group* groups;
    const T* q;
    T* dists;  // per-axis terms of mindist
    Search search;
    const Skip& skip;
    std::uint32_t leaf_size;

    struct Child {
      std::uint32_t node, group, count;  // node: index in nodes if count > leaf_size
    };

    void enter(const Child& c, T mindist) const {
      if (c.count <= leaf_size)
        leaf(groups + c.group, c.count);
      else
        visit(c, mindist);
    }

    void visit(const Child& c, T mindist) const {
      const PackedNode& node = nodes[c.node];
      const std::uint32_t axis = node.right >> 30;
      const T x = q[axis];
      const T to_low = x - node.low, to_high = node.high - x;
      Child near{c.node + 1, c.group, c.count / 2}, far{node.right & kChildMask, node.right_group, c.count - c.count / 2};
      T cut = to_high * to_high;  // distance term of the far cell on this axis
      if (to_low > to_high) {
        std::swap(near, far);
        cut = to_low * to_low;
      }
      prefetch(far);
      enter(near, mindist);
      const T old = dists[axis];
      mindist += cut - old;
      if (mindist <= search.bound()) {
        dists[axis] = cut;
        enter(far, mindist);
        dists[axis] = old;
      }
    }

    // The far child is fetched while the near one is searched: it is often visited next.
    void prefetch(const Child& c) const {
      if (c.count > leaf_size) {
        __builtin_prefetch(nodes + c.node);
        return;
      }
      for (std::uint32_t i = 0; i < c.count; i += 4) __builtin_prefetch(groups + c.group + i / 4);
    }

    void leaf(const Group* g, std::uint32_t count) const {
      T limit = search.limit();  // cheap rejection first; a k-best list breaks exact ties by index
      for (std::uint32_t i = 0; i < count; i += 4, ++g) {
        T d[4];
        for (unsigned mask = within(*g, limit, d); mask != 0; mask &= mask - 1) {
          const int l = std::countr_zero(mask);
          if (!(d[l] <= limit)) continue;  // the limit shrank since
          if constexpr (!kSkipsNothing<Skip>)
            if (skip(g->index[l])) continue;
          search.report(g->index[l], d[l]);
          limit = search.limit();
        }
      }
    }

    // The squared distances from q to the group's 4 points (as squared_distance sums
    // them: axis by axis), and a bit per lane whose distance is <= limit.
    unsigned within(const Group& g, T limit, T* d) const {
#if defined(__SSE__)
      if constexpr (std::is_same_v<T, float>) {
        __m128 t = _mm_sub_ps(_mm_set1_ps(q[0]), _mm_load_ps(g.x[0]));
        __m128 s = _mm_mul_ps(t, t);
        for (int a = 1; a < kGroupDim; ++a) {
          t = _mm_sub_ps(_mm_set1_ps(q[a]), _mm_load_ps(g.x[a]));
          s = _mm_add_ps(s, _mm_mul_ps(t, t));
        }
        _mm_storeu_ps(d, s);
        return unsigned(_mm_movemask_ps(_mm_cmple_ps(s, _mm_set1_ps(limit))));
      }
#endif
      unsigned mask = 0;
      for (int l = 0; l < 4; ++l) {
        T s = 0;
        for (int a = 0; a < kGroupDim; ++a) {
          const T t = q[a] - g.x[a][l];
          s += t * t;
        }
        d[l] = s;
        mask |= unsigned(s <= limit) << l;
      }
      return mask;
    }
  };

  struct BoxAt {
    std::uint32_t node, group;   // index in nodes_, or in packed_->nodes and the first point group
    std::uint32_t begin, count;  // the node's points are permutation()[begin, begin + count)
  };

  void check_box(std::span<const T> lo, std::span<const T> hi) const {
    check_point(lo, "box low corner");
    check_point(hi, "box high corner");
  }

  // The box descent: visit.range(begin, end) gets the permutation ranges of
  // subtrees inside the box (without a filter), visit.point(index) every other
  // point in the box. Returns the number of nodes visited.
  template <typename Visit, typename Skip>
  std::size_t box(const T* lo, const T* hi, Visit& visit, const Skip& skip) const {
    if (empty()) return 0;
    Scratch<T> cell_lo(dim()), cell_hi(dim());
    std::copy(root_lo_.begin(), root_lo_.end(), cell_lo.data());
    std::copy(root_hi_.begin(), root_hi_.end(), cell_hi.data());
    std::size_t nodes = 0;
    const BoxAt root{0, 0, 0, std::uint32_t(size())};
    if (packed_)
      box_node<true>(root, lo, hi, cell_lo.data(), cell_hi.data(), visit, skip, nodes);
    else
      box_node<false>(root, lo, hi, cell_lo.data(), cell_hi.data(), visit, skip, nodes);
    return nodes;
  }

  // cell_lo/cell_hi bound the points of node `at`; they are restored on return.
  // Packed: at.node indexes packed_->nodes (inner nodes only; leaves are told by
  // their count) and the leaf points are read from packed_->groups, else nodes_.
  template <bool Packed, typename Visit, typename Skip>
  void box_node(const BoxAt& at, const T* lo, const T* hi, T* cell_lo, T* cell_hi, Visit& visit, const Skip& skip,
                std::size_t& visited) const {
    ++visited;
    bool inside = true;
    for (std::size_t a = 0; a < dim(); ++a) {
      if (cell_lo[a] > hi[a] || cell_hi[a] < lo[a]) return;
      inside = inside && lo[a] <= cell_lo[a] && cell_hi[a] <= hi[a];
    }
    const std::uint32_t begin = at.begin, end = at.begin + at.count;
    if (inside) {
      if constexpr (kSkipsNothing<Skip>) {
        visit.range(begin, end);
      } else {
        for (std::uint32_t i = begin; i < end; ++i)
          if (!skip(perm_[i])) visit.point(perm_[i]);
      }
      return;
    }
    if (at.count <= leaf_size_) {  // a leaf (validate() checks that leaves are the nodes this small)
      if constexpr (Packed) {
        const Group* g = packed_->groups.data() + at.group;
        for (std::uint32_t i = begin; i < end; i += 4, ++g) {
          for (std::uint32_t l = 0; l < 4 && i + l < end; ++l) {
            if constexpr (!kSkipsNothing<Skip>)
              if (skip(g->index[l])) continue;
            bool in = true;
            for (int a = 0; a < kGroupDim; ++a) in = in && lo[a] <= g->x[a][l] && g->x[a][l] <= hi[a];
            if (in) visit.point(g->index[l]);
          }
        }
      } else {
        for (std::uint32_t i = begin; i < end; ++i) {
          const std::uint32_t j = perm_[i];
          if constexpr (!kSkipsNothing<Skip>)
            if (skip(j)) continue;
          const T* p = ordered_ ? ordered_.get() + std::size_t(i) * dim() : point(j);
          bool in = true;
          for (std::size_t a = 0; a < dim() && in; ++a) in = lo[a] <= p[a] && p[a] <= hi[a];
          if (in) visit.point(j);
        }
      }
      return;
    }
    std::uint32_t axis;
    T low, high;
    BoxAt left{at.node + 1, at.group, begin, at.count / 2}, right{0, 0, begin + at.count / 2, at.count - at.count / 2};
    if constexpr (Packed) {
      const PackedNode& node = packed_->nodes[at.node];
      axis = node.right >> 30, low = node.low, high = node.high;
      right.node = node.right & kChildMask, right.group = node.right_group;
    } else {
      const Node& node = nodes_[at.node];
      axis = node.axis, low = node.low, high = node.high;
      right.node = node.right;
    }
    const T saved_hi = cell_hi[axis];
    cell_hi[axis] = low;
    box_node<Packed>(left, lo, hi, cell_lo, cell_hi, visit, skip, visited);
    cell_hi[axis] = saved_hi;
    const T saved_lo = cell_lo[axis];
    cell_lo[axis] = high;
    box_node<Packed>(right, lo, hi, cell_lo, cell_hi, visit, skip, visited);
    cell_lo[axis] = saved_lo;
  }

  PointView<T> view_;
  std::shared_ptr<const FlatArray<T>> owned_;  // the points, when the tree owns or maps them (shared by copies)
  std::shared_ptr<const T[]> ordered_;  // size() * dim() values in tree order (PointLayout::tree_order)
  std::shared_ptr<const Packed> packed_;  // instead of ordered_ when packs() (PointLayout::tree_order)
  std::size_t leaf_size_ = kDefaultLeafSize;
  FlatArray<Node> nodes_;
  FlatArray<std::uint32_t> perm_;
  std::vector<T> root_lo_, root_hi_;
};

template <typename T>
using KdTree2 = KdTree<T, 2>;
template <typename T>
using KdTree3 = KdTree<T, 3>;

}  // namespace geods::spatial
