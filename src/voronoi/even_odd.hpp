#pragma once
// Even-odd point-in-polygon over a set of segments, with the segments
// bucketed into horizontal strips so that a query reads only the segments
// that span its y (internal to the voronoi module).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "geods/core/vec.hpp"

namespace geods::voronoi::detail {

class EvenOddIndex {
 public:
  explicit EvenOddIndex(std::vector<std::array<Vec2d, 2>> segments) : segments_(std::move(segments)) {
    if (segments_.empty()) return;
    lo_ = hi_ = segments_[0][0][1];
    for (const auto& s : segments_)
      for (const auto& p : s) lo_ = std::min(lo_, p[1]), hi_ = std::max(hi_, p[1]);
    strips_ = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(segments_.size()))), 1, 4096);
    height_ = (hi_ - lo_) / strips_;
    if (!(height_ > 0)) strips_ = 1, height_ = 1;
    bucket_.assign(strips_, {});
    for (std::uint32_t i = 0; i < segments_.size(); ++i) {
      const double a = std::min(segments_[i][0][1], segments_[i][1][1]), b = std::max(segments_[i][0][1], segments_[i][1][1]);
      for (int k = strip(a); k <= strip(b); ++k) bucket_[k].push_back(i);
    }
  }

  bool inside(const Vec2d& x) const {
    if (segments_.empty() || x[1] < lo_ || x[1] > hi_) return false;
    bool in = false;
    for (std::uint32_t i : bucket_[strip(x[1])]) {
      const Vec2d a = segments_[i][0], b = segments_[i][1];
      if ((a[1] > x[1]) != (b[1] > x[1])) {
        const double xi = a[0] + (x[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
        if (xi > x[0]) in = !in;
      }
    }
    return in;
  }

 private:
  int strip(double y) const { return std::clamp(static_cast<int>((y - lo_) / height_), 0, strips_ - 1); }
  std::vector<std::array<Vec2d, 2>> segments_;
  double lo_ = 0, hi_ = 0, height_ = 1;
  int strips_ = 1;
  std::vector<std::vector<std::uint32_t>> bucket_;
};

}  // namespace geods::voronoi::detail
