#pragma once
// Reading and writing point sets and segment sets.
#include <filesystem>

#include <Eigen/Core>

namespace geods::io {

/// n points of dimension 2 or 3, one per row.
using PointMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The points of a table (read_table in table_io.hpp): .npy (n x 2 or n x 3,
/// any numeric dtype), .xyz, .csv, .txt (columns after x, y, z such as normals
/// are ignored) or .ply (vertex x, y, z). Throws geods::Error on malformed
/// input, NaN/inf coordinates, or no points.
PointMatrix read_points(const std::filesystem::path& path);

/// Writes .npy (float64), .xyz, .csv or .ply (ascii) by extension.
void write_points(const std::filesystem::path& path, const PointMatrix& points);

/// m 2D segments, one per row: x0 y0 x1 y1.
using SegmentMatrix = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;

/// Reads a table of 4 columns (.npy, .csv, .txt; see read_table), .edg (count
/// line, then "x0 y0 x1 y1" lines) or .cin ("s x0 y0 x1 y1" lines; "p x y"
/// point sites are skipped).
SegmentMatrix read_segments(const std::filesystem::path& path);

}  // namespace geods::io
