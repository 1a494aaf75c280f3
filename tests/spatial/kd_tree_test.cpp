// k-d tree: every query against brute force on uniform, clustered, duplicated
// and degenerate sets; the O(sqrt(n) + a) range bound; files; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <cstring>
#include <string>
#include <vector>

#include <unistd.h>

#include "common/archive_files.hpp"
#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/core/rng.hpp"
#include "geods/spatial/kd_tree.hpp"
#include "geods/spatial/kd_tree_stepped_build.hpp"

namespace geods::spatial {
namespace {

enum class Shape { uniform, clustered, duplicated, line, plane, identical, grid };
const Shape kShapes[] = {Shape::uniform, Shape::clustered, Shape::duplicated, Shape::line,
                         Shape::plane,   Shape::identical, Shape::grid};

std::string name(Shape s) {
  const char* names[] = {"uniform", "clustered", "duplicated", "line", "plane", "identical", "grid"};
  return names[int(s)];
}

// n points of dimension d, row-major.
template <typename T>
std::vector<T> make_points(Shape shape, std::size_t n, std::size_t d, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<double> centers(10 * d), distinct(20 * d), origin(d), dir1(d), dir2(d);
  for (double& c : centers) c = rng.uniform();
  for (double& c : distinct) c = rng.uniform();
  for (std::size_t a = 0; a < d; ++a) origin[a] = rng.uniform(), dir1[a] = rng.normal(), dir2[a] = rng.normal();
  std::vector<T> p(n * d);
  for (std::size_t i = 0; i < n; ++i) {
    T* q = &p[i * d];
    const std::size_t c = rng.below(10), e = rng.below(20);
    const double s = rng.uniform(-1, 1), t = rng.uniform(-1, 1);
    for (std::size_t a = 0; a < d; ++a) {
      switch (shape) {
        case Shape::uniform: q[a] = T(rng.uniform()); break;
        case Shape::clustered: q[a] = T(centers[c * d + a] + 0.01 * rng.normal()); break;
        case Shape::duplicated: q[a] = T(distinct[e * d + a]); break;
        case Shape::line: q[a] = T(origin[a] + s * dir1[a]); break;
        case Shape::plane: q[a] = T(origin[a] + s * dir1[a] + t * dir2[a]); break;
        case Shape::identical: q[a] = T(0.5); break;
        case Shape::grid: q[a] = T(rng.below(8)); break;  // many exact distance ties
      }
    }
  }
  return p;
}

// Queries: random ones around the data, data points themselves (distance 0, ties), far ones.
template <typename T>
std::vector<T> make_queries(const std::vector<T>& points, std::size_t n, std::size_t d, std::size_t m,
                            std::uint64_t seed) {
  Rng rng(seed);
  std::vector<T> q(m * d);
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t a = 0; a < d; ++a) {
      if (i % 3 == 1 && n > 0) {
        q[i * d + a] = points[(i * 7919 % n) * d + a];
      } else {
        q[i * d + a] = T(rng.uniform(-0.5, 1.5) * (i % 5 == 4 ? 10 : 1));
      }
    }
  }
  return q;
}

template <typename T>
T sqdist(const T* q, const T* p, std::size_t d) {
  T s = 0;
  for (std::size_t a = 0; a < d; ++a) s += (q[a] - p[a]) * (q[a] - p[a]);
  return s;
}

template <typename T>
std::vector<Neighbor<T>> brute_all(const std::vector<T>& p, std::size_t d, const T* q) {
  std::vector<Neighbor<T>> all(p.size() / d);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = {std::uint32_t(i), sqdist(q, &p[i * d], d)};
  std::sort(all.begin(), all.end());
  return all;
}

template <typename T, int Dim>
void check_queries(Shape shape, std::size_t n, std::size_t d, std::size_t leaf) {
  SCOPED_TRACE(name(shape) + " n=" + std::to_string(n) + " d=" + std::to_string(d) + " leaf=" + std::to_string(leaf) +
               (sizeof(T) == 4 ? " float" : " double"));
  const std::vector<T> pts = make_points<T>(shape, n, d, 17 + n + d);
  const KdTree<T, Dim> tree(PointView<T>(pts.data(), n, d), leaf);
  ASSERT_NO_THROW(tree.validate());
  EXPECT_EQ(tree.size(), n);
  const std::size_t m = 30;
  const std::vector<T> qs = make_queries(pts, n, d, m, 99 + n);
  Rng rng(5 + n);
  for (std::size_t i = 0; i < m; ++i) {
    const T* q = &qs[i * d];
    const std::span<const T> qspan(q, d);
    const std::vector<Neighbor<T>> all = brute_all(pts, d, q);
    // Exact k-NN: identical to the sorted brute force, including ties broken by index.
    for (std::size_t k : {std::size_t(1), std::size_t(5), std::size_t(23)}) {
      const std::vector<Neighbor<T>> got = tree.query(qspan, k);
      const std::vector<Neighbor<T>> want(all.begin(), all.begin() + std::min(k, all.size()));
      ASSERT_EQ(got, want) << "k=" << k << " query " << i;
    }
    // k-NN limited by a distance: fewer than k, the rest marked missing.
    const double r = all.empty() ? 0.1 : std::sqrt(double(all[std::min<std::size_t>(3, all.size() - 1)].squared_distance));
    {
      std::vector<Neighbor<T>> slots(8);
      const std::size_t found = tree.query_into(qspan, KnnRequest{8, 0, r}, slots.data());
      std::size_t want = 0;
      while (want < std::min<std::size_t>(8, all.size()) && all[want].squared_distance <= T(r * r)) ++want;
      ASSERT_EQ(found, want);
      for (std::size_t j = 0; j < 8; ++j) {
        if (j < found) {
          ASSERT_EQ(slots[j], all[j]);
        } else {
          ASSERT_EQ(slots[j].index, kNoIndex);
          ASSERT_TRUE(std::isinf(slots[j].squared_distance));
        }
      }
    }
    // Approximate k-NN: the i-th distance within (1 + eps) of the true i-th.
    for (double eps : {0.1, 1.0}) {
      const std::size_t k = 7;
      const std::vector<Neighbor<T>> got = tree.query(qspan, k, eps);
      ASSERT_EQ(got.size(), std::min(k, all.size()));
      for (std::size_t j = 0; j < got.size(); ++j) {
        ASSERT_LT(got[j].index, n);
        ASSERT_EQ(got[j].squared_distance, sqdist(q, &pts[got[j].index * d], d));
        const double bound = (1 + eps) * std::sqrt(double(all[j].squared_distance));
        ASSERT_LE(std::sqrt(double(got[j].squared_distance)), bound * (1 + 1e-6) + 1e-12) << "eps=" << eps;
        if (j > 0) {
          ASSERT_TRUE(got[j - 1] < got[j]);
        }
      }
    }
    // Radius: everything within r, sorted.
    {
      const std::vector<Neighbor<T>> got = tree.query_radius(qspan, r);
      std::vector<Neighbor<T>> want;
      for (const auto& nb : all) {
        if (nb.squared_distance <= T(r * r)) want.push_back(nb);
      }
      ASSERT_EQ(got, want);
    }
    // Box: report and count, including boxes that are a point or empty.
    for (int b = 0; b < 3; ++b) {
      std::vector<T> lo(d), hi(d);
      for (std::size_t a = 0; a < d; ++a) {
        const double c = double(q[a]), w = b == 0 ? 0.0 : rng.uniform(0, b == 1 ? 0.5 : 3.0);
        lo[a] = T(c - w * rng.uniform());
        hi[a] = T(c + w * rng.uniform());
      }
      std::vector<std::uint32_t> want;
      for (std::size_t j = 0; j < n; ++j) {
        bool in = true;
        for (std::size_t a = 0; a < d; ++a) in = in && lo[a] <= pts[j * d + a] && pts[j * d + a] <= hi[a];
        if (in) want.push_back(std::uint32_t(j));
      }
      std::vector<std::uint32_t> got = tree.query_box(lo, hi);
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, want);
      ASSERT_EQ(tree.count_box(lo, hi), want.size());
    }
  }
}

template <typename T>
void check_all_shapes() {
  for (Shape shape : kShapes) {
    for (std::size_t n : {0, 1, 9, 100, 1500}) {
      check_queries<T, 2>(shape, n, 2, 10);
      check_queries<T, 3>(shape, n, 3, 10);
      check_queries<T, Dynamic>(shape, n, 16, 10);
    }
    check_queries<T, 3>(shape, 300, 3, 1);
    check_queries<T, Dynamic>(shape, 300, 3, 4);
    check_queries<T, Dynamic>(shape, 300, 5, 10);
  }
}

TEST(KdTree, QueriesMatchBruteForceFloat) { check_all_shapes<float>(); }
TEST(KdTree, QueriesMatchBruteForceDouble) { check_all_shapes<double>(); }

TEST(KdTree, EmptyTree) {
  const KdTree<double, 3> tree(PointView<double>(nullptr, 0, 3));
  const double q[3] = {0, 0, 0};
  EXPECT_TRUE(tree.query(std::span<const double>(q, 3), 4).empty());
  EXPECT_TRUE(tree.query_radius(std::span<const double>(q, 3), 1.0).empty());
  EXPECT_EQ(tree.count_box(std::span<const double>(q, 3), std::span<const double>(q, 3)), 0u);
  EXPECT_EQ(tree.stats().nodes, 0u);
  EXPECT_NO_THROW(tree.validate());
  const KdTree<float, Dynamic> empty;
  EXPECT_EQ(empty.size(), 0u);
}

TEST(KdTree, OwnedPointsAndEigenViews) {
  const std::vector<Vec3f> pts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  const KdTree<float, 3> view_tree(PointView<float>(std::span<const Vec3f>(pts)), 1);
  KdTree<float, 3> owned(std::vector<float>(pts[0].data(), pts[0].data() + 15), 3, 1);
  const KdTree<float, 3> copy = owned;  // copies share the owned points
  owned = KdTree<float, 3>();
  EXPECT_NO_THROW(copy.validate());
  const auto a = view_tree.query(Vec3f(0.9f, 0.9f, 0.8f), 2);
  const auto b = copy.query(Vec3f(0.9f, 0.9f, 0.8f), 2);
  EXPECT_EQ(a, b);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].index, 4u);
  EXPECT_EQ(copy.count_box(AABB3f({-0.5f, -0.5f, -0.5f}, {0.5f, 1.5f, 1.5f})), 3u);
}

// The layout only changes where leaves read their points: every k-NN (exact,
// approximate, limited), radius and box result must be identical between the
// default tree_order tree (its copy made by the build), a zero_copy one, and a
// zero_copy one turned into tree_order by store_points_in_tree_order().
template <typename T, int Dim>
void check_tree_order_copy(Shape shape, std::size_t d) {
  SCOPED_TRACE(name(shape) + " d=" + std::to_string(d) + (sizeof(T) == 4 ? " float" : " double"));
  constexpr std::size_t n = 3000;
  const std::vector<T> pts = make_points<T>(shape, n, d, 29 + d);
  const KdTree<T, Dim> plain(PointView<T>(pts.data(), n, d), 8, PointLayout::zero_copy);
  const KdTree<T, Dim> ordered(PointView<T>(pts.data(), n, d), 8);
  KdTree<T, Dim> converted = plain;
  converted.store_points_in_tree_order();
  ASSERT_EQ(ordered.layout(), PointLayout::tree_order);
  ASSERT_EQ(converted.layout(), PointLayout::tree_order);
  ASSERT_EQ(plain.layout(), PointLayout::zero_copy);
  ASSERT_NO_THROW(ordered.validate());  // checks the copy against the points
  ASSERT_NO_THROW(converted.validate());
  if constexpr (Dim == Dynamic) {
    EXPECT_EQ(ordered.bytes(), plain.bytes() + n * d * sizeof(T));
  } else {
    // The packed layout: 16 or 24 bytes per inner node; per leaf, its points in
    // groups of 4 (d x 4 coordinates and 4 indices, 16-byte aligned; 64 for float 3D).
    std::size_t inner = 0, groups = 0;
    for (const auto& node : plain.nodes()) node.leaf() ? groups += (node.end - node.begin + 3) / 4 : ++inner;
    const std::size_t group_bytes = (4 * d * sizeof(T) + 16 + 15) / 16 * 16;
    EXPECT_EQ(ordered.bytes(), plain.bytes() + inner * (2 * sizeof(T) + 8) + groups * group_bytes);
    EXPECT_EQ(converted.bytes(), ordered.bytes());
  }
  const std::vector<T> qs = make_queries(pts, n, d, 60, 31);
  for (std::size_t i = 0; i < 60; ++i) {
    const std::span<const T> q(&qs[i * d], d);
    for (std::size_t k : {1u, 10u, 37u}) {
      EXPECT_EQ(plain.query(q, k), ordered.query(q, k));
      EXPECT_EQ(plain.query(q, k), converted.query(q, k));
      EXPECT_EQ(plain.query(q, k, 0.5), ordered.query(q, k, 0.5));
      EXPECT_EQ(plain.query(q, KnnRequest{k, 0, 0.3}), ordered.query(q, KnnRequest{k, 0, 0.3}));
    }
    EXPECT_EQ(plain.query_radius(q, 0.2), ordered.query_radius(q, 0.2));
    std::vector<T> lo(q.begin(), q.end()), hi(q.begin(), q.end());
    for (std::size_t a = 0; a < d; ++a) lo[a] -= T(0.1), hi[a] += T(0.15);
    EXPECT_EQ(plain.query_box(lo, hi), ordered.query_box(lo, hi));
  }
}

TEST(KdTree, TreeOrderCopyGivesIdenticalResults) {
  for (Shape shape : {Shape::uniform, Shape::clustered, Shape::duplicated, Shape::identical}) {
    check_tree_order_copy<float, 3>(shape, 3);
    check_tree_order_copy<double, 2>(shape, 2);
    check_tree_order_copy<float, 2>(shape, 2);  // packed groups of 2 x 4 floats (SSE), 3D above
    check_tree_order_copy<float, 4>(shape, 4);
    check_tree_order_copy<double, 1>(shape, 1);  // packed, scalar lanes
    check_tree_order_copy<double, Dynamic>(shape, 5);
  }
}

TEST(KdTree, BalancedAndStats) {
  const std::size_t n = 100000;
  const auto pts = make_points<float>(Shape::clustered, n, 3, 3);
  const KdTree<float, 3> tree(PointView<float>(pts.data(), n, 3), 10);
  const KdTreeStats s = tree.stats();
  EXPECT_EQ(s.points, n);
  EXPECT_EQ(s.nodes, 2 * s.leaves - 1);
  EXPECT_LE(s.depth, std::size_t(std::ceil(std::log2(double(n) / 10))));  // median splits: balanced
  EXPECT_GE(s.bytes, s.nodes * sizeof(KdTree<float, 3>::Node));
}

TEST(KdTree, DeterministicParallelBuildAndBatch) {
  const std::size_t n = 200000;
  const auto pts = make_points<double>(Shape::uniform, n, 3, 11);
  const PointView<double> view(pts.data(), n, 3);
  const KdTree<double, 3> parallel(view, 8);
  set_num_threads(1);
  const KdTree<double, 3> serial(view, 8);
  set_num_threads(0);
  ASSERT_EQ(parallel.permutation(), serial.permutation());
  ASSERT_EQ(parallel.nodes().size(), serial.nodes().size());
  for (std::size_t i = 0; i < serial.nodes().size(); ++i) {
    const auto &a = parallel.nodes()[i], &b = serial.nodes()[i];
    ASSERT_TRUE(a.begin == b.begin && a.end == b.end && a.right == b.right && a.axis == b.axis && a.low == b.low &&
                a.high == b.high);
  }
  // Batches run in parallel over queries and equal one-at-a-time queries.
  const std::size_t m = 5000;
  const auto qs = make_queries(pts, n, 3, m, 12);
  const PointView<double> queries(qs.data(), m, 3);
  const KnnRequest request{6, 0, 0.05};
  const auto batch = parallel.query_batch(queries, request);
  const auto radius = parallel.query_radius_batch(queries, 0.02);
  std::vector<double> boxes(m * 6);
  for (std::size_t i = 0; i < m; ++i)
    for (int a = 0; a < 3; ++a) boxes[i * 6 + a] = qs[i * 3 + a] - 0.03, boxes[i * 6 + 3 + a] = qs[i * 3 + a] + 0.05;
  const auto counts = parallel.count_box_batch(PointView<double>(boxes.data(), m, 6));
  for (std::size_t i = 0; i < m; ++i) {
    std::vector<Neighbor<double>> one(6);
    serial.query_into({&qs[i * 3], 3}, request, one.data());
    ASSERT_TRUE(std::equal(one.begin(), one.end(), batch.begin() + i * 6));
    ASSERT_EQ(radius[i], serial.query_radius(std::span<const double>(&qs[i * 3], 3), 0.02));
    ASSERT_EQ(counts[i], serial.count_box({&boxes[i * 6], 3}, {&boxes[i * 6 + 3], 3}));
  }
}

// Theorem 4: a 2D range query visits O(sqrt(n) + a) nodes; counting visits O(sqrt(n)).
TEST(KdTree, RangeQueryVisitsSqrtNNodes) {
  for (Shape shape : {Shape::uniform, Shape::clustered}) {
    for (std::size_t n : {1000, 10000, 100000, 400000}) {
      const auto pts = make_points<double>(shape, n, 2, n);
      const KdTree<double, 2> tree(PointView<double>(pts.data(), n, 2), 10);
      Rng rng(n);
      double worst_count = 0, worst_report = 0;
      for (int b = 0; b < 200; ++b) {
        const double w = rng.uniform(0, 1), h = rng.uniform(0, 1);
        const double x = rng.uniform(-0.2, 1), y = rng.uniform(-0.2, 1);
        const double lo[2] = {x, y}, hi[2] = {x + w, y + h};
        std::size_t visited_count = 0, visited_report = 0;
        tree.count_box(lo, hi, &visited_count);
        const std::size_t a = tree.query_box(lo, hi, &visited_report).size();
        worst_count = std::max(worst_count, double(visited_count) / std::sqrt(double(n)));
        worst_report = std::max(worst_report, double(visited_report) / (std::sqrt(double(n)) + double(a)));
      }
      SCOPED_TRACE(name(shape) + " n=" + std::to_string(n));
      EXPECT_LE(worst_count, 12.0);
      EXPECT_LE(worst_report, 12.0);
    }
  }
}

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("geods_kd_" + std::to_string(::getpid()) + "_" + name);
}

TEST(KdTree, SaveLoadRoundTrip) {
  const std::size_t n = 3000;
  const auto pts = make_points<float>(Shape::clustered, n, 3, 4);
  const KdTree<float, 3> tree(PointView<float>(pts.data(), n, 3), 7);
  const auto path = temp_file("roundtrip.geods");
  tree.save(path);
  const KdTree<float, 3> loaded = KdTree<float, 3>::load(path);
  EXPECT_EQ(loaded.permutation(), tree.permutation());
  EXPECT_EQ(loaded.leaf_size(), 7u);
  EXPECT_EQ(loaded.stats().nodes, tree.stats().nodes);
  // Read in place from the mapped file, not copied.
  EXPECT_TRUE(loaded.nodes().mapped());
  EXPECT_TRUE(loaded.permutation().mapped());
  EXPECT_FALSE(tree.nodes().mapped());
  const auto qs = make_queries(pts, n, 3, 50, 1);
  for (std::size_t i = 0; i < 50; ++i) {
    const std::span<const float> q(&qs[i * 3], 3);
    EXPECT_EQ(loaded.query(q, 5), tree.query(q, 5));
  }
  // The runtime-dimension tree reads the same file; the info says what it holds.
  const auto dynamic = KdTree<float, Dynamic>::load(path);
  EXPECT_EQ(dynamic.dim(), 3u);
  EXPECT_EQ(read_kd_tree_info(path).scalar, DType::f32);
  EXPECT_EQ(read_kd_tree_info(path).dim, 3u);
  // An empty tree round-trips too.
  const auto empty_path = temp_file("empty.geods");
  KdTree<double, 2>().save(empty_path);
  EXPECT_EQ((KdTree<double, 2>::load(empty_path).size()), 0u);
  KdTree<double, Dynamic>().save(empty_path);
  EXPECT_EQ((KdTree<double, Dynamic>::load(empty_path).size()), 0u);
  std::filesystem::remove(path);
  std::filesystem::remove(empty_path);
}

// Every query of a loaded tree answers as the original's, on every shape (duplicates,
// identical points, lines, grids), a single point, strided input and the runtime dimension.
template <typename T, int Dim>
void expect_same_answers(const KdTree<T, Dim>& a, const KdTree<T, Dim>& b, const std::vector<T>& qs, std::size_t m,
                         std::size_t d) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  EXPECT_EQ(a.bounds_lo(), b.bounds_lo());
  EXPECT_EQ(a.bounds_hi(), b.bounds_hi());
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_TRUE(std::equal(a.point(i), a.point(i) + d, b.point(i))) << "point " << i;
  for (std::size_t i = 0; i < m; ++i) {
    const std::span<const T> q(&qs[i * d], d);
    ASSERT_EQ(a.query(q, 7), b.query(q, 7));
    ASSERT_EQ(a.query(q, 3, 0.5), b.query(q, 3, 0.5));
    ASSERT_EQ(a.query_radius(q, 0.2), b.query_radius(q, 0.2));
    std::vector<T> lo(d), hi(d);
    for (std::size_t k = 0; k < d; ++k) lo[k] = q[k] - T(0.3), hi[k] = q[k] + T(0.2);
    ASSERT_EQ(a.query_box(lo, hi), b.query_box(lo, hi));
  }
}

TEST(KdTree, LoadedTreesAnswerLikeTheOriginal) {
  const auto path = temp_file("answers.geods");
  for (Shape shape : kShapes) {
    for (std::size_t n : {1, 2, 11, 1000}) {
      SCOPED_TRACE(name(shape) + " n=" + std::to_string(n));
      const auto pts = make_points<double>(shape, n, 3, n + 7);
      const auto qs = make_queries(pts, n, 3, 20, 5);
      const KdTree<double, 3> tree(PointView<double>(pts.data(), n, 3), 4);
      tree.save(path);
      const auto loaded = KdTree<double, 3>::load(path);
      loaded.validate();
      EXPECT_TRUE(loaded.points().data != pts.data());
      expect_same_answers(tree, loaded, qs, 20, 3);
      // A loaded tree reads the mapped points in place unless asked for tree_order
      // (a copy made after loading); answers stay the same.
      EXPECT_EQ(loaded.layout(), PointLayout::zero_copy);
      const auto ordered = KdTree<double, 3>::load(path, Archive::Verify::checksums, PointLayout::tree_order);
      EXPECT_EQ(ordered.layout(), PointLayout::tree_order);
      ordered.validate();
      expect_same_answers(tree, ordered, qs, 20, 3);
    }
  }
  // A strided view is saved packed; the runtime dimension (5) round-trips.
  const auto pts = make_points<float>(Shape::uniform, 600, 6, 3);
  const KdTree<float, Dynamic> strided(PointView<float>(pts.data(), 600, 5, 6), 6);
  strided.save(path);
  const auto loaded = KdTree<float, Dynamic>::load(path);
  EXPECT_EQ(loaded.dim(), 5u);
  const auto qs = make_points<float>(Shape::uniform, 30, 5, 9);
  expect_same_answers(strided, loaded, qs, 30, 5);
  // Copies share the mapping; it outlives the file name.
  const auto copy = loaded;
  std::filesystem::remove(path);
  EXPECT_EQ(copy.nodes().data(), loaded.nodes().data());
  expect_same_answers(strided, copy, qs, 30, 5);
}

TEST(KdTree, CorruptedFilesThrow) {
  const std::size_t n = 500;
  const auto pts = make_points<double>(Shape::uniform, n, 2, 8);
  const KdTree<double, 2> tree(PointView<double>(pts.data(), n, 2));
  const auto path = temp_file("good.geods"), bad = temp_file("bad.geods");
  tree.save(path);
  const std::vector<char> good = test::read_bytes(path);
  // Checked by the container (checksums on) and, with the checksums skipped, by validate().
  auto expect_error = [&](std::vector<char> bytes, const std::string& what) {
    test::write_bytes(bad, bytes);
    EXPECT_THROW((KdTree<double, 2>::load(bad)), Error) << what;
    EXPECT_THROW((KdTree<double, 2>::load(bad, Archive::Verify::structure_only)), Error) << what;
  };
  expect_error(std::vector<char>(good.begin(), good.end() - 5), "truncated");
  expect_error(std::vector<char>(good.begin(), good.begin() + 20), "truncated header");
  auto bytes = good;
  bytes.push_back(0);
  expect_error(bytes, "trailing bytes");
  bytes = good;
  bytes[0] = 'X';
  expect_error(bytes, "magic");
  bytes = good;
  bytes[8] = 9;  // container version
  expect_error(bytes, "version");
  bytes = good;
  bytes[48] = 9;  // k-d tree layout version
  expect_error(bytes, "kind version");
  // Permutation entry duplicated: validate() refuses it.
  const std::size_t perm_at = test::archive_section_offset(good, "permutation");
  const std::size_t nodes_at = test::archive_section_offset(good, "nodes");
  const std::size_t points_at = test::archive_section_offset(good, "points");
  bytes = good;
  std::copy(bytes.begin() + perm_at, bytes.begin() + perm_at + 4, bytes.begin() + perm_at + 4);
  expect_error(bytes, "permutation");
  // A child index pointing outside the node array.
  bytes = good;
  bytes[nodes_at + 8] = char(0xff), bytes[nodes_at + 9] = char(0xff);
  expect_error(bytes, "child index");
  // A split value that lies about the points below it.
  bytes = good;
  const double lie = -1e9;
  std::memcpy(&bytes[nodes_at + 16], &lie, sizeof lie);
  expect_error(bytes, "split value");
  // A point that is not finite.
  for (double x : {std::nan(""), double(INFINITY)}) {
    bytes = good;
    std::memcpy(&bytes[points_at], &x, sizeof x);
    expect_error(bytes, "non-finite point");
  }
  // Wrong type or dimension, with a message that says so; another structure's file.
  EXPECT_THROW((KdTree<float, 2>::load(path)), Error);
  EXPECT_THROW((KdTree<double, 3>::load(path)), Error);
  try {
    (void)KdTree<float, Dynamic>::load(path);
    FAIL() << "a double tree loaded as float";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": a k-d tree of f64, expected f32");
  }
  ArchiveWriter other("spatial.Orthtree", 1);
  other.write(bad);
  EXPECT_THROW((KdTree<double, 2>::load(bad)), Error);
  EXPECT_THROW(read_kd_tree_info(bad), Error);
  EXPECT_THROW((KdTree<double, 2>::load(temp_file("missing.geods"))), Error);
  // Every truncation is an error, never a crash.
  for (std::size_t size = 0; size < good.size(); size += 1 + size / 8) {
    test::write_bytes(bad, std::vector<char>(good.begin(), good.begin() + std::ptrdiff_t(size)));
    EXPECT_THROW((KdTree<double, 2>::load(bad, Archive::Verify::structure_only)), Error) << size;
  }
  std::filesystem::remove(path);
  std::filesystem::remove(bad);
}

// The stepped build (pausing every `budget` element visits) and queries with a
// filter of skipped points: the same answers as brute force over the kept
// points, and without a filter the same as the parallel build.
template <typename T, int Dim>
void check_stepped_and_filtered(Shape shape, std::size_t n, std::size_t d, std::size_t budget) {
  SCOPED_TRACE(name(shape) + " n=" + std::to_string(n) + " d=" + std::to_string(d) + " budget=" +
               std::to_string(budget) + (sizeof(T) == 4 ? " float" : " double"));
  const std::vector<T> pts = make_points<T>(shape, n, d, 41 + n + d);
  using Build = KdTreeSteppedBuild<T, Dim>;
  std::vector<typename Build::Row> rows(n);
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (Dim == Dynamic) rows[i].resize(d);
    std::copy(&pts[i * d], &pts[i * d] + d, rows[i].begin());
  }
  Build build(rows, d, 6);
  std::size_t steps = 0;
  while (!build.step(budget)) ++steps;
  if (n > 100) {
    EXPECT_GE(steps, build.estimated_work() / budget / 4) << "the build runs in many small steps";
  }
  const auto [stepped, row] = build.finish();
  ASSERT_NO_THROW(stepped.validate());
  EXPECT_EQ(stepped.size(), n);
  // Its points are numbered in tree order: point i is input row row[i], the permutation is the identity.
  ASSERT_NO_THROW(require_permutation(row, n, "stepped build rows"));
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(stepped.permutation()[i], i);
    ASSERT_TRUE(std::equal(stepped.point(i), stepped.point(i) + d, &pts[row[i] * d]));
  }
  const KdTree<T, Dim> plain(PointView<T>(pts.data(), n, d), 6);
  EXPECT_EQ(stepped.stats().depth, plain.stats().depth);
  EXPECT_EQ(stepped.nodes().size(), plain.nodes().size());

  std::vector<std::uint8_t> flags(n), stepped_flags(n);  // by input row, by stepped tree point
  Rng rng(3 + n);
  for (std::size_t i = 0; i < n; ++i) flags[i] = i % 3 == 0 || rng.below(4) == 0;
  for (std::size_t i = 0; i < n; ++i) stepped_flags[i] = flags[row[i]];
  const SkipFlagged skip{flags.data()}, stepped_skip{stepped_flags.data()};
  const auto skip_odd_lambda = [&](std::uint32_t i) { return flags[i] != 0; };
  // The stepped tree's answers in input rows (ties broken by row, as the plain tree's).
  auto stepped_query = [&](const T* q, const KnnRequest& request, const auto& skip_points) {
    std::vector<Neighbor<T>> out(request.k);
    KnnResultSet<T> best(out.data(), request.k, squared_limit<T>(request.max_distance));
    struct InRows {
      KnnResultSet<T>& best;
      const std::uint32_t* row;
      T worst() const { return best.worst(); }
      bool full() const { return best.full(); }
      void insert(std::uint32_t i, T dist) { best.insert(row[i], dist); }
    } in_rows{best, row.data()};
    stepped.search_nearest(q, in_rows, request.eps, skip_points);
    best.finish();
    out.resize(best.size());
    return out;
  };
  auto stepped_radius = [&](const T* q, double r, const auto& skip_points) {
    std::vector<Neighbor<T>> out;
    for (const auto& nb : stepped.query_radius(std::span<const T>(q, d), r, skip_points)) out.push_back({row[nb.index], nb.squared_distance});
    std::sort(out.begin(), out.end());
    return out;
  };
  const std::vector<T> qs = make_queries(pts, n, d, 20, 7 + n);
  for (std::size_t i = 0; i < 20; ++i) {
    const T* q = &qs[i * d];
    const std::span<const T> qspan(q, d);
    std::vector<Neighbor<T>> kept;
    for (const auto& nb : brute_all(pts, d, q))
      if (!flags[nb.index]) kept.push_back(nb);
    for (std::size_t k : {std::size_t(1), std::size_t(5), std::size_t(23)}) {
      ASSERT_EQ(stepped_query(q, KnnRequest{k}, KeepAll{}), plain.query(qspan, k)) << "k=" << k;
      const std::vector<Neighbor<T>> want(kept.begin(), kept.begin() + std::min(k, kept.size()));
      ASSERT_EQ(stepped_query(q, KnnRequest{k}, stepped_skip), want) << "k=" << k;
      ASSERT_EQ(plain.query(qspan, KnnRequest{k}, skip_odd_lambda), want) << "k=" << k;
    }
    const double r = kept.empty() ? 0.1 : std::sqrt(double(kept[std::min<std::size_t>(3, kept.size() - 1)].squared_distance));
    std::vector<Neighbor<T>> within;
    for (const auto& nb : kept)
      if (nb.squared_distance <= T(r * r)) within.push_back(nb);
    ASSERT_EQ(stepped_radius(q, r, stepped_skip), within);
    ASSERT_EQ(plain.query_radius(qspan, r, skip), within);
    ASSERT_EQ(stepped_radius(q, r, KeepAll{}), plain.query_radius(qspan, r));
    // max_distance and (1 + eps) with a filter: fewer than k within the limit, each within the bound.
    const std::vector<Neighbor<T>> limited = stepped_query(q, KnnRequest{8, 0, r}, stepped_skip);
    ASSERT_EQ(limited, std::vector<Neighbor<T>>(within.begin(), within.begin() + std::min<std::size_t>(8, within.size())));
    const std::vector<Neighbor<T>> approx = stepped_query(q, KnnRequest{7, 1.0}, stepped_skip);
    ASSERT_EQ(approx.size(), std::min<std::size_t>(7, kept.size()));
    for (std::size_t j = 0; j < approx.size(); ++j) {
      ASSERT_FALSE(flags[approx[j].index]);
      ASSERT_LE(std::sqrt(double(approx[j].squared_distance)),
                2 * std::sqrt(double(kept[j].squared_distance)) * (1 + 1e-6) + 1e-12);
    }
    std::vector<T> lo(d), hi(d);
    for (std::size_t a = 0; a < d; ++a) lo[a] = q[a] - T(0.3), hi[a] = q[a] + T(0.4);
    std::vector<std::uint32_t> want_box, all_box;
    for (std::size_t j = 0; j < n; ++j) {
      bool in = true;
      for (std::size_t a = 0; a < d; ++a) in = in && lo[a] <= pts[j * d + a] && pts[j * d + a] <= hi[a];
      if (in) all_box.push_back(std::uint32_t(j));
      if (in && !flags[j]) want_box.push_back(std::uint32_t(j));
    }
    std::vector<std::uint32_t> stepped_box, stepped_all, plain_box = plain.query_box(lo, hi, nullptr, skip),
                                                   plain_all = plain.query_box(lo, hi);
    for (std::uint32_t j : stepped.query_box(lo, hi, nullptr, stepped_skip)) stepped_box.push_back(row[j]);
    for (std::uint32_t j : stepped.query_box(lo, hi)) stepped_all.push_back(row[j]);
    for (auto* found : {&stepped_box, &stepped_all, &plain_box, &plain_all}) std::sort(found->begin(), found->end());
    ASSERT_EQ(stepped_box, want_box);
    ASSERT_EQ(plain_box, want_box);
    ASSERT_EQ(stepped_all, all_box);
    ASSERT_EQ(plain_all, all_box);
    ASSERT_EQ(stepped.count_box(lo, hi, nullptr, stepped_skip), want_box.size());
    ASSERT_EQ(plain.count_box(lo, hi, nullptr, skip), want_box.size());
  }
}

TEST(KdTree, SteppedBuildAndFilterMatchBruteForce) {
  for (Shape shape : kShapes) {
    for (std::size_t n : {0, 1, 9, 700}) {
      check_stepped_and_filtered<float, 3>(shape, n, 3, 37);
      check_stepped_and_filtered<double, 2>(shape, n, 2, 1);
      check_stepped_and_filtered<double, Dynamic>(shape, n, 5, 100);
    }
  }
}

TEST(KdTree, SteppedBuildRejectsBadRows) {
  std::vector<std::array<double, 2>> rows = {{0, 0}, {1, std::nan("")}, {2, 2}};
  KdTreeSteppedBuild<double, 2> nan_build(rows);
  EXPECT_THROW(nan_build.finish(), Error);
  std::vector<std::vector<float>> ragged = {{0, 0, 0}, {1, 1}};
  KdTreeSteppedBuild<float, Dynamic> ragged_build(ragged, 3);
  EXPECT_THROW(ragged_build.finish(), Error);
  EXPECT_THROW((KdTreeSteppedBuild<float, Dynamic>(ragged, 0)), Error);
  EXPECT_THROW((KdTreeSteppedBuild<double, 2>(rows, 3)), Error);
  EXPECT_THROW((KdTreeSteppedBuild<double, 2>(rows, 2, 0)), Error);
}

TEST(KdTree, BadInputThrows) {
  std::vector<double> pts = {0, 0, 1, 1, 2, 2};
  EXPECT_NO_THROW((KdTree<double, 2>(PointView<double>(pts.data(), 3, 2))));
  EXPECT_THROW((KdTree<double, 3>(PointView<double>(pts.data(), 3, 2))), Error);  // dimension mismatch
  EXPECT_THROW((KdTree<double, 2>(PointView<double>(pts.data(), 3, 2), 0)), Error);  // leaf size 0
  EXPECT_THROW((KdTree<double, Dynamic>(std::vector<double>(5, 0.0), 2)), Error);  // not rows
  EXPECT_THROW(parse_point_layout("ordered"), Error);
  EXPECT_EQ(parse_point_layout(to_string(PointLayout::zero_copy)), PointLayout::zero_copy);
  pts[3] = std::nan("");
  EXPECT_THROW((KdTree<double, 2>(PointView<double>(pts.data(), 3, 2))), Error);
  pts[3] = INFINITY;
  EXPECT_THROW((KdTree<double, 2>(PointView<double>(pts.data(), 3, 2))), Error);
  pts[3] = 1;
  const KdTree<double, 2> tree(PointView<double>(pts.data(), 3, 2));
  const double q[3] = {0.5, 0.5, 0.5};
  EXPECT_THROW(tree.query(std::span<const double>(q, 3), 1), Error);  // dimension mismatch
  EXPECT_THROW(tree.query(std::span<const double>(q, 2), 0), Error);  // k = 0
  EXPECT_THROW(tree.query(std::span<const double>(q, 2), 1, -1.0), Error);  // eps < 0
  EXPECT_THROW(tree.query_radius(std::span<const double>(q, 2), -1.0), Error);
  EXPECT_THROW(tree.query_radius(std::span<const double>(q, 2), std::nan("")), Error);
  const double nan_q[2] = {std::nan(""), 0};
  EXPECT_THROW(tree.query(std::span<const double>(nan_q, 2), 1), Error);
  EXPECT_THROW(tree.count_box(std::span<const double>(nan_q, 2), std::span<const double>(q, 2)), Error);
  EXPECT_THROW(tree.count_box_batch(PointView<double>(q, 1, 3)), Error);  // rows of 2 * dim values
  const double inverted_lo[2] = {2, 2}, inverted_hi[2] = {0, 0};
  EXPECT_EQ(tree.count_box(inverted_lo, inverted_hi), 0u);  // an empty box is no error
}


// Points scaled by a power of two give the same neighbours, with squared
// distances scaled exactly, as long as they stay in the range where squared
// distances neither overflow nor underflow; beyond it the tree refuses them
// (1e300 used to give infinite distances and arbitrary neighbours).
template <typename T>
void check_scaled_copies(const std::vector<int>& good_exponents, const std::vector<T>& bad_scales) {
  const std::size_t n = 300, d = 3;
  const std::vector<T> unit = make_points<T>(Shape::uniform, n, d, 21);
  const std::vector<T> queries = make_points<T>(Shape::uniform, 30, d, 22);
  const KdTree<T, 3> reference(unit, d);
  for (int e : good_exponents) {
    std::vector<T> p = unit, q = queries;
    for (T& x : p) x = std::ldexp(x, e);
    for (T& x : q) x = std::ldexp(x, e);
    const KdTree<T, 3> tree(p, d);
    for (std::size_t i = 0; i < 30; ++i) {
      const auto want = reference.query(std::span<const T>(&queries[i * d], d), 5);
      const auto got = tree.query(std::span<const T>(&q[i * d], d), 5);
      ASSERT_EQ(got.size(), want.size());
      for (std::size_t j = 0; j < got.size(); ++j) {
        EXPECT_EQ(got[j].index, want[j].index) << "2^" << e;
        EXPECT_EQ(got[j].squared_distance, std::ldexp(want[j].squared_distance, 2 * e)) << "2^" << e;
      }
    }
  }
  for (T s : bad_scales) {
    std::vector<T> p = unit;
    for (T& x : p) x *= s;
    EXPECT_THROW((KdTree<T, 3>(p, d)), Error) << s;
    // A far query against unit points overflows the same way.
    const std::vector<T> far{s, 0, 0};
    if (s > 1) {
      EXPECT_THROW(reference.query(std::span<const T>(far), 1), Error) << s;
      EXPECT_THROW(reference.query_radius(std::span<const T>(far), 1.0), Error) << s;
    }
  }
}

TEST(KdTree, ExtremeScalesAreExactOrRefused) {
  check_scaled_copies<double>({-440, -300, 300, 490}, {1e300, 1e-300, 1e155, 1e-140});
  check_scaled_copies<float>({-30, 40}, {1e20f, 1e-20f, 1e30f});
  // Boxes are not distances: a box far out still counts (nothing).
  const std::vector<double> unit = make_points<double>(Shape::uniform, 50, 3, 23);
  const KdTree<double, 3> tree(unit, 3);
  const std::vector<double> lo{-1e300, -1e300, -1e300}, hi{1e300, 1e300, 1e300};
  EXPECT_EQ(tree.count_box(std::span<const double>(lo), std::span<const double>(hi)), 50u);
}

}  // namespace
}  // namespace geods::spatial
