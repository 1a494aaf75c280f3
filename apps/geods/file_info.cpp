#include "file_info.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include "geods/core/archive.hpp"
#include "geods/core/error.hpp"
#include "geods/io/image_io.hpp"
#include "geods/io/mesh_io.hpp"
#include "geods/io/npy.hpp"
#include "geods/io/polygon_io.hpp"
#include "geods/io/point_io.hpp"
#include "geods/io/table_io.hpp"
#include "geods/io/volume_io.hpp"
#include "geods/shape/collection.hpp"
#include "geods/terrain/height_field.hpp"
#include "stopwatch.hpp"

namespace geods::cli {

namespace fs = std::filesystem;

namespace {

// Lower-case extension including a compression suffix: ".nii.gz", ".ply".
std::string full_extension(const fs::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char* two : {".nii.gz", ".ply.gz", ".off.gz", ".nrrd.gz"}) {
    if (name.size() > std::string(two).size() && name.ends_with(two)) return two;
  }
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? "" : name.substr(dot);
}

template <typename V>
Json json_vec(const V& v) {
  Json a = Json::array();
  for (int i = 0; i < int(v.size()); ++i) a.push_back(double(v[i]));
  return a;
}

template <typename V>
std::string text_vec(const V& v) {
  std::string s = "(";
  for (int i = 0; i < int(v.size()); ++i) s += fmt::format("{}{:.6g}", i ? ", " : "", double(v[i]));
  return s + ")";
}

template <typename Box>
void add_bounds(Report& report, const Box& box) {
  if (box.empty()) {
    report.json["bounds"] = nullptr;
    return;
  }
  report.json["bounds"] = {{"min", json_vec(box.lo)}, {"max", json_vec(box.hi)}};
  report.lines.push_back("  bounds " + text_vec(box.lo) + " .. " + text_vec(box.hi));
}

// A PLY file holds a mesh when it declares faces, else a point cloud.
bool ply_has_faces(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int i = 0; i < 200 && std::getline(in, line); ++i) {
    if (line.rfind("end_header", 0) == 0) break;
    unsigned long long count = 0;
    if (std::sscanf(line.c_str(), "element face %llu", &count) == 1 && count > 0) return true;
  }
  return false;
}

void describe_mesh(const fs::path& path, Report& report) {
  const TriMesh mesh = io::read_mesh(path);
  Stopwatch watch;
  const MeshReport check = mesh.validate();
  report.json["kind"] = "mesh";
  report.json["vertices"] = mesh.num_vertices();
  report.json["triangles"] = mesh.num_triangles();
  report.lines.push_back(fmt::format("{}: mesh, {} vertices, {} triangles", path.filename().string(),
                                     mesh.num_vertices(), mesh.num_triangles()));
  add_bounds(report, mesh.bounds());
  report.json["surface_area"] = mesh.surface_area();
  report.json["closed_manifold"] = check.closed_manifold();
  if (check.closed_manifold()) report.json["volume"] = mesh.signed_volume();
  report.json["checks"] = {{"out_of_range_indices", check.out_of_range_indices},
                           {"non_finite_vertices", check.non_finite_vertices},
                           {"degenerate_faces", check.degenerate_faces},
                           {"duplicate_faces", check.duplicate_faces},
                           {"non_manifold_edges", check.non_manifold_edges},
                           {"boundary_edges", check.boundary_edges},
                           {"inconsistent_edges", check.inconsistent_edges}};
  report.json["problems"] = check.problems();
  if (check.closed_manifold()) {
    report.lines.push_back(fmt::format("  closed, consistently oriented 2-manifold; volume {:.6g}", mesh.signed_volume()));
  }
  for (const std::string& p : check.problems()) report.lines.push_back("  problem: " + p);
  report.json["validate_s"] = watch.seconds();
}

template <typename T>
void describe_grid(const Grid3<T>& grid, Report& report) {
  const auto [lo, hi] = std::minmax_element(grid.data.begin(), grid.data.end());
  report.json["dims"] = grid.dims;
  report.json["origin"] = json_vec(grid.origin);
  report.json["spacing"] = json_vec(grid.spacing);
  if (grid.size()) {
    report.json["min"] = double(*lo);
    report.json["max"] = double(*hi);
  }
  report.lines.push_back(fmt::format("  dims {} x {} x {}, spacing {}, origin {}", grid.dims[0], grid.dims[1],
                                     grid.dims[2], text_vec(grid.spacing), text_vec(grid.origin)));
  if (grid.size()) report.lines.push_back(fmt::format("  values {:.6g} .. {:.6g}", double(*lo), double(*hi)));
}

void describe_volume(const fs::path& path, const io::AnyGrid3& volume, Report& report) {
  const DType dtype = io::grid_dtype(volume);
  report.json["kind"] = "volume";
  report.json["dtype"] = std::string(dtype_name(dtype));
  report.lines.push_back(fmt::format("{}: volume of {}", path.filename().string(), dtype_name(dtype)));
  std::visit([&](const auto& grid) { describe_grid(grid, report); }, volume);
  std::visit([&](const auto& grid) { add_bounds(report, grid.bounds()); }, volume);
}

void describe_image(const fs::path& path, Report& report) {
  const Image<std::uint8_t> image = io::read_image(path);
  report.json["kind"] = "image";
  report.json["width"] = image.width;
  report.json["height"] = image.height;
  report.json["channels"] = image.channels;
  report.json["dtype"] = "u8";
  report.lines.push_back(fmt::format("{}: image {} x {}, {} channel(s) of u8", path.filename().string(),
                                     image.width, image.height, image.channels));
}

void describe_points(const fs::path& path, Report& report) {
  const io::PointMatrix points = io::read_points(path);
  report.json["kind"] = "points";
  report.json["count"] = points.rows();
  report.json["dim"] = points.cols();
  report.lines.push_back(fmt::format("{}: {} points in {}D", path.filename().string(), points.rows(), points.cols()));
  if (points.rows() == 0) return;
  const Eigen::VectorXd lo = points.colwise().minCoeff(), hi = points.colwise().maxCoeff();
  report.json["bounds"] = {{"min", json_vec(lo)}, {"max", json_vec(hi)}};
  report.lines.push_back("  bounds " + text_vec(lo) + " .. " + text_vec(hi));
}

void describe_segments(const fs::path& path, Report& report) {
  const io::SegmentMatrix segments = io::read_segments(path);
  std::size_t zero_length = 0;
  AABB2d box;
  for (Eigen::Index i = 0; i < segments.rows(); ++i) {
    const Vec2d a(segments(i, 0), segments(i, 1)), b(segments(i, 2), segments(i, 3));
    zero_length += a == b;
    box.extend(a).extend(b);
  }
  report.json["kind"] = "segments";
  report.json["count"] = segments.rows();
  report.json["zero_length"] = zero_length;
  report.lines.push_back(fmt::format("{}: {} segments in 2D", path.filename().string(), segments.rows()));
  add_bounds(report, box);
  if (zero_length) report.lines.push_back(fmt::format("  problem: {} zero-length segments", zero_length));
}

// A .npy file is a volume (3 dims), points (n x 2, n x 3), segments (n x 4) or just an array.
void describe_npy(const fs::path& path, Report& report) {
  const io::NpyArray array = io::read_npy(path);
  const auto& shape = array.shape;
  if (shape.size() == 3) return describe_volume(path, io::read_volume(path), report);
  if (shape.size() == 2 && (shape[1] == 2 || shape[1] == 3)) return describe_points(path, report);
  if (shape.size() == 2 && shape[1] == 4) return describe_segments(path, report);
  report.json["kind"] = "array";
  report.json["dtype"] = std::string(dtype_name(array.dtype));
  report.json["shape"] = shape;
  std::string dims;
  for (std::size_t i = 0; i < shape.size(); ++i) dims += (i ? " x " : "") + std::to_string(shape[i]);
  report.lines.push_back(fmt::format("{}: array of {}, shape {}", path.filename().string(),
                                     dtype_name(array.dtype), dims.empty() ? "()" : dims));
  if (array.size()) {
    const std::vector<double> values = array.to_vector<double>();
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    report.json["min"] = *lo;
    report.json["max"] = *hi;
    report.lines.push_back(fmt::format("  values {:.6g} .. {:.6g}", *lo, *hi));
  }
}

// Standard input ("-") has no name: a PLY there is a mesh if it has triangles, else points.
void describe_standard_input_ply(Report& report) {
  try {
    describe_mesh("-", report);
  } catch (const Error& e) {
    if (std::string(e.what()).find("no triangles") == std::string::npos) throw;
    describe_points("-", report);
  }
}

// A shape collection (.sh3f furniture library, zip of meshes): members and labels, without reading the meshes.
// A 2D map (polygons, polylines, points) read through GDAL/OGR or the SVG/.cin readers.
void describe_map(const fs::path& path, Report& report) {
  const io::PolygonSet map = io::read_polygons(path);
  AABB2d box;
  std::size_t ring_points = 0;
  for (const auto& ring : map.rings) {
    ring_points += ring.size();
    for (const Vec2d& p : ring) box.extend(p);
  }
  for (const auto& s : map.segments) box.extend(Vec2d(s[0], s[1])).extend(Vec2d(s[2], s[3]));
  for (const Vec2d& p : map.points) box.extend(p);
  report.json["kind"] = "map";
  report.json["rings"] = map.rings.size();
  report.json["ring_points"] = ring_points;
  report.json["segments"] = map.segments.size();
  report.json["points"] = map.points.size();
  report.lines.push_back(fmt::format("{}: 2D map, {} rings ({} corners), {} polyline segments, {} points",
                                     path.filename().string(), map.rings.size(), ring_points, map.segments.size(),
                                     map.points.size()));
  add_bounds(report, box);
}

// A raster read as a height field (GeoTIFF and other GDAL rasters, Terragen .ter).
void describe_raster(const fs::path& path, Report& report) {
  const terrain::HeightField field = terrain::read_height_field(path);
  float lo = INFINITY, hi = -INFINITY;
  for (const float h : field.heights)
    if (!std::isnan(h)) lo = std::min(lo, h), hi = std::max(hi, h);
  report.json["kind"] = "height_field";
  report.json["width"] = field.width;
  report.json["height"] = field.height;
  report.json["spacing"] = field.spacing;
  report.json["missing"] = field.missing();
  report.lines.push_back(fmt::format("{}: height field {} x {}, spacing {} x {}, heights {} .. {}",
                                     path.filename().string(), field.width, field.height,
                                     format_number(field.spacing[0]), format_number(field.spacing[1]),
                                     format_number(lo), format_number(hi)));
  if (field.missing()) report.lines.push_back(fmt::format("  {} missing (no-data) samples", field.missing()));
}

void describe_collection(const fs::path& path, Report& report) {
  const shape::ShapeCollection c = shape::ShapeCollection::open(path);
  std::map<std::string, std::size_t> labels;
  for (const auto& e : c.entries())
    if (!e.label.empty()) ++labels[e.label];
  report.json["kind"] = "collection";
  report.json["format"] = c.kind() == shape::CollectionKind::sh3f ? "sh3f" : "zip";
  report.json["meshes"] = c.size();
  report.json["labels"] = labels;
  std::string classes;
  for (const auto& [label, count] : labels) classes += fmt::format("{}{} {}", classes.empty() ? "" : ", ", label, count);
  report.lines.push_back(fmt::format("{}: shape collection ({}), {} meshes", path.filename().string(),
                                     c.kind() == shape::CollectionKind::sh3f ? "Sweet Home 3D library" : "zip",
                                     c.size()));
  if (!labels.empty()) report.lines.push_back("  labels: " + classes);
  for (const std::string& w : c.warnings()) report.lines.push_back("  problem: " + w);
}

// A geods archive (what save() writes: .geodsadf, .geodsterrain, ...): its structure and layout version.
void describe_archive(const fs::path& path, Report& report) {
  const Archive::Kind kind = Archive::peek(path);
  report.json["kind"] = "archive";
  report.json["structure"] = kind.kind;
  report.json["version"] = kind.version;
  report.lines.push_back(fmt::format("{}: geods archive of a {} (layout version {}), {} bytes",
                                     path.filename().string(), kind.kind, kind.version, fs::file_size(path)));
}

}  // namespace

Report describe_file(const fs::path& path, const std::optional<RawVolumeSpec>& raw) {
  const bool standard_input = path == "-";
  if (!standard_input && !fs::exists(path)) throw Error(path.string() + ": no such file");
  if (fs::is_directory(path)) throw Error(path.string() + ": is a directory, not a file");
  if (!standard_input && !fs::is_regular_file(path)) throw Error(path.string() + ": not a regular file");
  Report report;
  report.json["file"] = path.string();
  if (!standard_input) report.json["bytes"] = fs::file_size(path);
  Stopwatch watch;
  // Standard input: the format its bytes show (.npy, .ply, .off or a .txt table).
  const std::string ext = standard_input ? io::input_format(path) : full_extension(path);
  if (raw) {
    describe_volume(path, io::read_raw_volume(path, raw->dims, raw->dtype), report);
  } else if (ext == ".ply") {
    standard_input ? describe_standard_input_ply(report)
                   : ply_has_faces(path) ? describe_mesh(path, report) : describe_points(path, report);
  } else if (io::is_mesh_name(path) || (standard_input && ext == ".off")) {
    describe_mesh(path, report);
  } else if (ext == ".nii" || ext == ".nii.gz" || ext == ".nrrd" || ext == ".nhdr" || ext == ".nrrd.gz") {
    describe_volume(path, io::read_volume(path), report);
  } else if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp") {
    describe_image(path, report);
  } else if (ext == ".xyz" || ext == ".csv" || ext == ".txt") {
    describe_points(path, report);
  } else if (ext == ".edg" || ext == ".cin") {
    describe_segments(path, report);
  } else if (ext == ".npy") {
    describe_npy(path, report);
  } else if (ext == ".sh3f" || ext == ".zip") {
    describe_collection(path, report);
  } else if (ext == ".shp" || ext == ".wkt" || ext == ".geojson" || ext == ".gpkg" || ext == ".kml" || ext == ".svg") {
    describe_map(path, report);
  } else if (ext == ".tif" || ext == ".tiff" || ext == ".ter" || ext == ".asc" || ext == ".hgt") {
    describe_raster(path, report);
  } else if (!standard_input && ext.starts_with(".geods")) {
    describe_archive(path, report);
  } else if (ext == ".raw") {
    throw Error(path.string() + ": a raw volume needs --dims X,Y,Z and --dtype");
  } else {
    throw Error(path.string() + ": unknown file type '" + ext +
                "' (meshes .ply .obj .stl .off .gltf .glb, also .gz; volumes .nii .nii.gz .nrrd .npy .raw; images .png "
                ".jpg .bmp; points .xyz .csv .txt .ply .npy; segments .edg .cin .npy; shape collections .sh3f .zip; maps .shp "
                ".wkt .geojson .gpkg .kml .svg; height fields .tif .ter .asc .hgt; "
                "geods archives .geods*; "
                "- for standard input)");
  }
  report.json["compute_s"] = watch.seconds();
  return report;
}

}  // namespace geods::cli
