#pragma once
// Terrain level of detail on height fields (Lindstrom & Pascucci's 4-8 meshes):
// longest-edge bisection over the grid, per vertex a nested object-space error
// and a nested bounding-sphere radius, so that refinement by a maximum vertical
// error or by a screen-space error with frustum culling is crack-free by
// construction; output as one generalized triangle strip (the submesh
// recursion with its turns) and as indexed triangles. The per-vertex records
// live in one flat array, in memory in the matrix layout (or the interleaved
// red/blue quadtree layout), saved in the interleaved one and memory-mapped as is.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "geods/core/archive.hpp"
#include "geods/core/flat_array.hpp"
#include "geods/core/huge_page_allocator.hpp"
#include "geods/core/vec.hpp"
#include "geods/ray/camera.hpp"
#include "geods/terrain/height_field.hpp"

namespace geods::terrain {

inline constexpr std::string_view kTerrainArchiveKind = "terrain.Terrain";
inline constexpr std::uint32_t kTerrainArchiveVersion = 1;

/// Where vertex (x, y) of the padded (2^k + 1)^2 grid is stored.
enum class Layout : std::uint32_t {
  /// Lindstrom & Pascucci: the blue quadtree (edge midpoints) level by level
  /// in Morton order of its 45-degree rotated grid, the red quadtree (square
  /// centres) of the same level in the blue level's ghost slots (outside the
  /// grid); about 25 % of the slots unused. Blue children of slot i are 4 i + {0..3}
  /// of the next level.
  interleaved = 0,
  matrix = 1,  // y * n + x
};

/// One vertex: its height (times z_scale), nested error, nested bounding-sphere radius.
/// A plain aggregate (VertexRecord{} is all zero): the build leaves the records
/// of a layout without unused slots unwritten until its fill assigns them.
struct VertexRecord {
  float z, error, radius;
};

/// The slot arithmetic of a layout for a grid of n = 2^levels + 1 samples per side.
class LayoutIndex {
 public:
  LayoutIndex() = default;
  LayoutIndex(Layout layout, std::uint32_t levels);
  Layout layout() const { return layout_; }
  std::uint32_t levels() const { return levels_; }
  std::uint64_t n() const { return (std::uint64_t(1) << levels_) + 1; }
  /// Slots of the array (n^2 for the matrix layout).
  std::uint64_t slots() const { return slots_; }
  std::uint64_t slot(std::uint32_t x, std::uint32_t y) const {
    return layout_ == Layout::matrix ? std::uint64_t(y) * n() + x : interleaved_slot(x, y);
  }
  std::uint64_t interleaved_slot(std::uint32_t x, std::uint32_t y) const;
  /// The first slot of the interleaved level of spacing 2^t (t < levels).
  std::uint64_t level_base(std::uint32_t t) const { return base_[t]; }

 private:
  Layout layout_ = Layout::interleaved;
  std::uint32_t levels_ = 0;
  std::uint64_t slots_ = 0;
  std::array<std::uint64_t, 32> base_{};
};

struct TerrainOptions {
  double z_scale = 1;  // heights are multiplied by it
  /// In memory the matrix layout builds and refines faster (docs/terrain.md,
  /// Speed); save() writes the interleaved layout either way.
  Layout layout = Layout::matrix;
};

/// A camera for view-dependent refinement: an image of width x height pixels.
struct TerrainView {
  ray::Camera camera;  // eye, target, up, vertical field of view
  int width = 1024, height = 768;
};

/// What to refine by: a maximum vertical error, or a view and a pixel error
/// (both at once: a vertex is refined when either asks for it).
struct Refinement {
  std::optional<double> max_error;  // object-space error E (height units after z_scale)
  std::optional<TerrainView> view;
  double pixel_error = 1;  // screen-space error tau, pixels
};

/// A refined mesh: positions (x, y from origin and spacing, z = height * z_scale),
/// counter-clockwise triangles (seen from +z in grid coordinates) and one generalized
/// triangle strip over the same vertices (degenerate triangles join and turn it).
struct TerrainMesh {
  std::vector<Vec3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::uint32_t> strip;
  std::vector<std::array<std::uint32_t, 2>> samples;  // per vertex its grid sample (x, y)
};

struct TerrainStats {
  std::uint64_t width = 0, height = 0;  // samples of the field
  std::uint64_t grid = 0;               // n = 2^levels + 1 of the padded grid
  std::uint64_t levels = 0;
  std::uint64_t slots = 0, unused_slots = 0;
  double unused_slots_pct = 0;
  std::uint64_t filled_samples = 0;  // missing samples filled by the no-data rule
  std::uint64_t bytes = 0;           // of the vertex records
  bool mapped = false;
  double build_s = 0;
};

class Terrain {
 public:
  Terrain() = default;
  /// Builds the hierarchy. Missing samples are filled (fill_missing); a field
  /// that is not (2^k + 1)^2 is padded to the next such square, and the padding
  /// never appears in a mesh. O(n^2 log n) for the exact errors, parallel.
  explicit Terrain(HeightField field, TerrainOptions options = {});

  /// The mesh for `refinement`. Crack-free for any criterion; with max_error E
  /// every grid sample is within E (vertically) of the surface.
  /// Throws geods::Error for neither criterion, a negative or NaN E, a bad
  /// camera or image size, or a pixel error <= 0.
  TerrainMesh refine(const Refinement& refinement) const;
  /// The same mesh cut into tiles x tiles square tiles of the padded grid (a
  /// power of two), each refined on its own: the tiles' meshes meet without
  /// cracks because border vertices carry errors nested over both sides.
  TerrainMesh refine_tiles(const Refinement& refinement, std::uint32_t tiles) const;

  /// A triangulated irregular network within `max_error` of every sample, by
  /// greedy insertion (Garland & Heckbert): starting from the field's corners,
  /// the sample farthest (vertically) from the current triangulation is inserted
  /// into the Delaunay triangulation (split, then Lawson flips with the exact
  /// incircle test) until none is farther than max_error. With
  /// tiles > 1 the field is cut into tiles x tiles tiles whose shared borders are
  /// first simplified once (greedy insertion along the border polyline), so
  /// that the tiles' triangulations meet without cracks. No strip (empty).
  TerrainMesh tin(double max_error, std::uint32_t tiles = 1) const;

  /// The largest vertical distance between `mesh` and the field's samples
  /// (each sample against the triangle over it; `mesh.samples` places vertices).
  double measure_error(const TerrainMesh& mesh) const;

  std::uint64_t width() const { return width_; }
  std::uint64_t height() const { return height_; }
  const LayoutIndex& layout() const { return index_; }
  const FlatArray<VertexRecord>& records() const { return records_; }
  const VertexRecord& record(std::uint32_t x, std::uint32_t y) const { return records_[index_.slot(x, y)]; }
  std::array<double, 2> spacing() const { return spacing_; }
  std::array<double, 2> origin() const { return origin_; }
  double z_scale() const { return z_scale_; }
  /// The field's height at sample (x, y) times z_scale (x < width, y < height).
  float sample(std::uint32_t x, std::uint32_t y) const { return record(x, y).z; }
  TerrainStats stats() const;

  /// Writes the terrain as a geods archive (kind "terrain.Terrain"), its
  /// records in the interleaved layout (a matrix terrain's rearranged), whose
  /// coarse levels share pages: a view of a mapped file reads fewer of them.
  void save(const std::filesystem::path& path) const;
  /// Maps a saved terrain: the vertex records are read in place, page by page
  /// as views touch them. Verify::checksums reads the whole file once;
  /// Verify::structure_only reads only the header (the records are used as they are).
  static Terrain load(const std::filesystem::path& path, Archive::Verify verify = Archive::Verify::checksums);

 private:
  std::vector<float, HugePageAllocator<float>> heights_matrix() const;  // the field's samples (times z_scale), rows first
  std::uint64_t width_ = 0, height_ = 0;
  std::array<double, 2> spacing_{1, 1}, origin_{0, 0};
  double z_scale_ = 1;
  std::uint64_t filled_ = 0;
  double build_s_ = 0;
  LayoutIndex index_;
  FlatArray<VertexRecord> records_;
};

/// The border tolerance of Terrain::tin for a field whose samples span [lo, hi]:
/// a little less than max_error, so that a border sample (measured in 1D) is
/// never picked in 2D, where rounding differs.
double tin_border_limit(double max_error, double lo, double hi);

/// One tile of Terrain::tin on its own: the greedy-insertion TIN of the
/// width x height samples z (rows = y, finite), its four sides simplified to
/// border_limit (tin_border_limit() of the whole field) and the inside to
/// max_error. Vertices are (x, y, z) at the sample coordinates of the tile
/// (samples set). The arithmetic uses coordinate differences only, so the
/// tile [x0, x1] x [y0, y1] of tin(max_error, tiles) is this mesh of that
/// block shifted by (x0, y0): tiles can be computed apart (geods.dask.terrain_tiles).
/// Throws geods::Error for a bad max_error or border_limit, fewer than 2 x 2
/// samples, a size mismatch or a non-finite sample.
TerrainMesh tin_tile(std::span<const float> z, std::size_t width, std::size_t height, double max_error,
                     double border_limit);

}  // namespace geods::terrain
