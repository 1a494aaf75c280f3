#pragma once
// Shared by the full scan and the octree: the inside test, the face decisions
// of one cell, and the placement of edge vertices (regular or curvilinear).
#include <Eigen/Dense>

#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <type_traits>
#include <vector>

#include "geods/core/error.hpp"
#include "geods/core/grid3.hpp"
#include "geods/core/parallel.hpp"
#include "geods/iso/case_table.hpp"

namespace geods::iso::detail {

struct CaseTableView {
  const std::uint8_t* ambiguous;  // 256 masks of ambiguous faces
  const std::uint32_t* offsets;   // entry c * 64 + joined -> [offsets[i], offsets[i + 1]) in edges
  const std::uint8_t* edges;
  const std::uint16_t* centres;  // kMaxCentres edge masks per entry, 0 if unused
};
CaseTableView case_table_view();

// Same as face_corners(f) and edge_corners(e), as constants for the hot loops.
inline constexpr std::uint8_t kFaceCorners[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                                    {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
inline constexpr std::uint8_t kEdgeCorners[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                     {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

/// Crossed cube edges (bit e) of each case.
inline constexpr auto kCrossedEdges = [] {
  std::array<std::uint16_t, 256> mask{};
  for (int c = 0; c < 256; ++c)
    for (int e = 0; e < 12; ++e)
      if (((c >> kEdgeCorners[e][0]) & 1) != ((c >> kEdgeCorners[e][1]) & 1)) mask[c] |= std::uint16_t(1 << e);
  return mask;
}();

/// The centre vertex of a cell (see case_triangles()): the mean of the
/// vertices ids[e] of the edges e in `mask`, and (if `normals` is not null)
/// the mean of their normals.
inline void centre_vertex(std::uint16_t mask, const std::uint32_t* ids, const Vec3f* positions, const Vec3f* normals,
                          Vec3f& position, Vec3f& normal) {
  Vec3d p = Vec3d::Zero(), n = Vec3d::Zero();
  int count = 0;
  for (int e = 0; e < 12; ++e) {
    if (!((mask >> e) & 1)) continue;
    p += positions[ids[e]].cast<double>();
    if (normals) n += normals[ids[e]].cast<double>();
    ++count;
  }
  position = (p / count).cast<float>();
  if (normals) normal = n.squaredNorm() > 0 ? n.normalized().cast<float>() : normals[ids[std::countr_zero(mask)]];
}

/// Appends the centre vertex of a cell (centre_vertex()) to the output arrays;
/// `normals` empty: no normals.
inline void place_centre(std::uint16_t mask, const std::uint32_t* ids, const std::vector<Vec3f>& positions,
                         const std::vector<Vec3f>& normals, std::vector<Vec3f>& out_positions,
                         std::vector<Vec3f>& out_normals) {
  Vec3f position, normal;
  centre_vertex(mask, ids, positions.data(), normals.empty() ? nullptr : normals.data(), position, normal);
  out_positions.push_back(position);
  if (!normals.empty()) out_normals.push_back(normal);
}

/// `inside(v)` is exactly double(v) >= iso, with the comparison done in T
/// (floating point) or int32 (the 8- and 16-bit integer types), so that loops
/// over samples vectorize.
template <typename T>
struct Threshold {
  static_assert(std::is_floating_point_v<T> || sizeof(T) <= 2, "integer samples of at most 16 bits");
  using Compare = std::conditional_t<std::is_floating_point_v<T>, T, std::int32_t>;
  Compare value;

  explicit Threshold(double iso) {
    if (!std::isfinite(iso)) throw Error("isosurface: the iso-value must be finite");
    if constexpr (std::is_floating_point_v<T>) {
      T t = T(iso);
      if (double(t) < iso) t = std::nextafter(t, std::numeric_limits<T>::infinity());
      value = t;
    } else {
      value = std::int32_t(std::clamp(std::ceil(iso), -1e9, 1e9));
    }
  }
  bool inside(T v) const { return Compare(v) >= value; }

  /// How many of the n samples are inside; throws for a NaN or infinite one
  /// among them (v - v is NaN exactly for those).
  std::uint32_t count_inside(const T* v, std::size_t n) const {
    std::uint32_t count = 0, bad = 0;
    for (std::size_t i = 0; i < n; ++i) {
      count += std::uint32_t(Compare(v[i]) >= value);
      if constexpr (std::is_floating_point_v<T>) bad += std::uint32_t(v[i] - v[i] != 0);
    }
    if (bad) throw Error("isosurface: the volume has a NaN or infinite sample");
    return count;
  }
};

/// Bit f set for every ambiguous face f of the cell whose inside corners are
/// joined (asymptotic decider); `corner(c)` gives the sample at corner c.
template <typename Corner>
std::uint8_t decide_faces(std::uint8_t ambiguous, double iso, const Corner& corner) {
  std::uint8_t joined = 0;
  for (int f = 0; f < 6; ++f) {
    if (!((ambiguous >> f) & 1)) continue;
    const auto& c = kFaceCorners[f];
    if (face_joins_inside(double(corner(c[0])) - iso, double(corner(c[1])) - iso, double(corner(c[2])) - iso,
                          double(corner(c[3])) - iso))
      joined |= std::uint8_t(1 << f);
  }
  return joined;
}

/// Edge parameters are kept this far from the samples, so that a sample equal
/// to the iso-value never makes coincident vertices or zero-area triangles.
inline constexpr double kEdgeMargin = 1e-3;

/// Places vertices on grid edges: interpolated position, and a normal from the
/// central-difference gradient pointing from inside to outside.
template <typename T>
class VertexPlacer {
 public:
  VertexPlacer(const Grid3View<T>& volume, double iso, std::span<const Vec3f> positions, bool normals)
      : g_(volume), iso_(iso), positions_(positions), normals_(normals) {
    stride_[0] = 1;
    stride_[1] = volume.dims[0];
    stride_[2] = volume.dims[0] * volume.dims[1];
  }

  bool normals() const { return normals_; }

  /// Appends the vertex on the edge from sample (i, j, k) one step along `axis`
  /// (to std::vectors of Vec3f, any allocator).
  template <class Vertices>
  void place(std::size_t i, std::size_t j, std::size_t k, int axis, Vertices& out_positions,
             Vertices& out_normals) const {
    Vec3f position, normal;
    place(i, j, k, axis, position, normal);
    out_positions.push_back(position);
    if (normals_) out_normals.push_back(normal);
  }

  /// The vertex on that edge, written in place (`normal` only if normals() is true).
  void place(std::size_t i, std::size_t j, std::size_t k, int axis, Vec3f& position, Vec3f& normal) const {
    const std::size_t a = g_.index(i, j, k), b = a + stride_[axis];
    const double va = double(g_.data[a]), vb = double(g_.data[b]);
    const double s = std::clamp((iso_ - va) / (vb - va), kEdgeMargin, 1.0 - kEdgeMargin);
    if (positions_.empty()) {
      // Each coordinate on its own (not an indexed array), so that nothing goes through memory.
      const double idx[3] = {double(i) + (axis == 0 ? s : 0.0), double(j) + (axis == 1 ? s : 0.0),
                             double(k) + (axis == 2 ? s : 0.0)};
      for (int d = 0; d < 3; ++d) position[d] = float(double(g_.origin[d]) + idx[d] * double(g_.spacing[d]));
    } else {
      position = ((1 - s) * positions_[a].cast<double>() + s * positions_[b].cast<double>()).cast<float>();
    }
    if (!normals_) return;
    const std::size_t ijk_b[3] = {i + (axis == 0), j + (axis == 1), k + (axis == 2)};
    const Eigen::Vector3d g = (1 - s) * gradient(i, j, k) + s * gradient(ijk_b[0], ijk_b[1], ijk_b[2]);
    Eigen::Vector3d n = -g;
    if (!(n.squaredNorm() > 0) || !n.allFinite()) {
      // Flat field: the edge direction from the inside sample to the outside one.
      n = edge_direction(a, b, axis);
      if (va < iso_) n = -n;
    }
    normal = n.normalized().cast<float>();
  }

 private:
  double value(std::size_t i) const { return double(g_.data[i]); }

  // Central differences (one-sided at the border) in index space.
  Eigen::Vector3d index_gradient(const std::size_t (&ijk)[3], std::size_t at) const {
    Eigen::Vector3d g;
    for (int d = 0; d < 3; ++d) {
      const std::size_t n = g_.dims[d];
      const std::size_t lo = ijk[d] > 0 ? at - stride_[d] : at, hi = ijk[d] + 1 < n ? at + stride_[d] : at;
      const double span = double((ijk[d] + 1 < n) + (ijk[d] > 0));
      g[d] = span > 0 ? (value(hi) - value(lo)) / span : 0.0;
    }
    return g;
  }

  Eigen::Vector3d gradient(std::size_t i, std::size_t j, std::size_t k) const {
    const std::size_t ijk[3] = {i, j, k};
    const std::size_t at = g_.index(i, j, k);
    const Eigen::Vector3d gi = index_gradient(ijk, at);
    if (positions_.empty()) return gi.cwiseQuotient(g_.spacing.template cast<double>());
    // d(value)/d(index) = J^T grad, J = d(position)/d(index) by central differences.
    Eigen::Matrix3d jac;
    for (int d = 0; d < 3; ++d) {
      const std::size_t n = g_.dims[d];
      const std::size_t lo = ijk[d] > 0 ? at - stride_[d] : at, hi = ijk[d] + 1 < n ? at + stride_[d] : at;
      const double span = double((ijk[d] + 1 < n) + (ijk[d] > 0));
      jac.col(d) = span > 0 ? Eigen::Vector3d((positions_[hi] - positions_[lo]).cast<double>() / span)
                            : Eigen::Vector3d::Zero();
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(jac.transpose());
    if (!lu.isInvertible()) return Eigen::Vector3d::Zero();
    return lu.solve(gi);
  }

  Eigen::Vector3d edge_direction(std::size_t a, std::size_t b, int axis) const {
    if (positions_.empty()) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[axis] = g_.spacing[axis] < 0 ? -1.0 : 1.0;
      return d;
    }
    return (positions_[b] - positions_[a]).cast<double>();
  }

  Grid3View<T> g_;
  double iso_;
  std::span<const Vec3f> positions_;
  bool normals_;
  std::size_t stride_[3];
};

/// Checks the options that do not depend on the sample type.
template <typename T>
void check_positions(const Grid3View<T>& volume, std::span<const Vec3f> positions) {
  if (positions.empty()) return;
  if (positions.size() != volume.size())
    throw Error("isosurface: " + std::to_string(positions.size()) + " node positions for a volume of " +
                std::to_string(volume.size()) + " samples");
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!positions[i].allFinite()) throw Error("isosurface: node position " + std::to_string(i) + " is not finite");
}

/// True if the curvilinear grid maps index space to a mirrored physical space
/// (negative Jacobian at the first cell): triangles are then flipped so that
/// they stay oriented from inside to outside.
template <typename T>
bool mirrored(const Grid3View<T>& volume, std::span<const Vec3f> positions) {
  if (positions.empty()) {
    const int negative = (volume.spacing[0] < 0) + (volume.spacing[1] < 0) + (volume.spacing[2] < 0);
    return negative % 2 == 1;
  }
  if (volume.dims[0] < 2 || volume.dims[1] < 2 || volume.dims[2] < 2) return false;
  const Vec3d p = positions[0].cast<double>();
  Eigen::Matrix3d jac;
  const std::size_t along[3] = {1, volume.dims[0], volume.dims[0] * volume.dims[1]};
  for (int d = 0; d < 3; ++d) jac.col(d) = positions[along[d]].cast<double>() - p;
  return jac.determinant() < 0;
}

/// Throws if a floating-point volume holds a NaN (it could be neither inside
/// nor outside) or an infinity (the vertices on its edges would be NaN).
template <typename T>
void check_samples(const Grid3View<T>& volume) {
  if constexpr (std::is_floating_point_v<T>) {
    // One pass over the samples in parallel blocks; the rare failure is then located in order.
    std::atomic<bool> bad{false};
    parallel_for(0, volume.data.size(), std::size_t(1) << 16, [&](std::size_t b, std::size_t e) {
      bool block = false;
      for (std::size_t i = b; i < e; ++i) block |= (volume.data[i] - volume.data[i] != 0);
      if (block) bad.store(true, std::memory_order_relaxed);
    });
    if (bad.load()) {
      for (std::size_t i = 0; i < volume.data.size(); ++i)
        if (!std::isfinite(volume.data[i]))
          throw Error("isosurface: sample " + std::to_string(i) + " of the volume is " +
                      (volume.data[i] != volume.data[i] ? "NaN" : "infinite"));
    }
  }
}

}  // namespace geods::iso::detail
