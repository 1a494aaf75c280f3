#pragma once
// A per-query mailbox (seed §2.5): the classic one stores the last ray id with
// every triangle, which threads would race on. This one lives on the query's
// stack and remembers the last triangle tested in each of 64 slots (indexed by
// triangle id), so a triangle listed in several cells is tested once in
// almost every case; a collision only costs a repeated test, never an answer.
#include <array>
#include <cstdint>

#include "geods/core/ray_triangle.hpp"

namespace geods::ray::detail {

class Mailbox {
 public:
  Mailbox() { slots_.fill(RayHit::no_hit); }
  /// True if `prim` was tested already; otherwise records it.
  bool seen(std::uint32_t prim) {
    std::uint32_t& slot = slots_[prim & 63];
    if (slot == prim) return true;
    slot = prim;
    return false;
  }

 private:
  std::array<std::uint32_t, 64> slots_;
};

}  // namespace geods::ray::detail
