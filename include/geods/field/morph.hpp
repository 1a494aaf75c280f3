#pragma once
// Morphing with distance fields (seed §6.2.1, after Cohen-Or, Levin and
// Solomovici 1998): a metamorphosis from a shape S (mesh A) to a shape T
// (mesh B) through their signed distance fields, which handles changes of
// genus naturally.
//
// - Interpolation, equation (16): M(t) = (1 - t) D_S + t D_T. (The seed
//   writes t D_S + (1 - t) D_T, which starts at T; the weights here are
//   swapped so that M(0) = S and M(1) = T, as the seed's own definition of a
//   morph asks.) At t = 0 and t = 1 the field is D_S and D_T exactly.
// - Warped morph, equation (17): with user correspondences (p0_i on S, p1_i
//   on T), S is first warped by
//       W(t, x) = ((1 - t) I + t E)(R(a, t theta) (x - p0) + p0 + t c),
//   then M(t) = (1 - t) D_{W(t, S)} + t D_T. R(a, theta) and c are the
//   rotation and translation fitted to the correspondences by least squares
//   (Kabsch: the SVD of their cross-covariance, reflections excluded), the
//   rotation taken about the correspondences' centroid p0 (the seed's x is
//   measured from there, so the in-betweens turn in place) and interpolated
//   by its angle about its fixed axis; E is the elastic part, a radial basis
//   function interpolation of what the rigid fit leaves, E(y_i) = p1_i at
//   y_i = R (p0_i - p0) + p0 + c. So W(0, x) = x and W(1, p0_i) = p1_i.
//   D_{W(t, S)} is the exact signed distance of the warped mesh (its
//   vertices moved by W) on the morph's grid.
//   The seed warps S alone, so halfway S is turned only half-way towards T
//   and is blended with a T that has not moved: two perpendicular sticks
//   would still meet at 45 degrees. Here T is warped too, backwards, by the
//   warp W' fitted to the reversed correspondences (its rigid part is the
//   inverse rotation and translation), so both meet in the in-between pose:
//       M(t) = (1 - t) D_{W(t, S)} + t D_{W'(1 - t, T)},
//   still D_S at t = 0 and D_T at t = 1 exactly (W(0, .) and W'(0, .) are
//   the identity), and the seed's (17) where T needs no warp.
// Surfaces come from the iso module (field_surface: marching cubes of the
// zero set).
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "geods/core/grid3.hpp"
#include "geods/core/tri_mesh.hpp"
#include "geods/field/mesh_distance.hpp"
#include "geods/field/sdf_grid.hpp"

namespace geods::field {

/// A rotation about a centre followed by a translation: x -> R (x - centre) + centre + translation.
struct RigidTransform {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3d centre = Vec3d::Zero();
  Vec3d translation = Vec3d::Zero();

  Vec3d apply(const Vec3d& x) const { return rotation * (x - centre) + centre + translation; }
  /// The rotation's angle in [0, pi] and unit axis (x if the angle is 0).
  double angle() const;
  Vec3d axis() const;
};

/// The rigid transform that maps `from` onto `to` best in the least-squares
/// sense (Kabsch / Umeyama without scale), its centre the centroid of `from`:
/// minimizes sum |R (p_i - centre) + centre + c - q_i|^2 over rotations R
/// (det +1) and translations c. One pair: a translation; pairs on a line:
/// the smallest rotation among the equally good ones is not promised (any
/// best one). Throws geods::Error for lists of different lengths, no pairs
/// or non-finite coordinates.
RigidTransform fit_rigid(std::span<const Vec3d> from, std::span<const Vec3d> to);

/// The radial function of the elastic part: thin_plate, phi(r) = r (the
/// biharmonic spline of 3D, with an affine part when the centres span 3D),
/// or gaussian, phi(r) = exp(-(r / width)^2).
enum class RbfKernel : std::uint8_t { thin_plate, gaussian };

/// "thin_plate", "gaussian"; geods::Error otherwise.
RbfKernel parse_rbf_kernel(std::string_view name);
std::string_view to_string(RbfKernel kernel);

/// A radial basis function interpolation of displacements:
/// E(y) = y + sum_i w_i phi(|y - y_i|) + A y + b, with E(y_i) = targets_i
/// (thin_plate: sum_i w_i = 0 and sum_i w_i y_i^T = 0 when the affine part
/// is used, only the first when the centres are coplanar or fewer than 4).
struct RbfWarp {
  RbfKernel kernel = RbfKernel::thin_plate;
  double width = 1;                       // of the gaussian
  std::vector<Vec3d> centres;             // y_i
  std::vector<Vec3d> weights;             // w_i
  Eigen::Matrix3d linear = Eigen::Matrix3d::Zero();  // A
  Vec3d constant = Vec3d::Zero();                     // b

  /// Solves the (n + 1 or n + 4)-square system by LU with full pivoting
  /// (Eigen). width 0: the gaussian's width is half the diagonal of the
  /// centres' box. Throws geods::Error for lists of different lengths, more
  /// than 2000 centres, two centres closer than 1e-9 of the box's diagonal,
  /// non-finite values or a singular system.
  static RbfWarp fit(std::span<const Vec3d> centres, std::span<const Vec3d> targets,
                     RbfKernel kernel = RbfKernel::thin_plate, double width = 0);
  Vec3d operator()(const Vec3d& y) const;
};

/// W(t, x) of equation (17): the rigid fit and the elastic part.
struct MorphWarp {
  RigidTransform rigid;
  RbfWarp elastic;

  /// Fits both to the correspondences (from_i on S, to_i on T).
  static MorphWarp fit(std::span<const Vec3d> from, std::span<const Vec3d> to,
                       RbfKernel kernel = RbfKernel::thin_plate, double width = 0);
  /// W(t, x); exactly x at t = 0.
  Vec3d apply(double t, const Vec3d& x) const;
};

struct MorphOptions {
  std::size_t res = 64;             // samples along the longest side of the grid, padding included
  double padding = kDefaultPadding; // samples of margin
  SignMethod sign = SignMethod::winding;
  /// Correspondences: from[i] on A goes to to[i] on B. Empty: equation (16) alone.
  std::vector<Vec3d> from, to;
  RbfKernel kernel = RbfKernel::thin_plate;
  double width = 0;                 // of a gaussian kernel (0: automatic)
};

struct MorphStats {
  std::size_t samples = 0;          // of the grid
  std::size_t correspondences = 0;
  double rotation_angle = 0;        // of the rigid fit, radians
  double fit_residual = 0;          // RMS distance of the rigidly moved correspondences to their targets
};

/// A morph from mesh A to mesh B on one grid (covering A, B and the warped A
/// at every t). Build once, then take fields and surfaces at any t in [0, 1].
class Morph {
 public:
  /// Computes D_A and D_B (sdf_grid) and fits the warp. Throws geods::Error
  /// for empty or invalid meshes, unequal correspondence lists, bad res or
  /// padding, and what fit_rigid / RbfWarp::fit refuse.
  static Morph build(const TriMesh& a, const TriMesh& b, const MorphOptions& options = {});

  /// M(t) (equation (16), or with correspondences (17)); D_A at t = 0 and
  /// D_B at t = 1 exactly. t in [0, 1], else geods::Error. The warped morph
  /// computes the signed distance of the warped A (one sdf_grid per call).
  Grid3<float> field(double t) const;
  /// The zero set of field(t) (marching cubes; outward normals).
  TriMesh surface(double t) const;
  /// A with its vertices moved by W(t, .) (A itself without correspondences).
  TriMesh warped_source(double t) const;
  /// B with its vertices moved by W'(1 - t, .), the backward warp (B itself without correspondences).
  TriMesh warped_target(double t) const;

  const Grid3Geometry& grid() const { return grid_; }
  const Grid3<float>& source_field() const { return source_; }
  const Grid3<float>& target_field() const { return target_; }
  bool warped() const { return warped_; }
  const MorphWarp& warp() const { return warp_; }
  /// W': fitted to the correspondences from B to A.
  const MorphWarp& backward_warp() const { return backward_; }
  const MorphStats& stats() const { return stats_; }

 private:
  TriMesh source_mesh_, target_mesh_;
  Grid3Geometry grid_;
  Grid3<float> source_, target_;
  MorphWarp warp_, backward_;
  bool warped_ = false;
  SdfGridOptions sdf_options_;
  MorphStats stats_;
};

}  // namespace geods::field
