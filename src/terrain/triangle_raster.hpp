#pragma once
// Internal to the terrain module: the samples of a grid triangle and their
// vertical distance to the triangle's plane.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace geods::terrain::detail {

struct P2 {
  std::int64_t x, y;
};

struct Worst {
  double error = 0;
  P2 at{0, 0};
};

// The largest |z(sample) - plane(sample)| over the grid samples in the closed
// triangle (a, b, c) (integer grid coordinates) of an n-wide matrix of heights,
// and the sample where it is (the first such in row order).
inline Worst triangle_worst(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  const double za = z[a.y * n + a.x], zb = z[b.y * n + b.x], zc = z[c.y * n + c.x];
  // Plane z = za + gx (x - ax) + gy (y - ay).
  const double ux = double(b.x - a.x), uy = double(b.y - a.y), vx = double(c.x - a.x), vy = double(c.y - a.y);
  const double det = ux * vy - uy * vx;
  const double gx = ((zb - za) * vy - (zc - za) * uy) / det;
  const double gy = ((zc - za) * ux - (zb - za) * vx) / det;
  // Edge functions, made >= 0 inside.
  P2 v[3] = {a, b, c};
  if (det < 0) std::swap(v[1], v[2]);
  const std::int64_t y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
  const std::int64_t xmin = std::min({a.x, b.x, c.x}), xmax = std::max({a.x, b.x, c.x});
  Worst worst;
  for (std::int64_t y = y0; y <= y1; ++y) {
    std::int64_t lo = xmin, hi = xmax;
    for (int e = 0; e < 3; ++e) {
      const P2 p = v[e], q = v[(e + 1) % 3];
      // E(x, y) = (q.x - p.x) (y - p.y) - (q.y - p.y) (x - p.x) >= 0, i.e. A x <= B.
      const std::int64_t A = q.y - p.y, B = (q.x - p.x) * (y - p.y) + (q.y - p.y) * p.x;
      if (A > 0)
        hi = std::min(hi, B >= 0 ? B / A : -((-B + A - 1) / A));
      else if (A < 0)
        lo = std::max(lo, (-B) >= 0 ? ((-B) + (-A) - 1) / (-A) : -((B) / (-A)));
      else if (B < 0)
        lo = hi + 1;
    }
    const float* row = z + y * n;
    // Relative to a: the same rounding wherever the triangle lies (tin_tile() of a block equals the tile of tin()).
    const double base = za + gy * double(y - a.y);
    for (std::int64_t x = lo; x <= hi; ++x) {
      const double d = std::abs(double(row[x]) - (base + gx * double(x - a.x)));
      if (d > worst.error) worst = {d, {x, y}};
    }
  }
  return worst;
}

inline double triangle_error(const float* z, std::uint64_t n, P2 a, P2 b, P2 c) {
  return triangle_worst(z, n, a, b, c).error;
}

}  // namespace geods::terrain::detail
