#pragma once
// Which points a query skips: a predicate skip(index) that is true for the
// points to hide, such as the weakly deleted points of a dynamic structure.
#include <cstdint>
#include <type_traits>

namespace geods::spatial {

/// The default filter: hides nothing. Queries test for it at compile time, so
/// a query without a filter runs the code it ran before filters existed.
struct KeepAll {
  constexpr bool operator()(std::uint32_t) const { return false; }
};

/// Hides the points whose flag is non-zero: a view of one byte per point index.
struct SkipFlagged {
  const std::uint8_t* flags;
  bool operator()(std::uint32_t index) const { return flags[index] != 0; }
};

template <typename Skip>
inline constexpr bool kSkipsNothing = std::is_same_v<Skip, KeepAll>;

}  // namespace geods::spatial
