#include "geods/bsp/segments2.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <string>

#include "geods/core/error.hpp"

namespace geods::bsp {

namespace {

struct Line {
  __int128 a, b, c;  // a x + b y + c = 0
};

// Sign of line l at the intersection of lines m and n (they are not parallel).
int side(const Line& l, const Line& m, const Line& n) {
  const __int128 x = m.b * n.c - m.c * n.b, y = m.c * n.a - m.a * n.c, w = m.a * n.b - m.b * n.a;
  const __int128 v = l.a * x + l.b * y + l.c * w;
  return ((v > 0) - (v < 0)) * ((w > 0) - (w < 0));
}

struct Frag {
  std::uint32_t seg;
  std::uint32_t lo, hi;  // lines bounding the fragment on its segment's line
};

}  // namespace

SegmentBspStats segment_auto_partition(const std::vector<std::array<std::int64_t, 4>>& segments, std::uint64_t seed) {
  const std::int64_t limit = std::int64_t{1} << 20;
  std::vector<Line> lines;  // per segment: support line, then its two end caps
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const auto& s = segments[i];
    for (auto v : s)
      if (v > limit || v < -limit) throw Error("segment_auto_partition: coordinate beyond 2^20");
    const __int128 dx = s[2] - s[0], dy = s[3] - s[1];
    if (dx == 0 && dy == 0) throw Error("segment_auto_partition: segment " + std::to_string(i) + " has length 0");
    lines.push_back({dy, -dx, -(dy * s[0] - dx * s[1])});
    lines.push_back({dx, dy, -(dx * s[0] + dy * s[1])});  // cap through the start, normal along the segment
    lines.push_back({dx, dy, -(dx * s[2] + dy * s[3])});  // cap through the end
  }
  SegmentBspStats st;
  st.segments = segments.size();
  std::vector<std::uint32_t> rank(segments.size());
  std::iota(rank.begin(), rank.end(), 0u);
  std::mt19937_64 rng(seed);
  std::shuffle(rank.begin(), rank.end(), rng);
  auto support = [&](const Frag& f) -> const Line& { return lines[3 * f.seg]; };
  struct Task {
    std::vector<Frag> frags;
    std::size_t depth;
  };
  std::vector<Task> stack;
  {
    Task t{{}, 0};
    for (std::uint32_t i = 0; i < segments.size(); ++i) t.frags.push_back({i, 3 * i + 1, 3 * i + 2});
    if (!t.frags.empty()) stack.push_back(std::move(t));
  }
  while (!stack.empty()) {
    Task t = std::move(stack.back());
    stack.pop_back();
    st.depth = std::max(st.depth, t.depth);
    // The splitter: the fragment of the earliest segment in the random order.
    const Frag* best = &t.frags[0];
    for (const auto& f : t.frags)
      if (rank[f.seg] < rank[best->seg]) best = &f;
    const Line h = support(*best);
    ++st.nodes;
    Task neg{{}, t.depth + 1}, pos{{}, t.depth + 1};
    for (const auto& f : t.frags) {
      const Line& s = support(f);
      const int a = side(h, s, lines[f.lo]), b = side(h, s, lines[f.hi]);
      if (a == 0 && b == 0) {
        ++st.fragments;  // on the splitting line: stored at the node
      } else if (a <= 0 && b <= 0) {
        neg.frags.push_back(f);
      } else if (a >= 0 && b >= 0) {
        pos.frags.push_back(f);
      } else {
        // Split at the intersection with h: h becomes the cap of both pieces.
        lines.push_back(h);
        const auto hi = static_cast<std::uint32_t>(lines.size() - 1);
        (a < 0 ? neg : pos).frags.push_back({f.seg, f.lo, hi});
        (a < 0 ? pos : neg).frags.push_back({f.seg, hi, f.hi});
      }
    }
    if (!neg.frags.empty()) stack.push_back(std::move(neg));
    if (!pos.frags.empty()) stack.push_back(std::move(pos));
  }
  return st;
}

}  // namespace geods::bsp
