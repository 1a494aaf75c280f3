#include "geods/field/modeling.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"
#include "geods/iso/marching_cubes.hpp"

namespace geods::field {
namespace {

void check_samples(const Grid3<float>& f, const char* what) {
  if (f.size() != Grid3<float>::checked_size(f.dims[0], f.dims[1], f.dims[2]))
    throw Error(fmt::format("{}: the field holds {} samples for {} x {} x {}", what, f.size(), f.dims[0], f.dims[1],
                            f.dims[2]));
  for (const float v : f.data)
    if (std::isnan(v)) throw Error(fmt::format("{}: the field holds NaN", what));
}

void check_same_grid(const Grid3<float>& a, const Grid3<float>& b, const char* what) {
  if (a.dims != b.dims)
    throw Error(fmt::format("{}: the fields' grids differ: {} x {} x {} and {} x {} x {} samples", what, a.dims[0],
                            a.dims[1], a.dims[2], b.dims[0], b.dims[1], b.dims[2]));
  for (int i = 0; i < 3; ++i) {
    const double h = std::min(a.spacing[i], b.spacing[i]);
    if (std::abs(a.spacing[i] - b.spacing[i]) > 1e-6 * h || std::abs(a.origin[i] - b.origin[i]) > 1e-6 * h)
      throw Error(fmt::format("{}: the fields' grids differ along {}: origin {} and {}, spacing {} and {}", what,
                              char('x' + i), a.origin[i], b.origin[i], a.spacing[i], b.spacing[i]));
  }
}

}  // namespace

CsgOp parse_csg_op(std::string_view name) {
  if (name == "union") return CsgOp::union_;
  if (name == "intersection") return CsgOp::intersection;
  if (name == "difference") return CsgOp::difference;
  throw Error(fmt::format("unknown CSG operation '{}': union, intersection or difference", name));
}

std::string_view to_string(CsgOp op) {
  switch (op) {
    case CsgOp::union_: return "union";
    case CsgOp::intersection: return "intersection";
    case CsgOp::difference: return "difference";
  }
  return "?";
}

Grid3<float> csg(const Grid3<float>& object, const Grid3<float>& tool, CsgOp op, double blend) {
  if (!std::isfinite(blend) || blend < 0)
    throw Error(fmt::format("csg: the blend radius must be finite and >= 0, got {}", blend));
  check_same_grid(object, tool, "csg");
  check_samples(object, "csg"), check_samples(tool, "csg");
  Grid3<float> out;
  static_cast<Grid3Geometry&>(out) = object;
  out.data.resize(object.size());
  parallel_for_each_index(0, out.size(), [&](std::size_t i) {
    out.data[i] = float(csg_value(object.data[i], tool.data[i], op, blend));
  }, 1 << 14);
  return out;
}

Grid3<float> blend(const Grid3<float>& object, const Grid3<float>& tool, double radius, CsgOp op) {
  if (!(radius > 0) || !std::isfinite(radius))
    throw Error(fmt::format("blend: the radius must be finite and > 0, got {}", radius));
  return csg(object, tool, op, radius);
}

Grid3<float> offset(const Grid3<float>& field, double distance) {
  if (!std::isfinite(distance)) throw Error(fmt::format("offset: the distance must be finite, got {}", distance));
  check_samples(field, "offset");
  Grid3<float> out = field;
  for (float& v : out.data) v = float(double(v) - distance);
  return out;
}

double sample_trilinear(const Grid3View<float>& f, const Vec3d& p) {
  if (f.size() == 0) throw Error("sample_trilinear: the field has no samples");
  std::array<std::size_t, 3> i0{};
  std::array<double, 3> t{};
  for (int a = 0; a < 3; ++a) {
    const double n = double(f.dims[a]);
    const double u = std::clamp((p[a] - double(f.origin[a])) / double(f.spacing[a]), 0.0, n - 1);
    const double fl = std::min(std::floor(u), std::max(n - 2, 0.0));
    i0[a] = std::size_t(fl);
    t[a] = f.dims[a] > 1 ? u - fl : 0.0;
  }
  double v = 0;
  for (int c = 0; c < 8; ++c) {
    double w = 1;
    std::array<std::size_t, 3> i{};
    for (int a = 0; a < 3; ++a) {
      const bool up = (c >> a) & 1;
      w *= up ? t[a] : 1 - t[a];
      i[a] = std::min(i0[a] + (up ? 1 : 0), f.dims[a] - 1);
    }
    if (w != 0) v += w * double(f(i[0], i[1], i[2]));
  }
  return v;
}

TriMesh field_surface(const Grid3<float>& field, double level) {
  if (!std::isfinite(level)) throw Error(fmt::format("field_surface: the level must be finite, got {}", level));
  check_samples(field, "field_surface");
  float big = 0;
  for (const float v : field.data)
    if (std::isfinite(v)) big = std::max(big, std::abs(v));
  big = std::max(big, float(std::abs(level))) * 2 + 1;
  Grid3<float> negated = field;
  for (float& v : negated.data) v = -std::clamp(v, -big, big);
  return iso::isosurface(negated, -level);
}

}  // namespace geods::field
