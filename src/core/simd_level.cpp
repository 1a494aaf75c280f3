// Run-time choice of the instruction set of the multi-versioned kernels.
#include "geods/core/simd_level.hpp"

#include <atomic>
#include <cstdlib>

#include "geods/core/error.hpp"

namespace geods {
namespace {

SimdLevel detect() {
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq"))
    return SimdLevel::avx512;
  if (__builtin_cpu_supports("avx2")) return SimdLevel::avx2;
  if (__builtin_cpu_supports("avx")) return SimdLevel::avx;
#endif
  return SimdLevel::portable;
}

std::atomic<int>& current() {
  static std::atomic<int> level = [] {
    SimdLevel l = best_simd_level();
    if (const char* env = std::getenv("GEODS_SIMD"); env != nullptr && *env != '\0') {
      const SimdLevel cap = parse_simd_level(env);  // a bad name is an error, not silently ignored
      if (cap < l) l = cap;
    }
    return int(l);
  }();
  return level;
}

}  // namespace

SimdLevel best_simd_level() {
  static const SimdLevel best = detect();
  return best;
}

SimdLevel simd_level() { return SimdLevel(current().load(std::memory_order_relaxed)); }

void set_simd_level(SimdLevel level) {
  if (level > best_simd_level())
    throw Error("simd: this CPU does not run " + simd_level_name(level) + " (best: " +
                simd_level_name(best_simd_level()) + ")");
  current().store(int(level), std::memory_order_relaxed);
}

std::string simd_level_name(SimdLevel level) {
  switch (level) {
    case SimdLevel::portable: return "portable";
    case SimdLevel::avx: return "avx";
    case SimdLevel::avx2: return "avx2";
    case SimdLevel::avx512: return "avx512";
  }
  return "portable";
}

SimdLevel parse_simd_level(const std::string& name) {
  for (SimdLevel l : {SimdLevel::portable, SimdLevel::avx, SimdLevel::avx2, SimdLevel::avx512})
    if (simd_level_name(l) == name) return l;
  throw Error("simd: unknown SIMD level '" + name + "' (portable, avx, avx2, avx512)");
}

}  // namespace geods
