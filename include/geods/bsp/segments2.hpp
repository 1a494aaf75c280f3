#pragma once
// Auto-partitions of 2D segments (seed §3, Lemma 1): with the segments taken in a random
// order, each one's line splits the others in its cell; the expected number of fragments
// of disjoint segments is O(n log n) (at most n + 2 n H_n). Exact: segment endpoints are
// integers (|coordinate| <= 2^20), fragment endpoints are intersections of two integer
// lines, and the side of a line at such a point is evaluated in 128-bit integers.
#include <array>
#include <cstdint>
#include <vector>

namespace geods::bsp {

struct SegmentBspStats {
  std::size_t segments = 0;
  std::size_t fragments = 0;  // stored at the nodes (collinear pieces included)
  std::size_t nodes = 0;      // inner nodes
  std::size_t depth = 0;
};

/// segments: (x0, y0, x1, y1) integer endpoints, |coordinate| <= 2^20, non-degenerate.
/// Throws geods::Error otherwise.
SegmentBspStats segment_auto_partition(const std::vector<std::array<std::int64_t, 4>>& segments, std::uint64_t seed);

}  // namespace geods::bsp
