#include "geods/field/chamfer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "geods/core/error.hpp"

namespace geods::field {
namespace {

struct Step {
  int dx, dy, dz;
  double length;
};

// The matrix's steps that come before a sample in the forward scan (z, then
// y, then x increasing): the half the forward pass reads. Steps that are
// multiples of a smaller one are left out (the smaller one, taken twice, is
// as long).
std::vector<Step> forward_steps(int size, const std::array<double, 3>& s) {
  const int r = size / 2;
  std::vector<Step> steps;
  for (int dz = -r; dz <= r; ++dz)
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const bool before = dz < 0 || (dz == 0 && (dy < 0 || (dy == 0 && dx < 0)));
        if (!before || std::gcd(std::gcd(std::abs(dx), std::abs(dy)), std::abs(dz)) != 1) continue;
        const double x = s[0] * dx, y = s[1] * dy, z = s[2] * dz;
        steps.push_back({dx, dy, dz, std::sqrt(x * x + y * y + z * z)});
      }
  return steps;
}

}  // namespace

Grid3<double> chamfer(const Grid3View<std::uint8_t>& mask, const ChamferRequest& request) {
  if (request.size != 3 && request.size != 5)
    throw Error("chamfer: the distance matrix is 3x3x3 or 5x5x5 (size 3 or 5), got size " + std::to_string(request.size));
  std::array<double, 3> spacing{double(mask.spacing[0]), double(mask.spacing[1]), double(mask.spacing[2])};
  if (request.spacing) spacing = *request.spacing;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(spacing[a]) || !(spacing[a] > 0) || spacing[a] > 1e150)
      throw Error("chamfer: spacing must be finite and > 0, got " + std::to_string(spacing[a]) + " along " +
                  std::string(1, char('x' + a)));
  const std::size_t size = Grid3<double>::checked_size(mask.dims[0], mask.dims[1], mask.dims[2]);
  if (mask.data.size() != size)
    throw Error("chamfer: the mask holds " + std::to_string(mask.data.size()) + " samples, its dims say " +
                std::to_string(size));

  // The distances in a volume padded by r samples of +infinity on each side,
  // so that no step needs a bounds check.
  const int r = request.size / 2;
  const std::size_t px = mask.dims[0] + 2 * r, py = mask.dims[1] + 2 * r, pz = mask.dims[2] + 2 * r;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> d(Grid3<double>::checked_size(px, py, pz), kInf);
  const auto at = [&](std::size_t i, std::size_t j, std::size_t k) { return (i + r) + px * ((j + r) + py * (k + r)); };
  for (std::size_t k = 0; k < mask.dims[2]; ++k)
    for (std::size_t j = 0; j < mask.dims[1]; ++j)
      for (std::size_t i = 0; i < mask.dims[0]; ++i)
        if (!mask(i, j, k)) d[at(i, j, k)] = 0;

  struct Offset {
    std::ptrdiff_t delta;
    double length;
  };
  std::vector<Offset> steps;
  for (const Step& s : forward_steps(request.size, spacing))
    steps.push_back({std::ptrdiff_t(s.dx) + std::ptrdiff_t(px) * (s.dy + std::ptrdiff_t(py) * s.dz), s.length});
  // Forward: each sample from the samples before it; backward: from those after it.
  for (std::size_t k = 0; k < mask.dims[2]; ++k)
    for (std::size_t j = 0; j < mask.dims[1]; ++j) {
      double* row = d.data() + at(0, j, k);
      for (std::size_t i = 0; i < mask.dims[0]; ++i) {
        double v = row[i];
        if (v == 0) continue;
        for (const Offset& o : steps) v = std::min(v, row[std::ptrdiff_t(i) + o.delta] + o.length);
        row[i] = v;
      }
    }
  for (std::size_t k = mask.dims[2]; k-- > 0;)
    for (std::size_t j = mask.dims[1]; j-- > 0;) {
      double* row = d.data() + at(0, j, k);
      for (std::size_t i = mask.dims[0]; i-- > 0;) {
        double v = row[i];
        if (v == 0) continue;
        for (const Offset& o : steps) v = std::min(v, row[std::ptrdiff_t(i) - o.delta] + o.length);
        row[i] = v;
      }
    }

  Grid3<double> out;
  static_cast<Grid3Geometry&>(out) = mask;
  out.data.resize(size);
  for (std::size_t k = 0; k < mask.dims[2]; ++k)
    for (std::size_t j = 0; j < mask.dims[1]; ++j)
      std::copy_n(d.data() + at(0, j, k), mask.dims[0], out.data.data() + mask.index(0, j, k));
  return out;
}

double chamfer_max_error(int size) {
  // One background sample at a corner of a cube: every sample's ratio to its
  // Euclidean distance, over directions with integer coordinates up to n.
  constexpr std::size_t n = 48;
  Grid3<std::uint8_t> mask(n, n, n, 1);
  mask(0, 0, 0) = 0;
  ChamferRequest request;
  request.size = size;
  request.spacing = std::array<double, 3>{1, 1, 1};
  const Grid3<double> d = chamfer(mask.view(), request);
  double worst = 0;
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t i = 0; i < n; ++i)
        if (i + j + k > 0) worst = std::max(worst, d(i, j, k) / std::sqrt(double(i * i + j * j + k * k)) - 1);
  return worst;
}

}  // namespace geods::field
