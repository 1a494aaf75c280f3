#pragma once
// The instruction set of the kernels compiled more than once (the wide ray
// traversal of bvh::TriangleBvh, terrain's error rows), chosen at run time like
// Embree's: the portable build (SSE4.2 with the default
// -march=x86-64-v2, plain scalar code elsewhere), AVX, AVX2 or AVX-512
// (AVX-512 F/VL/BW/DQ on 256-bit vectors). Every level performs the same IEEE
// operations in the same order (no FMA contraction), so hits are
// bit-identical at every level; the wider levels only run faster.
//
// The environment variable GEODS_SIMD (portable, avx, avx2, avx512), read
// once, caps the level, e.g. GEODS_SIMD=portable to test the portable path.
#include <string>

namespace geods {

enum class SimdLevel { portable, avx, avx2, avx512 };

/// The highest level this CPU (and the build) supports.
SimdLevel best_simd_level();
/// The level the kernels use: best_simd_level(), capped by GEODS_SIMD.
SimdLevel simd_level();
/// Sets the level of later kernel calls (every thread). Throws geods::Error
/// if the CPU or the build does not support it.
void set_simd_level(SimdLevel level);
/// "portable", "avx", "avx2", "avx512"; and back (geods::Error for other names).
std::string simd_level_name(SimdLevel level);
SimdLevel parse_simd_level(const std::string& name);

}  // namespace geods
