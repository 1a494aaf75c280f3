#include "geods/core/morton.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "geods/core/parallel.hpp"

namespace geods {

namespace {

// Quantizes t in [0, 1] to [0, cells - 1], clamping outside values and NaN to 0.
std::uint32_t quantize(double t, double cells) {
  const double q = std::floor(t * cells);
  if (!(q > 0)) return 0;
  return q >= cells - 1 ? std::uint32_t(cells - 1) : std::uint32_t(q);
}

template <int N>
std::vector<std::uint64_t> codes_of(const std::vector<Vec<double, N>>& points, const AABB<double, N>& box) {
  constexpr double cells = N == 2 ? 4294967296.0 : 2097152.0;
  const Vec<double, N> extent = box.extent();
  Vec<double, N> inv;
  for (int a = 0; a < N; ++a) inv[a] = extent[a] > 0 ? 1.0 / extent[a] : 0.0;
  std::vector<std::uint64_t> codes(points.size());
  parallel_for_each_index(0, points.size(), [&](std::size_t i) {
    const Vec<double, N> t = (points[i] - box.lo).cwiseProduct(inv);
    if constexpr (N == 2) {
      codes[i] = morton2d_encode64(quantize(t[0], cells), quantize(t[1], cells));
    } else {
      codes[i] = morton3d_encode64(quantize(t[0], cells), quantize(t[1], cells), quantize(t[2], cells));
    }
  });
  return codes;
}

template <int N>
std::vector<std::uint32_t> order_of(const std::vector<Vec<double, N>>& points) {
  const std::vector<std::uint64_t> codes = codes_of<N>(points, bounds_of<double, N>(points));
  std::vector<std::uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return codes[a] != codes[b] ? codes[a] < codes[b] : a < b;
  });
  return order;
}

}  // namespace

std::vector<std::uint64_t> morton_codes(const std::vector<Vec2d>& points, const AABB2d& box) {
  return codes_of<2>(points, box);
}
std::vector<std::uint64_t> morton_codes(const std::vector<Vec3d>& points, const AABB3d& box) {
  return codes_of<3>(points, box);
}
std::vector<std::uint32_t> morton_order(const std::vector<Vec2d>& points) { return order_of<2>(points); }
std::vector<std::uint32_t> morton_order(const std::vector<Vec3d>& points) { return order_of<3>(points); }

}  // namespace geods
