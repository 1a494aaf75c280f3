#pragma once
// Point quadtree (2D) and octree (3D) of seed §2.1: every inner node has 2^Dim
// children whose cells are the equal quadrants (octants) of its square (cube).
//
// Definition (§2.1.1), generalized: a node splits while it holds more than
// `bucket` points, lies above `max_depth` and its points do not all coincide
// (so duplicates never split forever). A point goes to the high half of an axis
// when its coordinate is > the cell's middle, to the low half when <= (the
// seed's rule), so cells are (lo, hi] except on the root's low boundary.
//
// Root cell: the smallest enclosing square (cube) anchored at the low corner of
// the points' bounding box, with side = the box's longest extent (nudged up by
// ulps until lo + side covers the high corner). Cell geometry is computed in
// double from integer cell coordinates, identically in every build and query,
// so classification, locate() and the cell bounds never disagree.
//
// Layout: one flat node array in breadth-first order; the 2^Dim children of a
// node are contiguous from `first_child` (child slot c has the high half of axis
// a iff bit a of c is set, i.e. Morton order), every node knows its parent,
// depth and integer cell coordinates. Points are referenced by a permutation in
// which each node owns a contiguous range (ascending indices inside a leaf).
// Nodes, permutation and points are FlatArrays: a tree loaded from a file
// (load()) reads them in place from the mapped file.
//
// Two builds give the same tree, node for node: top-down (each level's nodes
// partition their points in parallel, the recursive definition level by level),
// and linear (Morton keys of every point in parallel, one parallel sort, then
// each node's children are runs of equal key digits). Both cost O((d + 1) n).
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "geods/core/aabb.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/coordinate_range.hpp"
#include "geods/core/error.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/morton.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/vec.hpp"
#include "geods/spatial/knn_result.hpp"
#include "geods/spatial/permutation.hpp"
#include "geods/spatial/point_view.hpp"

namespace geods::spatial {

/// "No node": no neighbor in that direction, or a point outside the root cell.
inline constexpr std::uint32_t kNoNode = std::numeric_limits<std::uint32_t>::max();

/// Face directions: axis = value / 2, negative side iff value is odd.
enum class Direction : std::uint8_t {
  pos_x = 0, neg_x = 1, pos_y = 2, neg_y = 3, pos_z = 4, neg_z = 5,
  // The spellings before enum values were snake_case everywhere.
  PosX [[deprecated("use pos_x")]] = pos_x, NegX [[deprecated("use neg_x")]] = neg_x,
  PosY [[deprecated("use pos_y")]] = pos_y, NegY [[deprecated("use neg_y")]] = neg_y,
  PosZ [[deprecated("use pos_z")]] = pos_z, NegZ [[deprecated("use neg_z")]] = neg_z,
};
inline constexpr Direction kEast = Direction::pos_x;
inline constexpr Direction kWest = Direction::neg_x;
inline constexpr Direction kNorth = Direction::pos_y;
inline constexpr Direction kSouth = Direction::neg_y;

enum class OrthtreeBuild {
  top_down,
  morton,
  TopDown [[deprecated("use top_down")]] = top_down,
  Morton [[deprecated("use morton")]] = morton,
};

/// The archive kind and layout version of a saved quadtree or octree (Orthtree::save).
inline constexpr std::string_view kOrthtreeArchiveKind = "spatial.Orthtree";
inline constexpr std::uint32_t kOrthtreeArchiveVersion = 1;

struct OrthtreeOptions {
  std::size_t bucket = 1;  // a leaf holds at most this many points (unless they coincide or max_depth is reached)
  int max_depth = -1;      // -1: the deepest level the 64-bit Morton keys hold (32 in 2D, 21 in 3D)
  OrthtreeBuild build = OrthtreeBuild::top_down;
};

struct OrthtreeStats {
  std::size_t points = 0;
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  std::size_t empty_leaves = 0;
  std::size_t depth = 0;  // edges on the longest root-to-leaf path
  std::size_t bytes = 0;  // nodes, permutation and the points
};

template <typename T, int Dim>
class Orthtree {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "Orthtree<T>: T is float or double");
  static_assert(Dim == 2 || Dim == 3, "Orthtree<T, Dim>: Dim is 2 (quadtree) or 3 (octree)");

 public:
  using Scalar = T;
  using VecT = Vec<T, Dim>;
  using Box = AABB<double, Dim>;
  static constexpr int kDim = Dim;
  static constexpr std::uint32_t kChildren = 1u << Dim;
  static constexpr int kMaxDepth = Dim == 2 ? 32 : 21;

  struct Node {
    std::uint32_t first_child;  // 0 marks a leaf (the root is nobody's child)
    std::uint32_t parent;       // kNoNode for the root
    std::uint32_t begin, end;   // the node's points are permutation()[begin, end)
    std::uint32_t depth;
    std::array<std::uint32_t, Dim> cell;  // integer cell coordinates at this depth
    bool leaf() const { return first_child == 0; }
    friend bool operator==(const Node&, const Node&) = default;
  };

  /// An empty tree (no nodes; queries return nothing).
  Orthtree() = default;

  /// Builds over a copy of the points. Throws geods::Error for NaN/inf
  /// coordinates, a dimension other than Dim, bucket 0, max_depth outside
  /// [0, kMaxDepth] or 2^32 - 1 points or more.
  explicit Orthtree(PointView<T> points, const OrthtreeOptions& options = {}) { build(points, options); }
  explicit Orthtree(std::span<const VecT> points, const OrthtreeOptions& options = {})
      : Orthtree(PointView<T>(points), options) {}

  // ---------------------------------------------------------------- accessors
  std::size_t size() const { return points_ ? points_->size() / Dim : 0; }
  bool empty() const { return size() == 0; }
  std::size_t bucket() const { return bucket_; }
  int max_depth() const { return max_depth_; }
  /// True for trees returned by balanced(): validate() then checks the 2:1 condition.
  bool is_balanced() const { return balanced_; }
  VecT point(std::size_t i) const { return Eigen::Map<const VecT>(points_->data() + i * Dim); }
  const FlatArray<Node>& nodes() const { return nodes_; }
  const Node& node(std::uint32_t v) const {
    if (v >= nodes_.size()) throw Error("Orthtree: node " + std::to_string(v) + " does not exist");
    return nodes_[v];
  }
  const FlatArray<std::uint32_t>& permutation() const { return perm_; }
  /// The root square (cube); empty for an empty tree.
  Box root_bounds() const { return nodes_.empty() ? Box() : node_bounds(0); }
  double root_side() const { return side_; }

  /// The closed cell of node v.
  Box node_bounds(std::uint32_t v) const {
    const Node& n = node(v);
    Box box;
    for (int a = 0; a < Dim; ++a) {
      box.lo[a] = coordinate(n.cell[a], n.depth, a);
      box.hi[a] = coordinate(n.cell[a] + 1.0, n.depth, a);
    }
    return box;
  }

  // ---------------------------------------------------------------- neighbor finding (§2.1.3)
  /// The deepest node of depth <= depth(v) whose cell is adjacent to v's cell
  /// across the face in direction `dir` (of v's depth if one exists, else a
  /// leaf); kNoNode at the boundary of the root cell. O(d + 1) (Theorem 3).
  std::uint32_t neighbor(std::uint32_t v, Direction dir) const {
    if (v >= nodes_.size()) throw Error("Orthtree::neighbor: node " + std::to_string(v) + " does not exist");
    const int axis = int(dir) / 2;
    if (axis >= Dim) throw Error("Orthtree::neighbor: direction along axis " + std::to_string(axis) +
                                 " in a tree of dimension " + std::to_string(Dim));
    return neighbor_in(nodes_, v, dir);
  }

  // ---------------------------------------------------------------- balancing (§2.1.3, de Berg et al. 14.2)
  /// The 2:1-balanced tree of this one: the smallest refinement in which any two
  /// leaves whose cells share a face differ by at most one in depth. O((d + 1) m)
  /// for m nodes. The points are shared, not copied.
  Orthtree balanced() const {
    Orthtree out = *this;
    out.balanced_ = true;
    if (nodes_.empty()) return out;
    std::vector<Node> nodes = nodes_.to_vector();
    std::vector<std::uint32_t> perm = perm_.to_vector(), stack, scratch(size());
    for (std::uint32_t v = 0; v < nodes.size(); ++v)
      if (nodes[v].leaf()) stack.push_back(v);
    while (!stack.empty()) {
      const std::uint32_t mu = stack.back();
      stack.pop_back();
      if (!nodes[mu].leaf() || !must_refine(nodes, mu)) continue;
      split(nodes, perm, mu, scratch.data());
      for (std::uint32_t c = 0; c < kChildren; ++c) stack.push_back(nodes[mu].first_child + c);
      // Larger neighbors now touch mu's children, two levels deeper: they split too.
      for (int d = 0; d < 2 * Dim; ++d) {
        const std::uint32_t nb = neighbor_in(nodes, mu, Direction(d));
        if (nb != kNoNode && nodes[nb].leaf() && nodes[nb].depth < nodes[mu].depth) stack.push_back(nb);
      }
    }
    out.nodes_ = std::move(nodes);
    out.perm_ = std::move(perm);
    return out;
  }

  // ---------------------------------------------------------------- queries
  /// The leaf whose cell contains p (points on an inner boundary go to the low
  /// side, as in the build); kNoNode outside the root cell. O(d + 1).
  std::uint32_t locate(const VecT& p) const {
    check_point(p, "locate: point");
    if (nodes_.empty() || !root_bounds().contains(p.template cast<double>())) return kNoNode;
    std::uint32_t v = 0;
    while (!nodes_[v].leaf()) v = nodes_[v].first_child + child_slot(nodes_[v], p);
    return v;
  }

  /// Indices of the points in the closed box [lo, hi], in tree order. Subtrees
  /// whose cell lies inside the box are reported without visiting them.
  std::vector<std::uint32_t> query_box(const VecT& lo, const VecT& hi) const {
    std::vector<std::uint32_t> out;
    box_search<true>(lo, hi, &out);
    return out;
  }
  std::size_t count_box(const VecT& lo, const VecT& hi) const { return box_search<false>(lo, hi, nullptr); }

  /// The k nearest points to q, by distance, ties by index (fewer if the tree holds fewer).
  std::vector<Neighbor<T>> query(const VecT& q, std::size_t k) const {
    if (k == 0) throw Error("Orthtree::query: k must be >= 1");
    check_point(q, "query point");
    check_query_range<2>(std::span<const T>(q.data(), Dim), "Orthtree");
    std::vector<Neighbor<T>> out(std::min(k, size()));
    if (out.empty()) return out;
    KnnResultSet<T> result(out.data(), out.size(), std::numeric_limits<T>::infinity());
    search_knn(0, root_bounds(), q, q.template cast<double>(), result);
    result.finish();
    return out;
  }

  /// Every point within distance `radius` of q (inclusive), sorted like query().
  std::vector<Neighbor<T>> query_radius(const VecT& q, double radius) const {
    check_point(q, "query point");
    check_query_range<2>(std::span<const T>(q.data(), Dim), "Orthtree");
    if (!(radius >= 0)) throw Error("Orthtree::query_radius: radius must be >= 0, got " + format_number(radius));
    std::vector<Neighbor<T>> out;
    if (nodes_.empty()) return out;
    const double r2 = radius * radius;
    const T limit = r2 >= double(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::infinity() : T(r2);
    search_radius(0, q, limit, out);
    std::sort(out.begin(), out.end());
    return out;
  }

  // ---------------------------------------------------------------- inspection
  OrthtreeStats stats() const {
    OrthtreeStats s;
    s.points = size();
    s.nodes = nodes_.size();
    for (const Node& n : nodes_) {
      s.depth = std::max<std::size_t>(s.depth, n.depth);
      if (n.leaf()) {
        ++s.leaves;
        if (n.begin == n.end) ++s.empty_leaves;
      }
    }
    s.bytes = nodes_.size() * sizeof(Node) + perm_.size() * sizeof(std::uint32_t) + size() * sizeof(VecT);
    return s;
  }

  /// Checks every invariant; throws geods::Error naming the first violation:
  /// the permutation is one; nodes form a tree from the root whose children have
  /// the right parent, depth and cell, and split their parent's point range in
  /// slot order; inner nodes had to split (unless balanced: balancing splits
  /// more), leaves may stay leaves and list ascending indices; every point is
  /// found by locate() in its own leaf (so it lies in its cell); and for a
  /// balanced tree, face-adjacent leaves differ by at most one in depth.
  void validate() const {
    const std::size_t n = size();
    auto fail = [](const std::string& what) { throw Error("Orthtree::validate: " + what); };
    require_permutation(perm_, n, "Orthtree::validate");
    if (n == 0) {
      if (!nodes_.empty()) fail("nodes without points");
      return;
    }
    if (nodes_.empty()) fail("points without nodes");
    if (bucket_ == 0 || max_depth_ < 0 || max_depth_ > kMaxDepth) fail("bad bucket or max_depth");
    if (!lo_.allFinite() || !std::isfinite(side_) || side_ < 0) fail("bad root square");
    const Node& root = nodes_[0];
    if (root.parent != kNoNode || root.depth != 0 || root.begin != 0 || root.end != n ||
        root.cell != std::array<std::uint32_t, Dim>{})
      fail("bad root");
    const Box root_box = root_bounds();
    for (std::size_t i = 0; i < n; ++i)
      if (!point(i).allFinite() || !root_box.contains(point(i).template cast<double>()))
        fail("point " + std::to_string(i) + " is not finite or lies outside the root");
    std::vector<std::uint32_t> stack{0};
    std::size_t visited = 0;
    while (!stack.empty()) {
      const std::uint32_t v = stack.back();
      stack.pop_back();
      if (++visited > nodes_.size()) fail("node graph is not a tree");
      const Node& node = nodes_[v];
      const std::string where = "node " + std::to_string(v) + ": ";
      if (node.begin > node.end || node.end > n) fail(where + "bad point range");
      if (int(node.depth) > max_depth_) fail(where + "deeper than max_depth");
      if (node.leaf()) {
        if (must_split(perm_, node)) fail(where + "leaf that has to be split");
        for (std::uint32_t i = node.begin + 1; i < node.end; ++i)
          if (perm_[i - 1] >= perm_[i]) fail(where + "leaf indices not ascending");
        continue;
      }
      if (!balanced_ && !must_split(perm_, node)) fail(where + "inner node that did not have to split");
      if (node.first_child <= v || std::size_t(node.first_child) + kChildren > nodes_.size())
        fail(where + "bad child index");
      std::uint32_t at = node.begin;
      for (std::uint32_t c = 0; c < kChildren; ++c) {
        const Node& child = nodes_[node.first_child + c];
        if (child.parent != v || child.depth != node.depth + 1) fail(where + "child with a bad parent or depth");
        for (int a = 0; a < Dim; ++a)
          if (child.cell[a] != 2 * node.cell[a] + ((c >> a) & 1)) fail(where + "child with a bad cell");
        if (child.begin != at) fail(where + "children do not split the point range in order");
        at = child.end;
        stack.push_back(node.first_child + c);
      }
      if (at != node.end) fail(where + "children do not cover the point range");
    }
    if (visited != nodes_.size()) fail("unreachable nodes");
    // Now that the links are sound, follow them: each point must descend to its own leaf.
    for (std::uint32_t v = 0; v < nodes_.size(); ++v) {
      if (!nodes_[v].leaf()) continue;
      for (std::uint32_t i = nodes_[v].begin; i < nodes_[v].end; ++i)
        if (locate(point(perm_[i])) != v)
          fail("node " + std::to_string(v) + ": point " + std::to_string(perm_[i]) + " is located elsewhere");
    }
    if (!balanced_) return;
    for (std::uint32_t v = 0; v < nodes_.size(); ++v)
      if (nodes_[v].leaf() && must_refine(nodes_, v)) fail("node " + std::to_string(v) + ": not 2:1 balanced");
  }

  // ---------------------------------------------------------------- files
  /// Writes the tree and its points as a "spatial.Orthtree" archive
  /// (core/archive.hpp): value sections scalar, dim, bucket, max_depth,
  /// balanced, root_side; arrays root_lo (Dim doubles), nodes, permutation,
  /// points (n x Dim, row-major).
  void save(const std::filesystem::path& path) const {
    ArchiveWriter w(std::string(kOrthtreeArchiveKind), kOrthtreeArchiveVersion);
    w.add_dtype("scalar", dtype_of<T>());
    w.add_value("dim", std::uint64_t(Dim));
    w.add_value("bucket", std::uint64_t(bucket_));
    w.add_value("max_depth", std::uint32_t(max_depth_));
    w.add_value("balanced", std::uint32_t(balanced_));
    w.add_value("root_side", side_);
    w.add("root_lo", std::span<const double>(lo_.data(), Dim));
    w.add("nodes", nodes_);
    w.add("permutation", perm_);
    w.add("points", points_ ? points_->span() : std::span<const T>());
    w.write(path);
  }

  /// Maps a tree written by save(): nodes, permutation and points are read in
  /// place from the file. Throws geods::Error naming the file for another
  /// scalar type or dimension, a truncated or corrupt file (checksums, unless
  /// `verify` says structure_only) or contents that fail validate().
  static Orthtree load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums) {
    const Archive a = Archive::open(path, kOrthtreeArchiveKind, kOrthtreeArchiveVersion, verify);
    a.require_dtype<T>("scalar", Dim == 2 ? "quadtree" : "octree");
    const std::uint64_t dim = a.value<std::uint64_t>("dim");
    if (dim != std::uint64_t(Dim))
      throw a.error("a tree of dimension " + std::to_string(dim) + ", expected " + std::to_string(Dim));
    Orthtree tree;
    const std::uint64_t bucket = a.value<std::uint64_t>("bucket");
    const std::uint32_t max_depth = a.value<std::uint32_t>("max_depth"), balanced = a.value<std::uint32_t>("balanced");
    if (bucket == 0 || max_depth > std::uint32_t(kMaxDepth) || balanced > 1) throw a.error("bad quadtree/octree parameters");
    tree.bucket_ = std::size_t(bucket);
    tree.max_depth_ = int(max_depth);
    tree.balanced_ = balanced == 1;
    tree.side_ = a.value<double>("root_side");
    const FlatArray<double> lo = a.array<double>("root_lo", Dim);
    std::copy(lo.begin(), lo.end(), tree.lo_.data());
    auto points = std::make_shared<const FlatArray<T>>(a.array<T>("points"));
    if (points->size() % Dim != 0 || points->size() / Dim >= kNoNode)
      throw a.error(std::to_string(points->size()) + " coordinates are not a point set of dimension " +
                    std::to_string(Dim));
    tree.points_ = std::move(points);
    tree.nodes_ = a.array<Node>("nodes");
    if (tree.nodes_.size() >= kNoNode) throw a.error("too many quadtree/octree nodes");
    tree.perm_ = a.array<std::uint32_t>("permutation", tree.size());
    try {
      tree.validate();
    } catch (const Error& e) {
      throw a.error(std::string("corrupted tree: ") + e.what());
    }
    return tree;
  }

 private:
  static_assert(sizeof(Node) == 4 * (5 + Dim), "Node is written to files as is");
  static_assert(std::is_trivially_copyable_v<Node>);

  // ---------------------------------------------------------------- geometry
  // 2^-d for every depth: k * 2^-d is exact, so every caller gets the same rounding.
  static constexpr std::array<double, kMaxDepth + 2> kScale = [] {
    std::array<double, kMaxDepth + 2> s{};
    double x = 1;
    for (double& v : s) v = x, x /= 2;
    return s;
  }();

  // Coordinate k / 2^depth of the root along axis a (k may be a half-integer).
  double coordinate(double k, std::uint32_t depth, int a) const { return lo_[a] + side_ * (k * kScale[depth]); }

  Vec<double, Dim> middle(const Node& node) const {
    Vec<double, Dim> mid;
    for (int a = 0; a < Dim; ++a) mid[a] = coordinate(node.cell[a] + 0.5, node.depth, a);
    return mid;
  }
  static std::uint32_t slot_of(const Vec<double, Dim>& mid, const VecT& p) {
    std::uint32_t slot = 0;
    for (int a = 0; a < Dim; ++a)
      if (double(p[a]) > mid[a]) slot |= 1u << a;
    return slot;
  }
  std::uint32_t child_slot(const Node& node, const VecT& p) const { return slot_of(middle(node), p); }

  // neighbor() over a node array (the tree's, or one being balanced).
  static std::uint32_t neighbor_in(std::span<const Node> nodes, std::uint32_t v, Direction dir) {
    const int axis = int(dir) / 2;
    const std::uint32_t toward = int(dir) % 2 == 0 ? 1 : 0;  // the slot bit on the side we move to
    const std::uint32_t flip = 1u << axis;
    // Climb while v is on the `dir` side of its parent (its neighbor lies outside
    // the parent), recording the slots; the first sibling across is the turn.
    std::array<std::uint8_t, kMaxDepth + 1> path;
    std::size_t len = 0;
    std::uint32_t u = v;
    for (;;) {
      if (u == 0) return kNoNode;
      const Node& p = nodes[nodes[u].parent];
      const std::uint32_t slot = u - p.first_child;
      if (((slot >> axis) & 1) != toward) {
        u = p.first_child + (slot ^ flip);
        break;
      }
      path[len++] = std::uint8_t(slot);
      u = nodes[u].parent;
    }
    // Come down mirrored while the nodes are inner (a leaf is the answer itself).
    while (len > 0 && !nodes[u].leaf()) u = nodes[u].first_child + (path[--len] ^ flip);
    return u;
  }


  bool coincident(std::span<const std::uint32_t> perm, const Node& node) const {
    if (node.end - node.begin < 2) return true;
    const VecT first = point(perm[node.begin]);
    for (std::uint32_t i = node.begin + 1; i < node.end; ++i)
      if (point(perm[i]) != first) return false;
    return true;
  }

  bool must_split(std::span<const std::uint32_t> perm, const Node& node) const {
    return node.end - node.begin > bucket_ && int(node.depth) < max_depth_ && !coincident(perm, node);
  }

  // A leaf must be refined for the 2:1 condition iff a same-depth neighbor has an
  // inner child on the face toward it (a leaf two or more levels deeper touches it).
  static bool must_refine(std::span<const Node> nodes, std::uint32_t mu) {
    for (int d = 0; d < 2 * Dim; ++d) {
      const std::uint32_t nb = neighbor_in(nodes, mu, Direction(d));
      if (nb == kNoNode || nodes[nb].leaf()) continue;
      const int axis = d / 2;
      const std::uint32_t near_bit = d % 2 == 0 ? 0 : 1;  // the neighbor's children facing mu
      for (std::uint32_t c = 0; c < kChildren; ++c)
        if (((c >> axis) & 1) == near_bit && !nodes[nodes[nb].first_child + c].leaf()) return true;
    }
    return false;
  }

  // ---------------------------------------------------------------- build
  void build(PointView<T> view, const OrthtreeOptions& options) {
    if (options.bucket == 0) throw Error("Orthtree: bucket must be >= 1");
    if (options.max_depth < -1 || options.max_depth > kMaxDepth)
      throw Error("Orthtree: max_depth must be in [0, " + std::to_string(kMaxDepth) + "] (or -1), got " +
                  std::to_string(options.max_depth));
    if (view.dim != std::size_t(Dim))
      throw Error("Orthtree: points of dimension " + std::to_string(view.dim) + ", expected " + std::to_string(Dim));
    if (view.count >= kNoNode)
      throw Error("Orthtree: " + std::to_string(view.count) + " points, at most 2^32 - 2 are supported");
    if (view.count > 0 && (view.data == nullptr || view.stride < view.dim)) throw Error("Orthtree: bad point array");
    bucket_ = options.bucket;
    max_depth_ = options.max_depth < 0 ? kMaxDepth : options.max_depth;
    const std::size_t n = view.count;
    std::vector<T> points(n * Dim);
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < Dim; ++a) {
        const T x = view[i][a];
        if (!std::isfinite(x))
          throw Error("Orthtree: point " + std::to_string(i) + " has a non-finite coordinate (axis " +
                      std::to_string(a) + ")");
        points[i * Dim + a] = x;
      }
    }
    check_coordinate_range(points.data(), n, Dim, Dim, 2, "Orthtree");
    points_ = std::make_shared<const FlatArray<T>>(std::move(points));
    if (n == 0) return;
    root_square();
    std::vector<Node> nodes;
    std::vector<std::uint32_t> perm(n);
    if (options.build == OrthtreeBuild::morton) {
      const std::vector<std::uint64_t> keys = sorted_morton_keys(perm);
      build_levels(nodes, perm, [&](std::uint32_t v) { split_by_keys(nodes, v, keys); });
    } else {
      std::iota(perm.begin(), perm.end(), 0u);
      std::vector<std::uint32_t> scratch(n);
      build_levels(nodes, perm, [&](std::uint32_t v) { split_points(nodes, perm, v, scratch.data()); });
    }
    parallel_for_each_index(0, nodes.size(), [&](std::size_t v) {
      if (nodes[v].leaf()) std::sort(perm.begin() + nodes[v].begin, perm.begin() + nodes[v].end);
    }, 256);
    nodes_ = std::move(nodes);
    perm_ = std::move(perm);
  }

  void root_square() {
    AABB<double, Dim> box;
    for (std::size_t i = 0; i < size(); ++i) box.extend(point(i).template cast<double>());
    lo_ = box.lo;
    side_ = box.extent().maxCoeff();
    // Rounding in hi - lo may leave lo + side a hair short of hi: grow by ulps.
    for (int a = 0; a < Dim; ++a)
      while (lo_[a] + side_ < box.hi[a]) side_ = std::nextafter(side_, std::numeric_limits<double>::infinity());
  }

  // Splits the nodes level by level: which nodes split is decided in parallel,
  // children are numbered in order (breadth first), then each splitting node
  // fills its children (and orders its points) in parallel.
  template <typename Partition>
  void build_levels(std::vector<Node>& nodes, std::span<const std::uint32_t> perm, const Partition& partition) const {
    nodes.assign(1, Node{0, kNoNode, 0, std::uint32_t(size()), 0, {}});
    std::vector<std::uint8_t> splits;
    for (std::size_t level_begin = 0, level_end = 1; level_begin < level_end;) {
      splits.assign(level_end - level_begin, 0);
      parallel_for_each_index(0, splits.size(),
                              [&](std::size_t i) { splits[i] = must_split(perm, nodes[level_begin + i]); }, 64);
      std::size_t next = nodes.size();
      for (std::size_t i = 0; i < splits.size(); ++i) {
        if (!splits[i]) continue;
        nodes[level_begin + i].first_child = std::uint32_t(next);
        next += kChildren;
        if (next >= kNoNode) throw Error("Orthtree: more than 2^32 - 2 nodes");
      }
      nodes.resize(next);
      parallel_for_each_index(0, splits.size(), [&](std::size_t i) {
        if (splits[i]) partition(std::uint32_t(level_begin + i));
      }, 16);
      level_begin = level_end;
      level_end = next;
    }
  }

  // Fills the children of v (already allocated) given where their point ranges start.
  static void make_children(std::vector<Node>& nodes, std::uint32_t v,
                            const std::array<std::uint32_t, kChildren + 1>& bounds) {
    const Node parent = nodes[v];
    for (std::uint32_t c = 0; c < kChildren; ++c) {
      Node& child = nodes[parent.first_child + c];
      child = Node{0, v, bounds[c], bounds[c + 1], parent.depth + 1, {}};
      for (int a = 0; a < Dim; ++a) child.cell[a] = 2 * parent.cell[a] + ((c >> a) & 1);
    }
  }

  // Top-down: a counting sort of v's points by child slot (scratch: n entries).
  void split_points(std::vector<Node>& nodes, std::vector<std::uint32_t>& perm, std::uint32_t v,
                    std::uint32_t* scratch) const {
    const Node node = nodes[v];
    const Vec<double, Dim> mid = middle(node);
    std::array<std::uint32_t, kChildren + 1> bounds{};
    for (std::uint32_t i = node.begin; i < node.end; ++i) {
      scratch[i] = perm[i];
      ++bounds[slot_of(mid, point(perm[i])) + 1];
    }
    bounds[0] = node.begin;
    for (std::uint32_t c = 0; c < kChildren; ++c) bounds[c + 1] += bounds[c];
    std::array<std::uint32_t, kChildren> at;
    std::copy(bounds.begin(), bounds.end() - 1, at.begin());
    for (std::uint32_t i = node.begin; i < node.end; ++i) perm[at[slot_of(mid, point(scratch[i]))]++] = scratch[i];
    make_children(nodes, v, bounds);
  }

  // Linear: the key of a point is its cell path down to max_depth, taken by the
  // same comparisons as the top-down build, as interleaved (Morton) digits.
  // Sorted by (key, index), every node's points are a run of perm and its
  // children are sub-runs. Returns the keys in perm order.
  std::vector<std::uint64_t> sorted_morton_keys(std::vector<std::uint32_t>& perm) const {
    const std::size_t n = size();
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
    parallel_for_each_index(0, n, [&](std::size_t i) {
      Node cell{0, kNoNode, 0, 0, 0, {}};
      for (int d = 0; d < max_depth_; ++d) {
        const std::uint32_t slot = child_slot(cell, point(i));
        for (int a = 0; a < Dim; ++a) cell.cell[a] = 2 * cell.cell[a] + ((slot >> a) & 1);
        ++cell.depth;
      }
      if constexpr (Dim == 2) {
        keyed[i] = {morton2d_encode64(cell.cell[0], cell.cell[1]), std::uint32_t(i)};
      } else {
        keyed[i] = {morton3d_encode64(cell.cell[0], cell.cell[1], cell.cell[2]), std::uint32_t(i)};
      }
    });
    tbb::parallel_sort(keyed.begin(), keyed.end());
    std::vector<std::uint64_t> keys(n);
    parallel_for_each_index(0, n, [&](std::size_t i) {
      keys[i] = keyed[i].first;
      perm[i] = keyed[i].second;
    });
    return keys;
  }

  void split_by_keys(std::vector<Node>& nodes, std::uint32_t v, const std::vector<std::uint64_t>& keys) const {
    const Node node = nodes[v];
    const int shift = Dim * (max_depth_ - 1 - int(node.depth));  // v's digit: the slot of its child
    std::array<std::uint32_t, kChildren + 1> bounds;
    bounds[0] = node.begin;
    for (std::uint32_t c = 0; c < kChildren; ++c) {
      const auto first = keys.begin() + bounds[c], last = keys.begin() + node.end;
      bounds[c + 1] = std::uint32_t(
          std::partition_point(first, last, [&](std::uint64_t key) { return ((key >> shift) & (kChildren - 1)) <= c; }) -
          keys.begin());
    }
    make_children(nodes, v, bounds);
  }

  // Balancing: turns leaf v into an inner node with children appended at the end.
  void split(std::vector<Node>& nodes, std::vector<std::uint32_t>& perm, std::uint32_t v, std::uint32_t* scratch) const {
    nodes[v].first_child = std::uint32_t(nodes.size());
    if (nodes.size() + kChildren >= kNoNode) throw Error("Orthtree: more than 2^32 - 2 nodes");
    nodes.resize(nodes.size() + kChildren);
    split_points(nodes, perm, v, scratch);
    for (std::uint32_t c = 0; c < kChildren; ++c) {
      const Node& child = nodes[nodes[v].first_child + c];
      std::sort(perm.begin() + child.begin, perm.begin() + child.end);
    }
  }

  // ---------------------------------------------------------------- search
  void check_point(const VecT& p, const char* what) const {
    for (int a = 0; a < Dim; ++a)
      if (!std::isfinite(p[a])) throw Error(std::string("Orthtree: ") + what + " has a non-finite coordinate");
  }

  static T squared_distance(const VecT& q, const VecT& p) {
    T d = 0;
    for (int a = 0; a < Dim; ++a) {
      const T t = q[a] - p[a];
      d += t * t;
    }
    return d;
  }

  // Rounding slack: a cell's distance is compared with point distances computed in T.
  static constexpr double kSlack = 1 + 4.0 * (Dim + 2) * std::numeric_limits<T>::epsilon();

  // The cell of child `slot` of a node with cell `box` and middle `mid` (the same
  // doubles node_bounds() gives: the middle is the children's shared corner).
  static Box child_box(const Box& box, const Vec<double, Dim>& mid, std::uint32_t slot) {
    Box child = box;
    for (int a = 0; a < Dim; ++a) ((slot >> a) & 1 ? child.lo[a] : child.hi[a]) = mid[a];
    return child;
  }

  void search_knn(std::uint32_t v, const Box& box, const VecT& q, const Vec<double, Dim>& qd,
                  KnnResultSet<T>& result) const {
    const Node& node = nodes_[v];
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) result.insert(perm_[i], squared_distance(q, point(perm_[i])));
      return;
    }
    // Nearest child first, so the k-th distance shrinks early.
    const Vec<double, Dim> mid = middle(node);
    std::array<std::pair<double, std::uint32_t>, kChildren> order;
    for (std::uint32_t c = 0; c < kChildren; ++c) {
      const Node& child = nodes_[node.first_child + c];
      order[c] = {child.begin == child.end ? std::numeric_limits<double>::infinity()
                                           : child_box(box, mid, c).squared_distance(qd),
                  c};
    }
    std::sort(order.begin(), order.end());
    for (const auto& [d2, c] : order) {
      if (!(d2 <= double(result.worst()) * kSlack)) break;
      search_knn(node.first_child + c, child_box(box, mid, c), q, qd, result);
    }
  }

  void search_radius(std::uint32_t v, const VecT& q, T r2, std::vector<Neighbor<T>>& out) const {
    const Node& node = nodes_[v];
    if (node.begin == node.end || !(node_bounds(v).squared_distance(q.template cast<double>()) <= double(r2) * kSlack))
      return;
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        const T d = squared_distance(q, point(perm_[i]));
        if (d <= r2) out.push_back({perm_[i], d});
      }
      return;
    }
    for (std::uint32_t c = 0; c < kChildren; ++c) search_radius(node.first_child + c, q, r2, out);
  }

  template <bool Report>
  std::size_t box_search(const VecT& lo, const VecT& hi, std::vector<std::uint32_t>* out) const {
    check_point(lo, "box low corner");
    check_point(hi, "box high corner");
    if (nodes_.empty()) return 0;
    std::size_t count = 0;
    box_node<Report>(0, Box(lo.template cast<double>(), hi.template cast<double>()), lo, hi, count, out);
    return count;
  }

  template <bool Report>
  void box_node(std::uint32_t v, const Box& box, const VecT& lo, const VecT& hi, std::size_t& count,
                std::vector<std::uint32_t>* out) const {
    const Node& node = nodes_[v];
    if (node.begin == node.end) return;
    const Box cell = node_bounds(v);
    if (!cell.overlaps(box)) return;
    if (box.contains(cell)) {
      count += node.end - node.begin;
      if constexpr (Report) out->insert(out->end(), perm_.begin() + node.begin, perm_.begin() + node.end);
      return;
    }
    if (node.leaf()) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        const VecT p = point(perm_[i]);
        if ((p.array() >= lo.array()).all() && (p.array() <= hi.array()).all()) {
          ++count;
          if constexpr (Report) out->push_back(perm_[i]);
        }
      }
      return;
    }
    for (std::uint32_t c = 0; c < kChildren; ++c) box_node<Report>(node.first_child + c, box, lo, hi, count, out);
  }

  std::shared_ptr<const FlatArray<T>> points_;  // n x Dim coordinates, shared by copies and balanced trees
  std::size_t bucket_ = 1;
  int max_depth_ = kMaxDepth;
  bool balanced_ = false;
  Vec<double, Dim> lo_ = Vec<double, Dim>::Zero();
  double side_ = 0;
  FlatArray<Node> nodes_;
  FlatArray<std::uint32_t> perm_;
};

template <typename T = double>
using Quadtree = Orthtree<T, 2>;
template <typename T = double>
using Octree = Orthtree<T, 3>;

}  // namespace geods::spatial
