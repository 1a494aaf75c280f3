#pragma once
// Parallel helpers over oneTBB, and the global thread limit.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cstddef>

namespace geods {

/// Limits the worker threads of every later parallel call; n <= 0 restores all cores.
void set_num_threads(int n);
/// The current limit (all cores unless set_num_threads was called).
int num_threads();

/// Calls body(begin, end) on disjoint chunks covering [first, last) in
/// parallel; chunks hold at least `grain` indices. Deterministic results need a
/// body whose effect does not depend on how the range is chunked.
template <typename Body>
void parallel_for(std::size_t first, std::size_t last, std::size_t grain, const Body& body) {
  if (first >= last) return;
  if (last - first <= grain || num_threads() == 1) {
    body(first, last);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(first, last, grain),
                    [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
}

/// Calls fn(i) for every i in [first, last) in parallel.
template <typename Fn>
void parallel_for_each_index(std::size_t first, std::size_t last, const Fn& fn, std::size_t grain = 1024) {
  parallel_for(first, last, grain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) fn(i);
  });
}

/// The box of n items in parallel: extend(box, i) adds item i to a Box (an
/// AABB); the extents' minima and maxima are the same in any order.
template <typename Box, typename Extend>
Box parallel_bounds(std::size_t n, const Extend& extend) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 65536), Box(),
      [&](const tbb::blocked_range<std::size_t>& r, Box box) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) extend(box, i);
        return box;
      },
      [](Box a, const Box& b) {
        a.extend(b);
        return a;
      });
}

}  // namespace geods
