#pragma once
// Parallel helpers over oneTBB, and the global thread limit.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

}  // namespace geods
