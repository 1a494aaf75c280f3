#pragma once
// Restores the SIMD level (core/simd_level.hpp) a test started with, also when
// an ASSERT leaves the test early, so later tests run at the level they expect.
#include "geods/core/simd_level.hpp"

namespace geods::test {

struct LevelGuard {
  SimdLevel saved = simd_level();
  ~LevelGuard() { set_simd_level(saved); }
};

}  // namespace geods::test
