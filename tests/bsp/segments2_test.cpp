#include "geods/bsp/segments2.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "geods/core/error.hpp"

using namespace geods;
using namespace geods::bsp;

namespace {

__int128 orient(std::int64_t ax, std::int64_t ay, std::int64_t bx, std::int64_t by, std::int64_t cx, std::int64_t cy) {
  return static_cast<__int128>(bx - ax) * (cy - ay) - static_cast<__int128>(by - ay) * (cx - ax);
}

bool cross(const std::array<std::int64_t, 4>& s, const std::array<std::int64_t, 4>& t) {
  auto sg = [](__int128 v) { return (v > 0) - (v < 0); };
  const int d1 = sg(orient(s[0], s[1], s[2], s[3], t[0], t[1])), d2 = sg(orient(s[0], s[1], s[2], s[3], t[2], t[3]));
  const int d3 = sg(orient(t[0], t[1], t[2], t[3], s[0], s[1])), d4 = sg(orient(t[0], t[1], t[2], t[3], s[2], s[3]));
  return d1 * d2 <= 0 && d3 * d4 <= 0;  // touching counts as crossing (we want disjoint segments)
}

// n disjoint random segments in a square, by rejection (brute-force intersection tests).
std::vector<std::array<std::int64_t, 4>> disjoint_segments(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const double side = 1000.0 * std::sqrt(double(n));
  std::uniform_real_distribution<double> u(0, side), a(0, 6.283185307179586), len(100, 1200);
  std::vector<std::array<std::int64_t, 4>> s;
  while (s.size() < n) {
    const double x = u(rng), y = u(rng), t = a(rng), l = len(rng);
    const std::array<std::int64_t, 4> c{std::llround(x), std::llround(y), std::llround(x + l * std::cos(t)),
                                        std::llround(y + l * std::sin(t))};
    bool ok = true;
    for (const auto& o : s) ok = ok && !cross(c, o);
    if (ok) s.push_back(c);
  }
  return s;
}

}  // namespace

// Lemma 1: the expected number of fragments of an auto-partition in random order is at most
// n + 2 n H_n (the proof's bound), O(n log n); measured as a mean over seeds.
TEST(SegmentBsp, Lemma1FragmentsAreNLogN) {
  double prev_ratio = 0;
  for (std::size_t n : {100, 200, 400}) {
    const auto segs = disjoint_segments(n, n);
    double h = 0;
    for (std::size_t i = 1; i <= n; ++i) h += 1.0 / double(i);
    double mean = 0;
    const int runs = 8;
    for (int r = 0; r < runs; ++r) {
      const SegmentBspStats st = segment_auto_partition(segs, 100 + r);
      EXPECT_EQ(st.segments, n);
      EXPECT_GE(st.fragments, n);
      mean += double(st.fragments) / runs;
    }
    EXPECT_LE(mean, double(n) + 2.0 * double(n) * h);
    const double ratio = mean / (double(n) * std::log(double(n)));
    EXPECT_LT(ratio, 1.0);
    prev_ratio = ratio;
  }
  (void)prev_ratio;
}

TEST(SegmentBsp, CollinearAndTouchingSegmentsAreExact) {
  // Collinear pieces of one line, and segments meeting at endpoints: no split at a touching endpoint.
  const std::vector<std::array<std::int64_t, 4>> s = {{0, 0, 10, 0}, {20, 0, 30, 0}, {10, 0, 10, 10}, {-5, -5, 0, 0}};
  for (int seed = 0; seed < 10; ++seed) EXPECT_EQ(segment_auto_partition(s, seed).fragments, 4u);
  // A segment crossed by another's line: split exactly once.
  // A segment crossed by the other's line: split once when that one goes first, else not.
  std::set<std::size_t> counts;
  for (int seed = 0; seed < 20; ++seed) counts.insert(segment_auto_partition({{0, 0, 10, 0}, {5, 1, 5, 5}}, seed).fragments);
  EXPECT_EQ(counts, (std::set<std::size_t>{2, 3}));
  EXPECT_THROW(segment_auto_partition({{0, 0, 0, 0}}, 1), Error);
  EXPECT_THROW(segment_auto_partition({{0, 0, 1 << 21, 0}}, 1), Error);
}
