#pragma once
// Eigen-based fixed-size vectors used throughout geods.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <cstdint>
#include <type_traits>

#include "geods/core/bytewise.hpp"

namespace geods {

template <typename T, int N>
using Vec = Eigen::Matrix<T, N, 1>;

using Vec2f = Vec<float, 2>;
using Vec3f = Vec<float, 3>;
using Vec4f = Vec<float, 4>;
using Vec2d = Vec<double, 2>;
using Vec3d = Vec<double, 3>;
using Vec4d = Vec<double, 4>;
using Vec2i = Vec<std::int32_t, 2>;
using Vec3i = Vec<std::int32_t, 3>;
using Vec3u = Vec<std::uint32_t, 3>;

/// A fixed-size Eigen matrix is its coefficients (saved and mapped as is).
template <typename S, int R, int C, int Options, int MaxR, int MaxC>
struct is_bytewise<Eigen::Matrix<S, R, C, Options, MaxR, MaxC>>
    : std::bool_constant<std::is_arithmetic_v<S> && (R > 0) && (C > 0)> {};

}  // namespace geods
