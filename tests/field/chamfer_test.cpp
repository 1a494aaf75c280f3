// field::chamfer against Dijkstra's algorithm on the grid (the exact chamfer
// distance: the shortest path of matrix steps to a background sample) and
// against the exact EDT (its documented error bound).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <queue>

#include "geods/core/error.hpp"
#include "geods/core/rng.hpp"
#include "geods/field/chamfer.hpp"
#include "geods/field/edt.hpp"

namespace geods::field {
namespace {

// Shortest paths of the matrix's steps (both halves) from every background sample.
std::vector<double> dijkstra(const Grid3<std::uint8_t>& mask, int size, const std::array<double, 3>& s) {
  const int r = size / 2;
  const auto [nx, ny, nz] = mask.dims;
  std::vector<double> d(mask.size(), INFINITY);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (!mask.data[i]) d[i] = 0, queue.push({0.0, i});
  while (!queue.empty()) {
    const auto [dist, i] = queue.top();
    queue.pop();
    if (dist > d[i]) continue;
    const long x = long(i % nx), y = long(i / nx % ny), z = long(i / (nx * ny));
    for (int dz = -r; dz <= r; ++dz)
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          if (std::gcd(std::gcd(std::abs(dx), std::abs(dy)), std::abs(dz)) != 1) continue;
          const long a = x + dx, b = y + dy, c = z + dz;
          if (a < 0 || b < 0 || c < 0 || a >= long(nx) || b >= long(ny) || c >= long(nz)) continue;
          const double len = std::sqrt(s[0] * s[0] * dx * dx + s[1] * s[1] * dy * dy + s[2] * s[2] * dz * dz);
          const std::size_t j = mask.index(std::size_t(a), std::size_t(b), std::size_t(c));
          if (dist + len < d[j]) d[j] = dist + len, queue.push({d[j], j});
        }
  }
  return d;
}

Grid3<std::uint8_t> random_mask(std::size_t nx, std::size_t ny, std::size_t nz, double foreground, std::uint64_t seed) {
  Rng rng(seed);
  Grid3<std::uint8_t> m(nx, ny, nz);
  for (auto& v : m.data) v = rng.uniform(0, 1) < foreground;
  m.data[seed % m.size()] = 0;
  return m;
}

TEST(Chamfer, TwoScansGiveTheShortestPathsOfSteps) {
  int masks = 0;
  for (const int size : {3, 5})
    for (const auto& spacing : {std::array<double, 3>{1, 1, 1}, std::array<double, 3>{1, 1.5, 0.7}})
      for (const double fg : {0.7, 0.97, 0.999}) {
        const Grid3<std::uint8_t> mask = random_mask(11, 9, 7, fg, std::uint64_t(size * 100 + fg * 1000));
        ChamferRequest request;
        request.size = size;
        request.spacing = spacing;
        const Grid3<double> d = chamfer(mask.view(), request);
        const std::vector<double> truth = dijkstra(mask, size, spacing);
        for (std::size_t i = 0; i < truth.size(); ++i) ASSERT_NEAR(d.data[i], truth[i], 1e-9) << i;
        ++masks;
      }
  EXPECT_EQ(masks, 12);
}

TEST(Chamfer, WithinItsErrorBoundOfTheExactDistance) {
  const double e3 = chamfer_max_error(3), e5 = chamfer_max_error(5);
  EXPECT_NEAR(e3, std::sqrt(1 + std::pow(std::sqrt(2.0) - 1, 2) + std::pow(std::sqrt(3.0) - std::sqrt(2.0), 2)) - 1,
              2e-3);  // the 3x3x3 norm's worst direction is (1, sqrt 2 - 1, sqrt 3 - sqrt 2)
  EXPECT_LT(e5, e3 / 2);
  for (const double fg : {0.9, 0.995}) {
    const Grid3<std::uint8_t> mask = random_mask(40, 30, 20, fg, std::uint64_t(fg * 1000));
    const EdtResult exact = edt(mask.view());
    for (const int size : {3, 5}) {
      ChamferRequest request;
      request.size = size;
      const Grid3<double> d = chamfer(mask.view(), request);
      const double e = size == 3 ? e3 : e5;
      double worst = 0;
      for (std::size_t i = 0; i < d.size(); ++i) {
        ASSERT_GE(d.data[i], exact.distance.data[i] * (1 - 1e-12)) << i;
        ASSERT_LE(d.data[i], exact.distance.data[i] * (1 + e) + 1e-12) << i;
        if (exact.distance.data[i] > 0) worst = std::max(worst, d.data[i] / exact.distance.data[i] - 1);
      }
      EXPECT_GT(worst, 0.0);  // an approximation: somewhere above the exact distance
    }
  }
}

TEST(Chamfer, DegenerateAndBadInput) {
  Grid3<std::uint8_t> all(4, 3, 2, 1);
  const Grid3<double> d = chamfer(all.view());
  for (const double v : d.data) EXPECT_TRUE(std::isinf(v));
  Grid3<std::uint8_t> none(4, 3, 2, 0);
  for (const double v : chamfer(none.view()).data) EXPECT_EQ(v, 0);
  Grid3<std::uint8_t> line(7, 1, 1, 1);  // a row: exact along the axis
  line(0, 0, 0) = 0;
  const Grid3<double> l = chamfer(line.view());
  for (std::size_t i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(l(i, 0, 0), double(i));
  ChamferRequest request;
  request.size = 4;
  EXPECT_THROW(chamfer(all.view(), request), Error);
  request.size = 3;
  request.spacing = std::array<double, 3>{1, 0, 1};
  EXPECT_THROW(chamfer(all.view(), request), Error);
  request.spacing = std::array<double, 3>{1, NAN, 1};
  EXPECT_THROW(chamfer(all.view(), request), Error);
}

}  // namespace
}  // namespace geods::field
