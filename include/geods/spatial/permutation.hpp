#pragma once
// The index permutation the pointer-free trees keep: tree order -> input index.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "geods/core/error.hpp"

namespace geods::spatial {

/// Throws geods::Error("<who>: ...") unless `perm` holds each of 0..n-1 exactly once.
inline void require_permutation(std::span<const std::uint32_t> perm, std::size_t n, const std::string& who) {
  if (perm.size() != n) {
    throw Error(who + ": permutation has " + std::to_string(perm.size()) + " entries for " + std::to_string(n) +
                " points");
  }
  std::vector<bool> seen(n, false);
  for (std::uint32_t i : perm) {
    if (i >= n || seen[i]) throw Error(who + ": permutation is not a permutation (entry " + std::to_string(i) + ")");
    seen[i] = true;
  }
}

}  // namespace geods::spatial
