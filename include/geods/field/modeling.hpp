#pragma once
// Volumetric modeling with distance fields (seed §6.2.2): Boolean operations,
// offsets and blends evaluated sample by sample on two fields of the same
// grid (negative inside, as sdf_grid gives them), and their surfaces by the
// iso module's marching cubes.
//
// The seed's table, object O and tool T:
//   union         D_{O u T} = min(D_O, D_T)
//   intersection  D_{O n T} = max(D_O, D_T)
//   difference    D_{O - T} = max(D_O, -D_T)
// The sign of the result is exactly the Boolean of the inputs' signs (inside
// where d < 0), so the zero set is the boundary of the combined solid. The
// values are the exact distance outside a union and inside an intersection,
// and a bound elsewhere (|result| <= the true distance): the field is still
// 1-Lipschitz, which is what marching cubes, offsets and blends need.
//
// Blends: with a blend radius r > 0 the min and max become the polynomial
// smooth minimum and maximum (smin(a, b) = min(a, b) - h^2 r / 4, h =
// max(r - |a - b|, 0) / r): equal to min / max wherever the two fields differ
// by r or more, and rounding the crease where the surfaces meet by a fillet
// of about r / 4 (the largest change, where a = b). Offsets: D - r, the
// surface moved outward by r (inward for r < 0): exact for r > 0 outside and
// r < 0 inside, as for any true signed distance field.
#include <cstdint>
#include <string_view>

#include "geods/core/grid3.hpp"
#include "geods/core/tri_mesh.hpp"

namespace geods::field {

/// The Boolean operations (the same names as bsp::CsgOp; strings "union",
/// "intersection", "difference").
enum class CsgOp : std::uint8_t { union_, intersection, difference };

/// "union", "intersection", "difference"; geods::Error naming the choices otherwise.
CsgOp parse_csg_op(std::string_view name);
std::string_view to_string(CsgOp op);

/// The operator on two values (object a, tool b), smooth with blend > 0.
inline double csg_value(double a, double b, CsgOp op, double blend = 0) {
  if (op == CsgOp::difference) b = -b;
  const bool min = op == CsgOp::union_;
  if (!(blend > 0)) return min ? (a < b ? a : b) : (a > b ? a : b);
  const double diff = a > b ? a - b : b - a;
  const double h = diff < blend ? (blend - diff) / blend : 0.0;
  const double fillet = h * h * blend * 0.25;
  return min ? (a < b ? a : b) - fillet : (a > b ? a : b) + fillet;
}

/// The field of `object` op `tool` (two fields on one grid: equal dims,
/// origins and spacings within 1e-6 of a sample), with a blend radius
/// (in the fields' units; 0: the seed's min / max). Parallel. Throws
/// geods::Error for grids that differ, a NaN sample, or a blend radius that
/// is negative or not finite.
Grid3<float> csg(const Grid3<float>& object, const Grid3<float>& tool, CsgOp op, double blend = 0);

/// A smooth union (or intersection, difference) with blend radius `radius` > 0.
Grid3<float> blend(const Grid3<float>& object, const Grid3<float>& tool, double radius, CsgOp op = CsgOp::union_);

/// The offset field D - distance: its zero set is the surface moved outward
/// by `distance` (inward if negative). Throws geods::Error for a non-finite
/// distance or a NaN sample.
Grid3<float> offset(const Grid3<float>& field, double distance);

/// The field's value at p by trilinear interpolation of the 8 samples around
/// it (p clamped to the grid's box).
double sample_trilinear(const Grid3View<float>& field, const Vec3d& p);

/// The surface {D = level} of a signed field (negative inside) by marching
/// cubes (iso::isosurface of -D at -level, so that the normals and the
/// orientation point outward); +-infinite samples (a narrow band) are taken
/// as +-the largest finite magnitude. Closed where the level set does not touch the
/// grid's border.
TriMesh field_surface(const Grid3<float>& field, double level = 0);

}  // namespace geods::field
