#pragma once
// Uniform grid with mailboxes (seed §2.5): the scene's bounding box is cut into
// equal cells, each cell lists the triangles that overlap it, and a ray walks
// from cell to cell with the 3D-DDA of Amanatides and Woo, testing the
// triangles of each cell until a hit lies inside the current cell.
//
// Resolution: with n triangles and the box's extents e_x, e_y, e_z the cell is
// a cube of side s = cbrt(e_x e_y e_z / (density * n)), so about density * n
// cells (density 4 by default: a few triangles per non-empty cell on meshes).
// Flat axes (extent below one cell) get one cell and the others share the
// budget; each axis has at most max_resolution cells.
//
// Layout: compressed sparse rows — cell_begin (cells + 1 offsets) and the
// triangle indices of all cells, sorted within each cell.
//
// Mailboxes: the classic mailbox stores the id of the last ray with each
// triangle, which is not thread-safe. Here each query keeps its own small
// direct-mapped mailbox (64 slots, indexed by triangle id) on the stack, so a
// triangle found in several cells is tested once in almost every case and
// queries from many threads share nothing.
#include <cstdint>
#include <vector>

#include "geods/ray/accelerator.hpp"

namespace geods::ray {

class UniformGrid final : public Accelerator {
 public:
  static std::unique_ptr<UniformGrid> build(const TriMesh& mesh, const AcceleratorOptions& options = {});

  static constexpr const char* kArchiveKind = "ray.UniformGrid";
  static constexpr std::uint32_t kArchiveVersion = 1;
  /// The corners, the resolution and the cell lists (the bounds follow from the corners).
  void save(const std::filesystem::path& path) const override;
  /// Maps a file written by save() and validate()s it; geods::Error naming the file if it is bad.
  static std::unique_ptr<UniformGrid> load(const std::filesystem::path& path);

  AcceleratorKind kind() const override { return AcceleratorKind::grid; }
  AcceleratorStats stats() const override;
  void validate() const override;

  const AABB3f& grid_bounds() const { return grid_bounds_; }
  const Vec3i& resolution() const { return resolution_; }
  /// Triangles listed in cell (x, y, z).
  std::span<const std::uint32_t> cell(int x, int y, int z) const;

 protected:
  RayHit closest_hit(const Ray3f& ray, RayCache& cache) const override;
  std::uint32_t any_hit(const Ray3f& ray, RayCache& cache) const override;

 private:
  explicit UniformGrid(const TriMesh& mesh) : Accelerator(mesh) {}
  explicit UniformGrid(const Archive& in) : Accelerator(in) {}
  // The grid's box and cell size for the current resolution.
  void set_cells();
  template <bool AnyHit>
  std::uint32_t traverse(const Ray3f& ray, RayHit& best) const;
  std::size_t cell_index(int x, int y, int z) const {
    return (std::size_t(z) * std::size_t(resolution_[1]) + std::size_t(y)) * std::size_t(resolution_[0]) +
           std::size_t(x);
  }

  AABB3f grid_bounds_;
  Vec3i resolution_ = Vec3i::Ones();
  Vec3f cell_size_ = Vec3f::Ones();
  Vec3f inv_cell_size_ = Vec3f::Ones();
  FlatArray<std::uint32_t> cell_begin_;
  FlatArray<std::uint32_t> cell_triangles_;
};

}  // namespace geods::ray
