#pragma once
// Plane-based exact geometry for BSP trees (Bernstein–Fussell, Campen–Kobbelt).
//
// Input vertices are snapped to an integer grid (|coordinate| <= 2^19, see
// Grid). Every plane has integer coefficients a x + b y + c z + d = 0 with
// |a|, |b|, |c| < 2^41 and |d| < 2^62: support planes through three snapped
// vertices (cross products of differences <= 2^20), edge planes through a
// snapped edge and its dominant normal axis, the six planes of the universe
// box |x|, |y|, |z| <= 2^20, and the axis-aligned planes of the balanced
// heuristic. A polygon is a convex polygon given by its support plane and the
// cyclic list of its edge planes; vertex k is the intersection of the support
// plane with edge planes k-1 and k, so splitting a polygon by a plane only
// adds that plane to the list and coordinates never grow.
//
// The one predicate is the sign of a plane at such a vertex, the sign of a
// 4x4 determinant of plane coefficients. With the bounds above the vertex's
// homogeneous coordinates are |W| < 2^126, |X|, |Y|, |Z| < 2^147 and the
// value a X + b Y + c Z + d W < 2^190, so it is evaluated exactly in 256-bit
// two's complement integers whenever a floating-point filter (error bound
// 32 u times the permanent) cannot decide. Every side decision of
// construction, splitting, merging and mesh extraction is this predicate.
#include <array>
#include <cstdint>
#include <vector>

namespace geods::bsp {

/// Bits of the snapped grid: snapped coordinates satisfy |q| <= 2^kGridBits.
inline constexpr int kGridBits = 19;
/// Half-side of the universe box (all planes' polygons are clipped to it).
inline constexpr std::int64_t kUniverse = std::int64_t{1} << (kGridBits + 1);

/// A plane reference: an index into a PlaneSet, with kFlip set for the opposite orientation.
inline constexpr std::uint32_t kFlip = 0x80000000u;
inline constexpr std::uint32_t plane_index(std::uint32_t ref) { return ref & ~kFlip; }

struct Plane {
  std::int64_t a = 0, b = 0, c = 0, d = 0;
};

inline constexpr std::uint32_t kNoPoint = 0xffffffffu;

/// A polygon vertex: the point where planes p, q, r meet; if `point` is not kNoPoint it is
/// also that snapped input vertex (integer coordinates), which makes its sign tests cheap.
struct Vertex {
  std::uint32_t p = 0, q = 0, r = 0;
  std::uint32_t point = kNoPoint;
};

/// 256-bit two's complement integer (only what the predicate needs).
struct Int256 {
  std::array<std::uint64_t, 4> limb{};  // little endian
  static Int256 from(__int128 v);
  friend Int256 operator+(const Int256& x, const Int256& y);
  friend Int256 operator-(const Int256& x, const Int256& y);
  friend Int256 operator*(const Int256& x, const Int256& y);  // truncated to 256 bits
  int sign() const;
};

/// Table of the planes of one computation (shared by the trees of a boolean).
/// Planes 0..5 are the universe box: x <= L, x >= -L, y <= L, ... written as
/// (+-1, 0, 0, -L) so the box's inside is their negative side.
class PlaneSet {
 public:
  PlaneSet();
  std::uint32_t add(const Plane& p);
  /// The plane of a reference (ignoring kFlip).
  const Plane& operator[](std::uint32_t ref) const { return planes_[plane_index(ref)]; }
  std::size_t size() const { return planes_.size(); }
  /// Sign of plane reference h at the point where planes p, q, r meet (they must meet in
  /// one point; their kFlip bits do not matter).
  int side(std::uint32_t h, std::uint32_t p, std::uint32_t q, std::uint32_t r) const;
  /// Sign of plane h at a vertex (integer evaluation for snapped input vertices).
  int side(std::uint32_t h, const Vertex& v) const;
  std::array<double, 3> point(const Vertex& v, double* radius = nullptr) const;
  std::uint32_t add_point(const std::array<std::int64_t, 3>& q);
  const std::array<std::int64_t, 3>& integer_point(std::uint32_t i) const { return points_[i]; }
  std::size_t point_count() const { return points_.size(); }
  void reserve(std::size_t planes, std::size_t points);
  /// Sign of the dot product of the normals of planes p and q (exact).
  int normal_dot_sign(std::uint32_t p, std::uint32_t q) const;
  /// Double approximation of the point where p, q, r meet (grid coordinates).
  /// If radius is given, a bound on the error of each coordinate.
  std::array<double, 3> point(std::uint32_t p, std::uint32_t q, std::uint32_t r, double* radius = nullptr) const;
  /// Sign of plane h at a point given in double grid coordinates: exact for that point.
  int side(std::uint32_t h, const double* x) const;
  /// Plane through three integer points (a x + ... with normal (q-p) x (r-p)).
  static Plane through(const std::array<std::int64_t, 3>& p, const std::array<std::int64_t, 3>& q,
                       const std::array<std::int64_t, 3>& r);

 private:
  std::vector<Plane> planes_;
  std::vector<std::array<double, 4>> approx_;
  std::vector<std::array<std::int64_t, 3>> points_;
};

/// A convex polygon: vertex k is support ∩ edges[k-1] ∩ edges[k]; the interior is on
/// the negative side of every edge plane; vertices run counter-clockwise seen from the
/// positive side of the support plane (its normal is the polygon's normal).
struct Polygon {
  std::uint32_t support = 0;
  std::vector<std::uint32_t> edges;
  std::vector<std::uint32_t> points;  // per vertex: its snapped input point, or kNoPoint
  std::uint32_t source = 0;           // input triangle (or tag) this fragment came from

  std::size_t size() const { return edges.size(); }
  std::uint32_t prev_edge(std::size_t k) const { return edges[(k + edges.size() - 1) % edges.size()]; }
  Vertex vertex(std::size_t k) const { return {support, prev_edge(k), edges[k], points[k]}; }
  /// The same polygon with the opposite orientation.
  Polygon reversed() const;
};

enum class Side { negative, positive, coplanar, straddling };

/// Signs of h at the polygon's vertices and the summary.
Side classify(const PlaneSet& planes, const Polygon& poly, std::uint32_t h, std::vector<int>* signs = nullptr);
/// Splits a straddling polygon by h into its negative and positive parts.
void split(const PlaneSet& planes, const Polygon& poly, std::uint32_t h, const std::vector<int>& signs, Polygon& neg,
           Polygon& pos);
/// Plane through edge a->b of a triangle with opposite corner c, containing the dominant
/// normal axis `axis`; the triangle's inside is its negative side.
Plane edge_plane(const std::array<std::int64_t, 3>& a, const std::array<std::int64_t, 3>& b,
                 const std::array<std::int64_t, 3>& c, int axis);
/// The triangle p0 p1 p2 of snapped points (ids i0 i1 i2 of planes.add_point) as a polygon
/// (support plane and three edge planes added to planes); false if it is degenerate.
bool triangle_polygon(PlaneSet& planes, const std::array<std::int64_t, 3>& p0, const std::array<std::int64_t, 3>& p1,
                      const std::array<std::int64_t, 3>& p2, std::array<std::uint32_t, 3> ids, Polygon& out);
/// The polygon h ∩ universe box, normal = h's normal.
Polygon universe_polygon(const PlaneSet& planes, std::uint32_t h);
/// Keeps the part of poly on side `keep` (-1 or +1) of h; returns false if nothing of positive area is left.
bool clip(const PlaneSet& planes, Polygon& poly, std::uint32_t h, int keep);
/// Approximate area in grid units^2 and double vertices.
double approx_area(const PlaneSet& planes, const Polygon& poly);
std::array<double, 3> approx_centroid(const PlaneSet& planes, const Polygon& poly);

}  // namespace geods::bsp
