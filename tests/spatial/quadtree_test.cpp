// Quadtree and octree: the definition (validate), top-down == Morton build,
// Theorems 1 and 2, neighbor finding against a brute-force adjacency oracle,
// 2:1 balancing against an all-pairs oracle, queries against brute force, bad input.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "common/archive_files.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/spatial/quadtree.hpp"

namespace geods::spatial {
namespace {

enum class Shape2 { uniform, clustered, duplicated, line, identical, grid };
const Shape2 kShapes2[] = {Shape2::uniform, Shape2::clustered, Shape2::duplicated,
                           Shape2::line,    Shape2::identical, Shape2::grid};

std::string name(Shape2 s) {
  const char* names[] = {"uniform", "clustered", "duplicated", "line", "identical", "grid"};
  return names[int(s)];
}

template <typename T, int D>
std::vector<Vec<T, D>> make_points(Shape2 shape, std::size_t n, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec<double, D>> centers(6), distinct(15);
  for (auto& c : centers) for (int a = 0; a < D; ++a) c[a] = rng.uniform(-5, 5);
  for (auto& c : distinct) for (int a = 0; a < D; ++a) c[a] = rng.uniform(-5, 5);
  Vec<double, D> origin, dir;
  for (int a = 0; a < D; ++a) origin[a] = rng.uniform(), dir[a] = rng.normal();
  std::vector<Vec<T, D>> points(n);
  for (auto& p : points) {
    const std::size_t c = rng.below(centers.size()), e = rng.below(distinct.size());
    const double s = rng.uniform(-1, 1);
    // Clusters of very different spread make deep, unbalanced trees.
    const double spread = std::pow(10.0, -1.0 - double(c));
    for (int a = 0; a < D; ++a) {
      switch (shape) {
        case Shape2::uniform: p[a] = T(rng.uniform(-3, 7)); break;
        case Shape2::clustered: p[a] = T(centers[c][a] + spread * rng.normal()); break;
        case Shape2::duplicated: p[a] = T(distinct[e][a]); break;
        case Shape2::line: p[a] = T(origin[a] + s * dir[a]); break;
        case Shape2::identical: p[a] = T(0.25); break;
        case Shape2::grid: p[a] = T(rng.below(6)); break;
      }
    }
  }
  return points;
}

template <typename T, int D>
using Tree = Orthtree<T, D>;

// Cells as integer boxes at the finer of two depths: node u covers [c << s, (c + 1) << s) at depth d(u) + s.
struct IntCell {
  std::uint64_t lo[3], hi[3];
};
template <typename T, int D>
IntCell int_cell(const Tree<T, D>& tree, std::uint32_t u, std::uint32_t depth) {
  const auto& n = tree.node(u);
  IntCell c{};
  for (int a = 0; a < D; ++a) {
    c.lo[a] = std::uint64_t(n.cell[a]) << (depth - n.depth);
    c.hi[a] = std::uint64_t(n.cell[a] + 1ull) << (depth - n.depth);
  }
  return c;
}

// Brute force: the deepest node of depth <= depth(v) across v's face in direction dir.
template <typename T, int D>
std::uint32_t neighbor_oracle(const Tree<T, D>& tree, std::uint32_t v, int dir) {
  const int axis = dir / 2;
  const bool positive = dir % 2 == 0;
  const std::uint32_t dv = tree.node(v).depth;
  const IntCell cv = int_cell(tree, v, dv);
  std::uint32_t best = kNoNode;
  for (std::uint32_t u = 0; u < tree.nodes().size(); ++u) {
    if (tree.node(u).depth > dv) continue;
    const IntCell cu = int_cell(tree, u, dv);
    bool adjacent = positive ? cu.lo[axis] == cv.hi[axis] : cu.hi[axis] == cv.lo[axis];
    for (int a = 0; a < D && adjacent; ++a)
      if (a != axis) adjacent = cu.lo[a] <= cv.lo[a] && cv.hi[a] <= cu.hi[a];
    if (adjacent && (best == kNoNode || tree.node(u).depth > tree.node(best).depth)) best = u;
  }
  return best;
}

// Brute force: do two leaves sharing a face (a (D-1)-dimensional patch) differ by more than one in depth?
template <typename T, int D>
bool balanced_oracle(const Tree<T, D>& tree) {
  std::vector<std::uint32_t> leaves;
  std::uint32_t deepest = 0;
  for (std::uint32_t v = 0; v < tree.nodes().size(); ++v) {
    if (tree.node(v).leaf()) leaves.push_back(v);
    deepest = std::max(deepest, tree.node(v).depth);
  }
  std::vector<IntCell> cells;
  for (std::uint32_t v : leaves) cells.push_back(int_cell(tree, v, deepest));
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    for (std::size_t j = i + 1; j < leaves.size(); ++j) {
      const int di = int(tree.node(leaves[i]).depth), dj = int(tree.node(leaves[j]).depth);
      if (std::abs(di - dj) <= 1) continue;
      int touching = 0, overlapping = 0;
      for (int a = 0; a < D; ++a) {
        if (cells[i].hi[a] == cells[j].lo[a] || cells[j].hi[a] == cells[i].lo[a]) ++touching;
        else if (cells[i].lo[a] < cells[j].hi[a] && cells[j].lo[a] < cells[i].hi[a]) ++overlapping;
      }
      if (touching == 1 && overlapping == D - 1) return false;
    }
  }
  return true;
}

template <typename T, int D>
T sq_dist(const Vec<T, D>& q, const Vec<T, D>& p) {
  T d = 0;
  for (int a = 0; a < D; ++a) {
    const T t = q[a] - p[a];
    d += t * t;
  }
  return d;
}

template <typename T, int D>
std::vector<Neighbor<T>> brute_all(const std::vector<Vec<T, D>>& points, const Vec<T, D>& q) {
  std::vector<Neighbor<T>> all;
  for (std::uint32_t i = 0; i < points.size(); ++i) all.push_back({i, sq_dist(q, points[i])});
  std::sort(all.begin(), all.end());
  return all;
}

template <typename T, int D>
void check_queries(const Tree<T, D>& tree, const std::vector<Vec<T, D>>& points, std::uint64_t seed) {
  Rng rng(seed);
  const auto root = tree.root_bounds();
  for (int t = 0; t < 40; ++t) {
    Vec<T, D> q;
    if (t % 2 == 0 && !points.empty()) {
      q = points[rng.below(points.size())];  // on a data point: distance-0 ties and duplicates
    } else {
      for (int a = 0; a < D; ++a) q[a] = T(rng.uniform(root.lo[a] - 1, root.hi[a] + 1));
    }
    const auto all = brute_all(points, q);
    for (std::size_t k : {std::size_t(1), std::size_t(5), std::size_t(17)}) {
      std::vector<Neighbor<T>> expected(all.begin(), all.begin() + std::min(k, all.size()));
      ASSERT_EQ(tree.query(q, k), expected) << "k = " << k;
    }
    const double r = rng.uniform(0, 2);
    std::vector<Neighbor<T>> within;
    for (const auto& nb : all)
      if (nb.squared_distance <= T(r * r)) within.push_back(nb);
    ASSERT_EQ(tree.query_radius(q, r), within);

    Vec<T, D> lo, hi;
    for (int a = 0; a < D; ++a) {
      T x = T(rng.uniform(root.lo[a] - 0.5, root.hi[a] + 0.5)), y = T(rng.uniform(root.lo[a] - 0.5, root.hi[a] + 0.5));
      if (t % 4 == 1 && !points.empty()) x = y = points[rng.below(points.size())][a];  // degenerate box on a point
      lo[a] = std::min(x, y);
      hi[a] = std::max(x, y);
    }
    std::vector<std::uint32_t> in_box;
    for (std::uint32_t i = 0; i < points.size(); ++i)
      if ((points[i].array() >= lo.array()).all() && (points[i].array() <= hi.array()).all()) in_box.push_back(i);
    std::vector<std::uint32_t> got = tree.query_box(lo, hi);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, in_box);
    ASSERT_EQ(tree.count_box(lo, hi), in_box.size());

    const std::uint32_t leaf = tree.locate(q);
    if (root.contains(q.template cast<double>())) {
      ASSERT_NE(leaf, kNoNode);
      ASSERT_TRUE(tree.node(leaf).leaf());
      ASSERT_TRUE(tree.node_bounds(leaf).contains(q.template cast<double>()));
    } else {
      ASSERT_EQ(leaf, kNoNode);
    }
  }
}

// Every node of small trees, a sample of about 1000 of large ones (the oracle is O(m) per call).
template <typename T, int D>
void check_neighbors(const Tree<T, D>& tree) {
  const std::size_t step = tree.nodes().size() / 1000 + 1;
  for (std::uint32_t v = 0; v < tree.nodes().size(); v += std::uint32_t(step))
    for (int dir = 0; dir < 2 * D; ++dir)
      ASSERT_EQ(tree.neighbor(v, Direction(dir)), neighbor_oracle(tree, v, dir)) << "node " << v << " dir " << dir;
}

// Smallest distance between two distinct points (0 if there are none).
template <typename T, int D>
double smallest_distance(const std::vector<Vec<T, D>>& points) {
  double c = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t j = i + 1; j < points.size(); ++j) {
      const double d = (points[i].template cast<double>() - points[j].template cast<double>()).norm();
      if (d > 0) c = std::min(c, d);
    }
  return c;
}

template <typename T, int D>
void check_shape(Shape2 shape, std::size_t n, std::size_t bucket, bool all_checks) {
  SCOPED_TRACE(name(shape) + " n=" + std::to_string(n) + " bucket=" + std::to_string(bucket) + " D=" +
               std::to_string(D) + (sizeof(T) == 4 ? " float" : " double"));
  const auto points = make_points<T, D>(shape, n, 7 * n + int(shape) + 100 * D);
  const Tree<T, D> tree(points, {.bucket = bucket});
  tree.validate();
  const Tree<T, D> linear(points, {.bucket = bucket, .build = OrthtreeBuild::morton});
  linear.validate();
  ASSERT_EQ(linear.nodes(), tree.nodes());
  ASSERT_EQ(linear.permutation(), tree.permutation());

  // Theorem 1 (any dimension): an inner node holds two points at distance >= c in a
  // cell of diameter sqrt(D) s / 2^depth, so depth <= log2(s / c) + log2(D) / 2 + 1.
  const OrthtreeStats stats = tree.stats();
  const double c = smallest_distance(points);
  if (std::isfinite(c)) {
    EXPECT_LE(double(stats.depth), std::log2(tree.root_side() / c) + std::log2(double(D)) / 2 + 1 + 1e-9);
  } else {
    EXPECT_EQ(stats.nodes, 1u);  // all points coincide: one leaf
  }
  // Theorem 2: at most n / (bucket + 1) inner nodes per depth, 2^D children each.
  const std::size_t inner = stats.nodes - stats.leaves;
  EXPECT_EQ(stats.nodes, 1 + (std::size_t(1) << D) * inner);
  EXPECT_LE(inner, std::max<std::size_t>(stats.depth, 1) * (n / (bucket + 1)));

  check_queries(tree, points, n + 1);
  if (!all_checks) return;
  check_neighbors(tree);
  const Tree<T, D> balanced = tree.balanced();
  ASSERT_TRUE(balanced.is_balanced());
  balanced.validate();
  EXPECT_TRUE(balanced_oracle(balanced));
  if (shape == Shape2::clustered) {
    EXPECT_FALSE(balanced_oracle(tree));  // so balancing had work to do
    EXPECT_GT(balanced.nodes().size(), tree.nodes().size());
  }
  EXPECT_EQ(balanced.stats().depth, stats.depth);  // balancing never deepens the tree
  // A refinement of the original: every original cell is still a node.
  std::map<std::pair<std::uint32_t, std::array<std::uint32_t, D>>, std::uint32_t> cells;
  for (std::uint32_t v = 0; v < balanced.nodes().size(); ++v)
    cells[{balanced.node(v).depth, balanced.node(v).cell}] = v;
  for (const auto& node : tree.nodes()) ASSERT_TRUE(cells.count({node.depth, node.cell}));
  EXPECT_EQ(balanced.balanced().nodes().size(), balanced.nodes().size());  // already balanced
  check_neighbors(balanced);
  check_queries(balanced, points, n + 2);
}

TEST(Quadtree, ShapesAgainstOracles) {
  for (Shape2 shape : kShapes2) {
    check_shape<double, 2>(shape, 300, 1, true);
    check_shape<float, 2>(shape, 300, 3, true);
    check_shape<double, 2>(shape, 3000, 1, false);
  }
}

TEST(Octree, ShapesAgainstOracles) {
  for (Shape2 shape : kShapes2) {
    check_shape<double, 3>(shape, 150, 1, true);
    check_shape<float, 3>(shape, 200, 4, true);
    check_shape<double, 3>(shape, 3000, 2, false);
  }
}

TEST(Quadtree, SeedDefinitionSmallExample) {
  // The square [0, 4]^2; points on a middle line go to the low (W or S) side.
  const std::vector<Vec2d> points{{0, 0}, {4, 4}, {2, 2}, {3, 1}};
  const Quadtree<> tree(points);
  tree.validate();
  EXPECT_EQ(tree.root_side(), 4.0);
  const auto& root = tree.node(0);
  ASSERT_FALSE(root.leaf());
  // Slots: 0 SW, 1 SE, 2 NW, 3 NE. (2, 2) is on both middle lines: SW.
  const auto& sw = tree.node(root.first_child + 0);
  EXPECT_EQ(sw.end - sw.begin, 2u);  // (0, 0) and (2, 2)
  EXPECT_EQ(tree.node(root.first_child + 1).end - tree.node(root.first_child + 1).begin, 1u);  // (3, 1)
  EXPECT_EQ(tree.node(root.first_child + 3).end - tree.node(root.first_child + 3).begin, 1u);  // (4, 4)
  EXPECT_EQ(tree.locate(Vec2d(2, 2)), tree.locate(Vec2d(1.5, 1.5)));
  EXPECT_EQ(tree.locate(Vec2d(4.5, 1)), kNoNode);
  // North of SW is NW, east of SW is SE, south of SW is nothing.
  EXPECT_EQ(tree.neighbor(root.first_child, kNorth), root.first_child + 2);
  EXPECT_EQ(tree.neighbor(root.first_child, kEast), root.first_child + 1);
  EXPECT_EQ(tree.neighbor(root.first_child, kSouth), kNoNode);
  EXPECT_EQ(tree.neighbor(0, kWest), kNoNode);
}

TEST(Quadtree, CoincidentPointsAndDepthLimit) {
  // Near-duplicates one ulp apart split down to max_depth; exact duplicates stop at once.
  std::vector<Vec2d> points(50, Vec2d(0.5, 0.5));
  points.push_back({0.5, std::nextafter(0.5, 1.0)});
  points.push_back({0, 0});
  const Quadtree<> tree(points);
  tree.validate();
  EXPECT_EQ(tree.stats().depth, std::size_t(Quadtree<>::kMaxDepth));
  const Quadtree<> shallow(points, {.max_depth = 4});
  shallow.validate();
  EXPECT_EQ(shallow.stats().depth, 4u);
  const Quadtree<> linear(points, {.max_depth = 4, .build = OrthtreeBuild::morton});
  EXPECT_EQ(linear.nodes(), shallow.nodes());
  const Quadtree<> zero(points, {.max_depth = 0});
  zero.validate();
  EXPECT_EQ(zero.nodes().size(), 1u);

  const std::vector<Vec2d> same(1000, Vec2d(-3, 7));
  const Quadtree<> one(same);
  one.validate();
  EXPECT_EQ(one.nodes().size(), 1u);
  EXPECT_EQ(one.query(Vec2d(0, 0), 3).size(), 3u);
  EXPECT_EQ(one.balanced().nodes().size(), 1u);
}

TEST(Quadtree, ParallelBuildMatchesSequential) {
  const auto points = make_points<double, 2>(Shape2::clustered, 200000, 5);
  const Quadtree<> parallel_td(points, {.bucket = 8});
  const Quadtree<> parallel_morton(points, {.bucket = 8, .build = OrthtreeBuild::morton});
  set_num_threads(1);
  const Quadtree<> sequential(points, {.bucket = 8});
  set_num_threads(0);
  EXPECT_EQ(parallel_td.nodes(), sequential.nodes());
  EXPECT_EQ(parallel_morton.nodes(), sequential.nodes());
  EXPECT_EQ(parallel_morton.permutation(), sequential.permutation());
  sequential.validate();
}

TEST(Octree, BalancingLargeClusteredTree) {
  const auto points = make_points<float, 3>(Shape2::clustered, 20000, 9);
  const Octree<float> tree(points);
  const Octree<float> balanced = tree.balanced();
  balanced.validate();
  EXPECT_GT(balanced.nodes().size(), tree.nodes().size());
  EXPECT_LE(balanced.nodes().size(), 16 * tree.nodes().size());  // O(m) nodes
}

TEST(Orthtree, SaveLoad) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("geods_qt_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto points = make_points<float, 3>(Shape2::clustered, 500, 3);
  const Octree<float> tree(points, {.bucket = 2, .max_depth = 12});
  const Octree<float> balanced = tree.balanced();
  for (const Octree<float>* t : {&tree, &balanced}) {
    t->save(dir / "t.geods");
    const Octree<float> loaded = Octree<float>::load(dir / "t.geods");
    EXPECT_EQ(loaded.nodes(), t->nodes());
    EXPECT_EQ(loaded.permutation(), t->permutation());
    EXPECT_EQ(loaded.is_balanced(), t->is_balanced());
    EXPECT_EQ(loaded.bucket(), 2u);
    EXPECT_EQ(loaded.query(points[7], 4), t->query(points[7], 4));
    EXPECT_TRUE(loaded.nodes().mapped());  // read in place
    EXPECT_TRUE(loaded.permutation().mapped());
  }
  EXPECT_THROW(Octree<double>::load(dir / "t.geods"), Error);    // other scalar type
  EXPECT_THROW(Quadtree<float>::load(dir / "t.geods"), Error);   // other dimension
  EXPECT_THROW(Octree<float>::load(dir / "missing.geods"), Error);
  // Truncated, and single corrupted bytes: an Error or a tree that validates, never a crash
  // (with the checksums skipped, so that validate() sees the corruption).
  const std::vector<char> bytes = test::read_bytes(dir / "t.geods");
  test::write_bytes(dir / "short.geods", std::vector<char>(bytes.begin(), bytes.end() - 5));
  EXPECT_THROW(Octree<float>::load(dir / "short.geods"), Error);
  Rng rng(1);
  for (int t = 0; t < 200; ++t) {
    std::vector<char> bad = bytes;
    bad[rng.below(bad.size())] ^= char(1 + rng.below(255));
    test::write_bytes(dir / "bad.geods", bad);
    for (auto verify : {Archive::Verify::checksums, Archive::Verify::structure_only}) {
      try {
        Octree<float>::load(dir / "bad.geods", verify).validate();
      } catch (const Error&) {
      }
    }
  }
  // validate() checks the 2:1 condition of trees that claim it: mark an unbalanced tree balanced.
  ASSERT_FALSE(balanced_oracle(tree));
  tree.save(dir / "t.geods");
  std::vector<char> claim = test::read_bytes(dir / "t.geods");
  claim[test::archive_section_offset(claim, "balanced")] = 1;
  test::write_bytes(dir / "claim.geods", claim);
  EXPECT_THROW(Octree<float>::load(dir / "claim.geods"), Error);  // the checksum sees it
  try {
    Octree<float>::load(dir / "claim.geods", Archive::Verify::structure_only);
    FAIL() << "an unbalanced tree passed as balanced";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not 2:1 balanced"), std::string::npos) << e.what();
  }
  const Quadtree<> empty(std::vector<Vec2d>{});
  empty.save(dir / "empty.geods");
  EXPECT_TRUE(Quadtree<>::load(dir / "empty.geods").empty());
  std::filesystem::remove_all(dir);
}

// A loaded tree answers every query as the original, on every shape, a single point and a
// balanced tree; bad parameters, points and kinds are errors naming the file.
template <typename T, int D>
void expect_round_trip(const Orthtree<T, D>& tree, const std::vector<Vec<T, D>>& queries,
                       const std::filesystem::path& path) {
  tree.save(path);
  const auto loaded = Orthtree<T, D>::load(path);
  ASSERT_EQ(loaded.nodes(), tree.nodes());
  ASSERT_EQ(loaded.permutation(), tree.permutation());
  ASSERT_EQ(loaded.size(), tree.size());
  EXPECT_EQ(loaded.max_depth(), tree.max_depth());
  EXPECT_EQ(loaded.root_side(), tree.root_side());
  for (std::size_t i = 0; i < tree.size(); ++i) ASSERT_EQ(loaded.point(i), tree.point(i));
  for (const auto& q : queries) {
    ASSERT_EQ(loaded.query(q, 5), tree.query(q, 5));
    ASSERT_EQ(loaded.query_radius(q, 0.1), tree.query_radius(q, 0.1));
    ASSERT_EQ(loaded.locate(q), tree.locate(q));
    const Vec<T, D> lo = q.array() - T(0.2), hi = q.array() + T(0.1);
    ASSERT_EQ(loaded.query_box(lo, hi), tree.query_box(lo, hi));
  }
  for (std::uint32_t v = 0; v < tree.nodes().size(); ++v)
    for (int d = 0; d < 2 * D; ++d) ASSERT_EQ(loaded.neighbor(v, Direction(d)), tree.neighbor(v, Direction(d)));
  const auto rebalanced = loaded.balanced();  // balancing a mapped tree copies its arrays
  EXPECT_EQ(rebalanced.nodes(), tree.balanced().nodes());
  EXPECT_FALSE(rebalanced.nodes().mapped());
}

TEST(Orthtree, LoadedTreesAnswerLikeTheOriginal) {
  const auto path = std::filesystem::temp_directory_path() / ("geods_qt_rt_" + std::to_string(getpid()));
  for (Shape2 shape : kShapes2) {
    for (std::size_t n : {1, 2, 9, 400}) {
      SCOPED_TRACE(name(shape) + " n=" + std::to_string(n));
      const auto p2 = make_points<double, 2>(shape, n, n + 1);
      const auto q2 = make_points<double, 2>(Shape2::uniform, 20, n + 2);
      expect_round_trip(Quadtree<double>(p2, {.bucket = 3}), q2, path);
      expect_round_trip(Quadtree<double>(p2).balanced(), q2, path);
      const auto p3 = make_points<float, 3>(shape, n, n + 3);
      const auto q3 = make_points<float, 3>(Shape2::uniform, 20, n + 4);
      expect_round_trip(Octree<float>(p3, {.bucket = 2, .max_depth = 8, .build = OrthtreeBuild::morton}), q3, path);
    }
  }
  // A non-finite point, a bad parameter, another structure's archive.
  const auto pts = make_points<double, 2>(Shape2::uniform, 50, 5);
  Quadtree<double>(pts).save(path);
  const std::vector<char> good = test::read_bytes(path);
  for (const char* section : {"points", "bucket", "max_depth", "root_side"}) {
    std::vector<char> bad = good;
    const double nan = std::nan("");
    std::memcpy(&bad[test::archive_section_offset(bad, section)], &nan, sizeof nan);
    test::write_bytes(path, bad);
    EXPECT_THROW(Quadtree<double>::load(path, Archive::Verify::structure_only), Error) << section;
    EXPECT_THROW(Quadtree<double>::load(path), Error) << section;
  }
  ArchiveWriter("spatial.KdTree", 1).write(path);
  EXPECT_THROW(Quadtree<double>::load(path), Error);
  std::filesystem::remove(path);
}

TEST(Orthtree, EmptyTree) {
  const Quadtree<> tree(std::span<const Vec2d>{});
  tree.validate();
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.nodes().size(), 0u);
  EXPECT_TRUE(tree.query(Vec2d(0, 0), 2).empty());
  EXPECT_TRUE(tree.query_radius(Vec2d(0, 0), 1).empty());
  EXPECT_EQ(tree.count_box(Vec2d(0, 0), Vec2d(1, 1)), 0u);
  EXPECT_EQ(tree.locate(Vec2d(0, 0)), kNoNode);
  EXPECT_TRUE(tree.balanced().nodes().empty());
  EXPECT_THROW(tree.neighbor(0, kNorth), Error);
}

TEST(Orthtree, BadInput) {
  std::vector<Vec2d> points{{0, 0}, {1, std::numeric_limits<double>::quiet_NaN()}};
  try {
    Quadtree<> tree(points);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("point 1"), std::string::npos) << e.what();
  }
  points[1] = {std::numeric_limits<double>::infinity(), 0};
  EXPECT_THROW(Quadtree<>{points}, Error);
  points[1] = {1, 1};
  EXPECT_THROW(Quadtree<>(points, {.bucket = 0}), Error);
  EXPECT_THROW(Quadtree<>(points, {.max_depth = 33}), Error);
  EXPECT_THROW(Octree<>(PointView<double>(points[0].data(), 2, 2)), Error);  // wrong dimension
  const Quadtree<> tree(points);
  EXPECT_THROW(tree.neighbor(0, Direction::pos_z), Error);
  EXPECT_THROW(tree.neighbor(99, kNorth), Error);
  EXPECT_THROW(tree.query(Vec2d(0, 0), 0), Error);
  EXPECT_THROW(tree.query_radius(Vec2d(0, 0), -1), Error);
  EXPECT_THROW(tree.locate(Vec2d(0, std::numeric_limits<double>::quiet_NaN())), Error);
}


// Coordinates so large that the root square's side overflows (used to give
// NaN bounds and index 4294967295), or a set so small that its distances
// underflow, are refused; scaled copies inside the range answer the same.
TEST(Quadtree, ExtremeScalesAreExactOrRefused) {
  Rng rng(5);
  std::vector<Vec2d> unit(200);
  for (Vec2d& p : unit) p = Vec2d(rng.uniform(), rng.uniform());
  const Quadtree<> reference(unit);
  for (double s : {1.7e308, 1e300, 1e-300}) {
    std::vector<Vec2d> p = unit;
    for (Vec2d& x : p) x *= s;
    p[0] = Vec2d(-s, -s);
    EXPECT_THROW(Quadtree<>{p}, Error) << s;
  }
  EXPECT_THROW(reference.query(Vec2d(1e300, 0), 1), Error);
  EXPECT_THROW(reference.query_radius(Vec2d(0, -1e300), 1), Error);
  for (int e : {-400, 400}) {
    std::vector<Vec2d> p = unit;
    for (Vec2d& x : p) x = Vec2d(std::ldexp(x[0], e), std::ldexp(x[1], e));
    const Quadtree<> tree(p);
    tree.validate();
    for (int i = 0; i < 20; ++i) {
      const Vec2d q(rng.uniform(), rng.uniform());
      const auto want = reference.query(q, 3);
      const auto got = tree.query(Vec2d(std::ldexp(q[0], e), std::ldexp(q[1], e)), 3);
      ASSERT_EQ(got.size(), want.size());
      for (std::size_t j = 0; j < got.size(); ++j) {
        EXPECT_EQ(got[j].index, want[j].index) << e;
        EXPECT_EQ(got[j].squared_distance, std::ldexp(want[j].squared_distance, 2 * e)) << e;
      }
    }
  }
}

}  // namespace
}  // namespace geods::spatial
