#include "geods/field/morph.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/field/modeling.hpp"

namespace geods::field {
namespace {

void check_pairs(std::span<const Vec3d> from, std::span<const Vec3d> to, const char* what) {
  if (from.size() != to.size())
    throw Error(fmt::format("{}: {} source points but {} targets", what, from.size(), to.size()));
  for (std::size_t i = 0; i < from.size(); ++i)
    if (!from[i].allFinite() || !to[i].allFinite())
      throw Error(fmt::format("{}: correspondence {} has a coordinate that is not finite", what, i));
}

double rbf(RbfKernel kernel, double width, double r) {
  return kernel == RbfKernel::thin_plate ? r : std::exp(-(r / width) * (r / width));
}

}  // namespace

double RigidTransform::angle() const { return Eigen::AngleAxisd(rotation).angle(); }

Vec3d RigidTransform::axis() const {
  const Eigen::AngleAxisd aa(rotation);
  return aa.angle() == 0 ? Vec3d::UnitX() : Vec3d(aa.axis());
}

RigidTransform fit_rigid(std::span<const Vec3d> from, std::span<const Vec3d> to) {
  check_pairs(from, to, "fit_rigid");
  if (from.empty()) throw Error("fit_rigid: no correspondences");
  const double n = double(from.size());
  Vec3d p = Vec3d::Zero(), q = Vec3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) p += from[i], q += to[i];
  p /= n, q /= n;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();  // cross-covariance
  for (std::size_t i = 0; i < from.size(); ++i) h += (from[i] - p) * (to[i] - q).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  const double d = (v * u.transpose()).determinant() < 0 ? -1.0 : 1.0;  // no reflection
  RigidTransform t;
  t.rotation = v * Eigen::DiagonalMatrix<double, 3>(1, 1, d) * u.transpose();
  t.centre = p;
  t.translation = q - p;
  return t;
}

RbfKernel parse_rbf_kernel(std::string_view name) {
  if (name == "thin_plate") return RbfKernel::thin_plate;
  if (name == "gaussian") return RbfKernel::gaussian;
  throw Error(fmt::format("unknown RBF kernel '{}': thin_plate or gaussian", name));
}

std::string_view to_string(RbfKernel kernel) { return kernel == RbfKernel::thin_plate ? "thin_plate" : "gaussian"; }

RbfWarp RbfWarp::fit(std::span<const Vec3d> centres, std::span<const Vec3d> targets, RbfKernel kernel, double width) {
  check_pairs(centres, targets, "rbf warp");
  const std::size_t n = centres.size();
  if (n > 2000) throw Error(fmt::format("rbf warp: {} correspondences, at most 2000", n));
  if (!std::isfinite(width) || width < 0) throw Error(fmt::format("rbf warp: the width must be >= 0, got {}", width));
  RbfWarp w;
  w.kernel = kernel;
  w.centres.assign(centres.begin(), centres.end());
  w.weights.assign(n, Vec3d::Zero());
  if (n == 0) return w;
  AABB3d box;
  for (const Vec3d& c : centres) box.extend(c);
  const double diagonal = (box.hi - box.lo).norm();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if ((centres[i] - centres[j]).norm() <= 1e-9 * diagonal)
        throw Error(fmt::format("rbf warp: correspondences {} and {} start at the same point", i, j));
  w.width = width > 0 ? width : (diagonal > 0 ? diagonal / 2 : 1.0);
  // The affine part: with thin plates when the centres span 3D, else a constant (thin plates) or none.
  std::size_t m = 0;
  if (kernel == RbfKernel::thin_plate) {
    m = 1;
    if (n >= 4) {
      Eigen::MatrixXd spread(3, n);
      const Vec3d mean = (box.lo + box.hi) / 2;
      for (std::size_t i = 0; i < n; ++i) spread.col(Eigen::Index(i)) = (centres[i] - mean) / std::max(diagonal, 1e-300);
      if (Eigen::FullPivLU<Eigen::MatrixXd>(spread).setThreshold(1e-9).rank() == 3) m = 4;
    }
  }
  const Eigen::Index size = Eigen::Index(n + m);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(size, size);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(size, 3);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) a(Eigen::Index(i), Eigen::Index(j)) = rbf(kernel, w.width, (centres[i] - centres[j]).norm());
    rhs.row(Eigen::Index(i)) = (targets[i] - centres[i]).transpose();
    for (std::size_t k = 0; k < m; ++k) {
      const double pk = k == 0 ? 1.0 : centres[i][Eigen::Index(k - 1)];
      a(Eigen::Index(i), Eigen::Index(n + k)) = a(Eigen::Index(n + k), Eigen::Index(i)) = pk;
    }
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(a);
  if (!lu.isInvertible()) throw Error("rbf warp: the interpolation system is singular (degenerate correspondences)");
  const Eigen::MatrixXd x = lu.solve(rhs);
  for (std::size_t i = 0; i < n; ++i) w.weights[i] = x.row(Eigen::Index(i)).transpose();
  if (m >= 1) w.constant = x.row(Eigen::Index(n)).transpose();
  if (m == 4) w.linear = x.block(Eigen::Index(n + 1), 0, 3, 3).transpose();
  return w;
}

Vec3d RbfWarp::operator()(const Vec3d& y) const {
  Vec3d out = y + linear * y + constant;
  for (std::size_t i = 0; i < centres.size(); ++i) out += weights[i] * rbf(kernel, width, (y - centres[i]).norm());
  return out;
}

MorphWarp MorphWarp::fit(std::span<const Vec3d> from, std::span<const Vec3d> to, RbfKernel kernel, double width) {
  MorphWarp w;
  w.rigid = fit_rigid(from, to);
  std::vector<Vec3d> moved(from.size());
  for (std::size_t i = 0; i < from.size(); ++i) moved[i] = w.rigid.apply(from[i]);
  w.elastic = RbfWarp::fit(moved, to, kernel, width);
  return w;
}

Vec3d MorphWarp::apply(double t, const Vec3d& x) const {
  if (t == 0) return x;
  const Eigen::AngleAxisd full(rigid.rotation);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(t * full.angle(), full.axis()).toRotationMatrix();
  const Vec3d y = r * (x - rigid.centre) + rigid.centre + t * rigid.translation;
  return (1 - t) * y + t * elastic(y);
}

Morph Morph::build(const TriMesh& a, const TriMesh& b, const MorphOptions& options) {
  a.require_valid("morph: mesh A");
  b.require_valid("morph: mesh B");
  if (a.num_triangles() == 0 || b.num_triangles() == 0) throw Error("morph: a mesh has no faces");
  check_pairs(options.from, options.to, "morph");
  Morph m;
  m.source_mesh_ = a;
  m.target_mesh_ = b;
  m.sdf_options_.sign = options.sign;
  m.stats_.correspondences = options.from.size();
  AABB3f box = a.bounds();
  box.extend(b.bounds());
  if (!options.from.empty()) {
    m.warped_ = true;
    m.warp_ = MorphWarp::fit(options.from, options.to, options.kernel, options.width);
    m.backward_ = MorphWarp::fit(options.to, options.from, options.kernel, options.width);
    m.stats_.rotation_angle = m.warp_.rigid.angle();
    double r2 = 0;
    for (std::size_t i = 0; i < options.from.size(); ++i)
      r2 += (m.warp_.rigid.apply(options.from[i]) - options.to[i]).squaredNorm();
    m.stats_.fit_residual = std::sqrt(r2 / double(options.from.size()));
    // The grid holds the warped A and B at every t (sampled at 16 steps).
    for (int s = 1; s < 16; ++s) box.extend(m.warped_source(s / 16.0).bounds()), box.extend(m.warped_target(s / 16.0).bounds());
  }
  m.grid_ = sdf_grid_geometry(box, options.res, 0, options.padding);
  const MeshDistance da = MeshDistance::build(a), db = MeshDistance::build(b);
  m.source_ = sdf_grid(da, m.grid_, m.sdf_options_).distance;
  m.target_ = sdf_grid(db, m.grid_, m.sdf_options_).distance;
  m.stats_.samples = m.source_.size();
  return m;
}

namespace {

TriMesh warped_mesh(const TriMesh& mesh, const MorphWarp& warp, bool warped, double t, double s) {
  if (!(t >= 0 && t <= 1)) throw Error(fmt::format("morph: t must be in [0, 1], got {}", t));
  TriMesh w = mesh;
  w.normals.clear();
  if (!warped) return w;
  for (Vec3f& v : w.vertices) {
    v = warp.apply(s, v.cast<double>()).cast<float>();
    if (!v.allFinite()) throw Error("morph: the warp sends a vertex beyond float range");
  }
  return w;
}

}  // namespace

TriMesh Morph::warped_source(double t) const { return warped_mesh(source_mesh_, warp_, warped_, t, t); }
TriMesh Morph::warped_target(double t) const { return warped_mesh(target_mesh_, backward_, warped_, t, 1 - t); }

Grid3<float> Morph::field(double t) const {
  if (!(t >= 0 && t <= 1)) throw Error(fmt::format("morph: t must be in [0, 1], got {}", t));
  Grid3<float> out;
  static_cast<Grid3Geometry&>(out) = grid_;
  Grid3<float> warped_a, warped_b;
  const Grid3<float>* from = &source_;
  const Grid3<float>* to = &target_;
  if (warped_ && t > 0 && t < 1) {
    warped_a = sdf_grid(warped_source(t), grid_, sdf_options_).distance;
    warped_b = sdf_grid(warped_target(t), grid_, sdf_options_).distance;
    from = &warped_a, to = &warped_b;
  }
  const float s = float(1 - t), u = float(t);
  out.data.resize(source_.size());
  parallel_for_each_index(0, out.size(), [&](std::size_t i) {
    out.data[i] = s * from->data[i] + u * to->data[i];
  }, 1 << 14);
  return out;
}

TriMesh Morph::surface(double t) const { return field_surface(field(t)); }

}  // namespace geods::field
