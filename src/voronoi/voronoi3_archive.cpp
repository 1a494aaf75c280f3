// Voronoi3::save and load: the points, the box, the hull triangles and the
// cells flattened into arrays (per cell its site, volume, centroid and the
// ranges of its corners and faces). Load copies them into cells, checks every
// index before anything follows one, then runs validate().
#include <string>

#include "archive_sections.hpp"
#include "geods/voronoi/voronoi3.hpp"

namespace geods::voronoi {
namespace {
constexpr const char* kKind = "voronoi.Voronoi3";
constexpr std::uint32_t kVersion = 1;
}  // namespace

void Voronoi3::save(const std::filesystem::path& path) const {
  std::vector<std::uint32_t> sites, vertex_offsets{0}, face_offsets{0}, face_sizes, face_vertices, face_neighbors;
  std::vector<Vec3d> vertices, centroids;
  std::vector<double> volumes;
  for (const Voronoi3Cell& cell : cells_) {
    sites.push_back(cell.site);
    vertices.insert(vertices.end(), cell.vertices.begin(), cell.vertices.end());
    vertex_offsets.push_back(std::uint32_t(vertices.size()));
    for (std::size_t f = 0; f < cell.face_count(); ++f)
      face_sizes.push_back(cell.face_offsets[f + 1] - cell.face_offsets[f]);
    face_offsets.push_back(std::uint32_t(face_sizes.size()));
    face_vertices.insert(face_vertices.end(), cell.face_vertices.begin(), cell.face_vertices.end());
    face_neighbors.insert(face_neighbors.end(), cell.face_neighbors.begin(), cell.face_neighbors.end());
    volumes.push_back(cell.volume);
    centroids.push_back(cell.centroid);
  }
  const std::vector<Vec3d> box{box_.lo, box_.hi};
  std::vector<std::uint32_t> hull;
  for (const auto& t : hull_) hull.insert(hull.end(), t.begin(), t.end());
  ArchiveWriter w(kKind, kVersion);
  w.add("points", coordinates_of(std::span<const Vec3d>(points_)));
  w.add("box", coordinates_of(std::span<const Vec3d>(box)));
  w.add("hull", hull);
  w.add("sites", sites);
  w.add("vertex_offsets", vertex_offsets);
  w.add("vertices", coordinates_of(std::span<const Vec3d>(vertices)));
  w.add("face_offsets", face_offsets);
  w.add("face_sizes", face_sizes);
  w.add("face_vertices", face_vertices);  // indices into the cell's own corners
  w.add("face_neighbors", face_neighbors);
  w.add("volumes", volumes);
  w.add("centroids", coordinates_of(std::span<const Vec3d>(centroids)));
  w.write(path);
}

Voronoi3 Voronoi3::load(const std::filesystem::path& path, Archive::Verify verify) {
  const Archive a = Archive::open(path, kKind, kVersion, verify);
  Voronoi3 v;
  v.points_ = read_points<Vec3d>(a, "points").to_vector();
  const FlatArray<Vec3d> box = read_points<Vec3d>(a, "box");
  if (box.size() != 2) throw a.error("box: not two corners");
  v.box_ = AABB3d(box[0], box[1]);
  const FlatArray<std::uint32_t> hull = read_indices(a, "hull", v.points_.size());
  if (hull.size() % 3) throw a.error("hull: not 3 indices per triangle");
  for (std::size_t k = 0; k < hull.size(); k += 3) v.hull_.push_back({hull[k], hull[k + 1], hull[k + 2]});
  const FlatArray<std::uint32_t> sites = a.array<std::uint32_t>("sites");
  const std::size_t cells = sites.size();
  const FlatArray<Vec3d> vertices = read_points<Vec3d>(a, "vertices");
  const FlatArray<std::uint32_t> vertex_offsets = read_indices(a, "vertex_offsets", vertices.size() + 1, {}, cells + 1);
  const FlatArray<std::uint32_t> face_sizes = a.array<std::uint32_t>("face_sizes");
  const FlatArray<std::uint32_t> face_offsets = read_indices(a, "face_offsets", face_sizes.size() + 1, {}, cells + 1);
  const FlatArray<std::uint32_t> face_vertices = a.array<std::uint32_t>("face_vertices");
  const FlatArray<std::uint32_t> face_neighbors = a.array<std::uint32_t>("face_neighbors", face_sizes.size());
  const FlatArray<double> volumes = a.array<double>("volumes", cells);
  const FlatArray<Vec3d> centroids = read_points<Vec3d>(a, "centroids");
  if (centroids.size() != cells) throw a.error("centroids: not one per cell");
  v.cells_.resize(cells);
  std::size_t corner = 0;  // into face_vertices
  for (std::size_t c = 0; c < cells; ++c) {
    if (vertex_offsets[c] > vertex_offsets[c + 1] || face_offsets[c] > face_offsets[c + 1])
      throw a.error("cell " + std::to_string(c) + ": its offsets decrease");
    Voronoi3Cell& cell = v.cells_[c];
    cell.site = sites[c];
    cell.vertices.assign(vertices.begin() + vertex_offsets[c], vertices.begin() + vertex_offsets[c + 1]);
    cell.face_offsets.push_back(0);
    for (std::uint32_t f = face_offsets[c]; f < face_offsets[c + 1]; ++f) {
      if (face_sizes[f] > face_vertices.size() - corner) throw a.error("face_sizes: more corners than face_vertices");
      cell.face_vertices.insert(cell.face_vertices.end(), face_vertices.begin() + corner,
                                face_vertices.begin() + corner + face_sizes[f]);
      corner += face_sizes[f];
      cell.face_offsets.push_back(std::uint32_t(cell.face_vertices.size()));
      cell.face_neighbors.push_back(face_neighbors[f]);
    }
    cell.volume = volumes[c];
    cell.centroid = centroids[c];
  }
  if (vertex_offsets.front() != 0 || vertex_offsets.back() != vertices.size() || face_offsets.front() != 0 ||
      face_offsets.back() != face_sizes.size() || corner != face_vertices.size())
    throw a.error("the cells' offsets do not cover their arrays");
  a.check([&] { Archive::checks_everything(verify) ? v.validate() : v.check_cells(); });
  return v;
}

}  // namespace geods::voronoi
