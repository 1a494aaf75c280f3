#pragma once
// The neighbourhood N(p) of texture synthesis (seed §5.5, Figures 52 and 53):
// the pixels of an n x n window around p at p's pyramid level, and the pixels
// of an m x m window around p's parent (x / 2, y / 2) one level coarser.
// During the scan-line pass the fine window is causal: only the rows above p
// and the pixels left of p in its row, all of which are synthesized before p.
// A neighbourhood is a vector of 8-bit values, the channels of each offset in
// turn: fine offsets first, then parent offsets.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace geods::texture {

struct Offset {
  int dx, dy;
};

struct NeighborhoodShape {
  std::vector<Offset> fine;    // at p's level
  std::vector<Offset> parent;  // around (x / 2, y / 2) at the coarser level (empty at the coarsest)
  int fine_half = 0;           // the fine window is (2 fine_half + 1) wide
  int parent_half = 0;

  /// size: odd fine window side >= 3; parent_size: odd parent window side >= 1,
  /// 0 for no parent level. causal: the fine window's pixels before p in scan
  /// order (the scan-line pass); otherwise the whole window without p (the
  /// refinement passes).
  static NeighborhoodShape make(std::size_t size, std::size_t parent_size, bool causal);

  /// Values per vector: (fine + parent offsets) * channels.
  std::size_t dimension(std::size_t channels) const { return (fine.size() + parent.size()) * channels; }
};

}  // namespace geods::texture
