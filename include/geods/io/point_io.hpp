#pragma once
// Reading and writing point sets and segment sets.
#include <filesystem>

#include <Eigen/Core>

namespace geods::io {

/// n points of dimension 2 or 3, one per row.
using PointMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Reads .npy (n x 2 or n x 3, float32/float64), .xyz (whitespace separated,
/// extra columns such as normals ignored), .csv (header line optional) or .ply
/// (vertex x, y, z). Throws geods::Error on malformed input, NaN/inf
/// coordinates, or no points.
PointMatrix read_points(const std::filesystem::path& path);

/// Writes .npy (float64), .xyz, .csv or .ply (ascii) by extension.
void write_points(const std::filesystem::path& path, const PointMatrix& points);

/// m 2D segments, one per row: x0 y0 x1 y1.
using SegmentMatrix = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;

/// Reads .npy (m x 4), .edg (count line, then "x0 y0 x1 y1" lines) or .cin
/// ("s x0 y0 x1 y1" lines; "p x y" point sites are skipped).
SegmentMatrix read_segments(const std::filesystem::path& path);

}  // namespace geods::io
