// The coordinate range of distance computations: the limits are where the
// polynomials really overflow or underflow, and the checks refuse just that.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "geods/core/coordinate_range.hpp"
#include "geods/core/parallel.hpp"

namespace geods {
namespace {

TEST(CoordinateRange, LimitsAreWhereSquaredDistancesOverflowAndUnderflow) {
  EXPECT_EQ(coordinate_limit<double>(2), std::ldexp(1.0, 502));
  EXPECT_EQ(coordinate_limit<float>(2), std::ldexp(1.0f, 54));
  EXPECT_EQ(coordinate_limit<double>(3), std::ldexp(1.0, 334));
  EXPECT_EQ(extent_floor<double>(2), std::ldexp(1.0, -458));
  EXPECT_EQ(extent_floor<float>(2), std::ldexp(1.0f, -39));
  // At the limit, 2^16 squared differences of opposite corners still sum to a finite value.
  for (int degree : {2, 3}) {
    const double m = coordinate_limit<double>(degree);
    const double term = std::pow(2 * m, degree);
    EXPECT_TRUE(std::isfinite(term * 65536)) << degree;
  }
  const float mf = coordinate_limit<float>(2);
  EXPECT_TRUE(std::isfinite((2 * mf) * (2 * mf) * 65536.0f));
  // At the floor, the smallest resolvable difference of the extent still has a normal square.
  const double e = extent_floor<double>(2) * std::ldexp(1.0, -53);
  EXPECT_GE(e * e, std::numeric_limits<double>::min());
  const float ef = extent_floor<float>(2) * std::ldexp(1.0f, -24);
  EXPECT_GE(ef * ef, std::numeric_limits<float>::min());
}

TEST(CoordinateRange, RefusesPointsBeyondTheRangeAndNothingElse) {
  const std::vector<double> unit{0, 0, 1, 0, 0, 1};
  EXPECT_NO_THROW(check_coordinate_range(unit.data(), 3, 2, 2, 2, "test"));
  for (double s : {1e300, 1e-300, 1e152, 1e-140}) {
    std::vector<double> scaled = unit;
    for (double& x : scaled) x *= s;
    EXPECT_THROW(check_coordinate_range(scaled.data(), 3, 2, 2, 2, "test"), Error) << s;
  }
  for (double s : {1e150, 1e-130}) {
    std::vector<double> scaled = unit;
    for (double& x : scaled) x *= s;
    EXPECT_NO_THROW(check_coordinate_range(scaled.data(), 3, 2, 2, 2, "test")) << s;
  }
  // Far from the origin but spread out: fine; all points equal: fine (no distances to lose).
  const std::vector<double> far{1e100, 1e100, 1e100 + 1e90, 1e100};
  EXPECT_NO_THROW(check_coordinate_range(far.data(), 2, 2, 2, 2, "test"));
  const std::vector<double> same{1e-300, 1e-300, 1e-300, 1e-300};
  EXPECT_NO_THROW(check_coordinate_range(same.data(), 2, 2, 2, 2, "test"));
  // Stride skips the values between rows.
  const std::vector<double> strided{0, 1e300, 1, 1e300};
  EXPECT_NO_THROW(check_coordinate_range(strided.data(), 2, 1, 2, 2, "test"));
  // The message names the caller and the value briefly.
  try {
    const std::vector<float> big{0, 1e20f};
    check_coordinate_range(big.data(), 2, 1, 1, 2, "KdTree");
    FAIL();
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("KdTree: coordinate 1e+20 of point 1", 0), 0u) << m;
    EXPECT_LT(m.size(), 160u) << m;
  }
  const std::vector<double> q{3e200, 0};
  EXPECT_THROW(check_query_range<2>(std::span<const double>(q), "test"), Error);
  EXPECT_NO_THROW(check_query_range<2>(std::span<const double>(q).subspan(1), "test"));
}

// The one-pass scan is split over threads in chunks of rows: its extent and
// its verdict must be those of looking at every coordinate, wherever the
// outlier lies (first row, a chunk boundary, last row) and on any thread count.
TEST(CoordinateRange, ParallelScanMatchesBruteForce) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0, 1e3);
  for (std::size_t dim : {1, 2, 3, 5})
    for (std::size_t stride : {dim, dim + 2})
      for (std::size_t n : {std::size_t(1), std::size_t(1000), std::size_t(200003)}) {
        std::vector<double> coords(n * stride);
        for (double& x : coords) x = normal(rng);
        double extent = 0;
        for (std::size_t a = 0; a < dim; ++a) {
          double lo = coords[a], hi = coords[a];
          for (std::size_t i = 0; i < n; ++i) {
            lo = std::min(lo, coords[i * stride + a]);
            hi = std::max(hi, coords[i * stride + a]);
          }
          extent = std::max(extent, hi - lo);
        }
        const double limit = coordinate_limit<double>(2);
        for (int threads : {1, 2, 3}) {
          set_num_threads(threads);
          const CoordinateScan<double> scan = scan_coordinates(coords.data(), n, dim, stride, limit);
          EXPECT_TRUE(scan.finite_within);
          EXPECT_EQ(scan.extent, extent) << dim << " " << n;
          for (std::size_t row : {std::size_t(0), std::min(n - 1, std::size_t(65536)), n - 1})
            for (double bad : {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity(),
                               2 * limit}) {
              std::vector<double> spoiled = coords;
              spoiled[row * stride + dim - 1] = bad;
              EXPECT_FALSE(scan_coordinates(spoiled.data(), n, dim, stride, limit).finite_within) << row << " " << bad;
            }
          // A value between the rows (stride) is not a coordinate.
          if (stride > dim) {
            std::vector<double> between = coords;
            between[(n - 1) * stride + dim] = std::numeric_limits<double>::quiet_NaN();
            EXPECT_TRUE(scan_coordinates(between.data(), n, dim, stride, limit).finite_within);
          }
        }
        set_num_threads(0);
      }
  // Many points: the error still names the first coordinate beyond, axis by axis.
  std::vector<float> many(3 * 300000, 1.0f);
  many[3 * 250000 + 0] = 1e20f;
  many[3 * 100000 + 1] = 2e20f;
  try {
    check_coordinate_range(many.data(), 300000, 3, 3, 2, "KdTree");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("KdTree: coordinate 1e+20 of point 250000", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace geods
