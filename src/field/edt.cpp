#include "geods/field/edt.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "../core/prefault.hpp"
#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::field {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The lower envelope of one line's parabolas g(p) + (s (q - p))^2, over the
// samples with a finite g (Felzenszwalb and Huttenlocher 2012, with the
// nearest sample's feature carried along). Ties at an integer q go to the
// smaller p: a breakpoint equal to q keeps the left parabola.
class LineEnvelope {
 public:
  // g, feature: the line's values and features (read); out, out_feature: written.
  void run(std::size_t n, double s, const double* g, const std::uint64_t* feature, double* out,
           std::uint64_t* out_feature) {
    apex_.resize(n);
    from_.resize(n + 1);
    const double s2 = s * s;
    std::size_t k = 0;  // parabolas in the envelope: apex_[0..k)
    for (std::size_t p = 0; p < n; ++p) {
      if (!(g[p] < kInf)) continue;
      double x = -kInf;
      while (k > 0) {
        x = crossing(apex_[k - 1], p, g, s2);
        if (x > from_[k - 1]) break;
        --k;  // the last parabola is nowhere strictly lowest
      }
      if (k == 0) x = -kInf;
      apex_[k] = p;
      from_[k] = x;
      ++k;
    }
    if (k == 0) {
      std::fill_n(out, n, kInf);
      if (out_feature) std::fill_n(out_feature, n, EdtResult::kNoFeature);
      return;
    }
    from_[k] = kInf;
    std::size_t j = 0;
    for (std::size_t q = 0; q < n; ++q) {
      while (from_[j + 1] < double(q)) ++j;
      const std::size_t p = apex_[j];
      const double d = s * (double(q) - double(p));
      out[q] = g[p] + d * d;
      if (out_feature) out_feature[q] = feature[p];
    }
  }

 private:
  // Where the parabola of p (left) and that of r (right) meet. The squared
  // terms are divided by s^2 so that an integer crossing of integer data is
  // computed exactly (see the header on exactness).
  static double crossing(std::size_t p, std::size_t r, const double* g, double s2) {
    const double dp = double(p), dr = double(r);
    return ((g[r] - g[p]) / s2 + (dr * dr - dp * dp)) / (2 * (dr - dp));
  }

  std::vector<std::size_t> apex_;
  std::vector<double> from_;  // from_[k]: where parabola k starts being the lowest
};

// The pass along y (axis 1) or z (axis 2): every line of the grid through the
// envelope, in place. Lines are copied out and back in bundles of kBundle
// neighbours in x, so each strided step reads and writes whole cache lines.
void pass(const Grid3Geometry& grid, int axis, double s, std::span<double> g, std::vector<std::uint64_t>* feature) {
  constexpr std::size_t kBundle = 8;
  const auto& d = grid.dims;
  const std::size_t n = d[axis];
  if (n <= 1) return;
  const std::size_t stride = axis == 1 ? d[0] : d[0] * d[1];
  // Bundles are numbered by x / kBundle (fastest) and the other coordinate.
  const std::size_t na = (d[0] + kBundle - 1) / kBundle, nb = axis == 2 ? d[1] : d[2];
  const std::size_t b_stride = axis == 2 ? d[0] : d[0] * d[1];
  parallel_for(0, na * nb, std::max<std::size_t>(1, 4096 / (n * kBundle)), [&](std::size_t begin, std::size_t end) {
    LineEnvelope envelope;
    std::vector<double> line(n * kBundle), out(n);
    std::vector<std::uint64_t> line_feature(feature ? n * kBundle : 0), out_feature(feature ? n : 0);
    for (std::size_t l = begin; l < end; ++l) {
      const std::size_t a = l % na, first = a * kBundle + (l / na) * b_stride;
      const std::size_t width = std::min(kBundle, d[0] - a * kBundle);
      for (std::size_t q = 0; q < n; ++q)
        for (std::size_t b = 0; b < width; ++b) line[b * n + q] = g[first + q * stride + b];
      if (feature)
        for (std::size_t q = 0; q < n; ++q)
          for (std::size_t b = 0; b < width; ++b) line_feature[b * n + q] = (*feature)[first + q * stride + b];
      for (std::size_t b = 0; b < width; ++b) {
        envelope.run(n, s, line.data() + b * n, line_feature.data() + (feature ? b * n : 0), out.data(),
                     feature ? out_feature.data() : nullptr);
        std::copy_n(out.data(), n, line.data() + b * n);
        if (feature) std::copy_n(out_feature.data(), n, line_feature.data() + b * n);
      }
      for (std::size_t q = 0; q < n; ++q)
        for (std::size_t b = 0; b < width; ++b) g[first + q * stride + b] = line[b * n + q];
      if (feature)
        for (std::size_t q = 0; q < n; ++q)
          for (std::size_t b = 0; b < width; ++b) (*feature)[first + q * stride + b] = line_feature[b * n + q];
    }
  });
}

// The pass along x straight from the mask: a sample's nearest background
// sample in its row is the nearer of the last one before it and the first one
// after it (the one before on a tie), found by one scan each way.
void first_pass(const Grid3View<std::uint8_t>& mask, double s, std::vector<double>& g,
                std::vector<std::uint64_t>* feature) {
  const std::size_t n = mask.dims[0];
  parallel_for(0, mask.dims[1] * mask.dims[2], std::max<std::size_t>(1, 4096 / n), [&](std::size_t begin, std::size_t end) {
    constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> before(n);
    for (std::size_t l = begin; l < end; ++l) {
      const std::size_t first = l * n;
      const std::uint8_t* m = mask.data.data() + first;
      std::size_t last = kNone;
      for (std::size_t q = 0; q < n; ++q) before[q] = last = m[q] ? last : q;
      std::size_t next = kNone;
      for (std::size_t q = n; q-- > 0;) {
        if (!m[q]) next = q;
        std::size_t p = before[q];
        if (next != kNone && (p == kNone || next - q < q - p)) p = next;
        if (p == kNone) {
          g[first + q] = kInf;
          if (feature) (*feature)[first + q] = EdtResult::kNoFeature;
        } else {
          const double d = s * (double(q) - double(p));
          g[first + q] = d * d;
          if (feature) (*feature)[first + q] = first + p;
        }
      }
    }
  });
}

void check_spacing(double s, int axis, double side) {
  const std::string where = format_number(s) + " along " + std::string(1, char('x' + axis));
  if (!std::isfinite(s) || !(s > 0)) throw Error("edt: spacing must be finite and > 0, got " + where);
  // Squared distances of up to (spacing * side)^2 must neither underflow nor overflow.
  if (s < 1e-150 || s * side > 1e150)
    throw Error("edt: spacing " + where + " is out of range (squared distances would underflow or overflow; "
                "rescale the spacing)");
}

}  // namespace

void edt_pass(std::span<double> g, const std::array<std::size_t, 3>& dims, int axis, double spacing) {
  if (axis < 0 || axis > 2) throw Error("edt_pass: axis must be 0 (x), 1 (y) or 2 (z), got " + std::to_string(axis));
  check_spacing(spacing, axis, double(dims[std::size_t(axis)]));
  const std::size_t size = Grid3<double>::checked_size(dims[0], dims[1], dims[2]);
  if (g.size() != size)
    throw Error("edt_pass: the array holds " + std::to_string(g.size()) + " values, its dims say " + std::to_string(size));
  if (size == 0) return;
  if (axis > 0) {
    Grid3Geometry grid;
    grid.dims = dims;
    pass(grid, axis, spacing, g, nullptr);
    return;
  }
  const std::size_t n = dims[0];
  parallel_for(0, dims[1] * dims[2], std::max<std::size_t>(1, 4096 / n), [&](std::size_t begin, std::size_t end) {
    LineEnvelope envelope;
    std::vector<double> out(n);
    for (std::size_t l = begin; l < end; ++l) {
      envelope.run(n, spacing, g.data() + l * n, nullptr, out.data(), nullptr);
      std::copy_n(out.data(), n, g.data() + l * n);
    }
  });
}

EdtResult edt(const Grid3View<std::uint8_t>& mask, const EdtRequest& request) {
  std::array<double, 3> spacing{double(mask.spacing[0]), double(mask.spacing[1]), double(mask.spacing[2])};
  if (request.spacing) spacing = *request.spacing;
  for (int a = 0; a < 3; ++a) check_spacing(spacing[a], a, double(mask.dims[a]));
  const std::size_t size = Grid3<double>::checked_size(mask.dims[0], mask.dims[1], mask.dims[2]);
  if (mask.data.size() != size) throw Error("edt: the mask holds " + std::to_string(mask.data.size()) +
                                            " samples, its dims say " + std::to_string(size));

  EdtResult result;
  result.distance.dims = mask.dims;
  result.distance.origin = mask.origin;
  result.distance.spacing = mask.spacing;
  // The output arrays mapped at once (huge pages advised): a fault per 4 KiB
  // page on the calling thread was a serial tenth of the transform.
  std::vector<double>& g = result.distance.data;
  detail::reserve_prefaulted(g, size);
  g.resize(size);
  for (const std::uint8_t v : mask.data) result.foreground += v != 0;
  std::vector<std::uint64_t>* feature = nullptr;
  if (request.features) {
    detail::reserve_prefaulted(result.features, size);
    result.features.resize(size);
    feature = &result.features;
  }
  if (size == 0) return result;
  first_pass(mask, spacing[0], g, feature);
  for (int axis = 1; axis < 3; ++axis) pass(result.distance, axis, spacing[axis], g, feature);
  if (!request.squared)
    parallel_for(0, size, 1 << 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) g[i] = std::sqrt(g[i]);
    });
  return result;
}

}  // namespace geods::field
